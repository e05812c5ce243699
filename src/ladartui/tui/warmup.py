"""Compile the tracing kernels in a separate process, so the interface never waits.

numba compiles with the interpreter lock held, which would freeze the
interface for seconds if done on a thread of the app. A child process does it
instead and fills numba's on-disk cache; the app then loads the compiled
kernels from the cache in moments. Run as
``python -m ladartui.tui.warmup SCENARIO.toml``; it imports nothing from textual.
"""

from __future__ import annotations

import subprocess
import sys


def tiny_run(scenario, scene=None, cancel=None) -> None:
    """Simulate one ray of the scenario's first scan: compiles every kernel a run uses."""
    from ladartui.flight import FlightPlan, Manual
    from ladartui.sensor import Sensor
    from ladartui.simulation import simulate

    tiny = scenario.with_changes(
        sensor=Sensor(grid=1, ray_grid=1, fov=scenario.sensor.fov),
        flight=FlightPlan(None, (Manual((scenario.poses()[0],)),)),
    )
    simulate(tiny, write=False, scene=scene, cancel=cancel)


def warm_in_child(scenario_path, stop=None, timeout: float = 600.0) -> bool:
    """Run the warm-up in a child process; True when it finished cleanly.

    ``stop`` (a threading.Event) ends the child early, e.g. when the app quits.
    """
    import time

    try:
        child = subprocess.Popen(
            [sys.executable, "-m", "ladartui.tui.warmup", str(scenario_path)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
    except OSError:
        return False
    deadline = time.monotonic() + timeout
    while child.poll() is None:
        if (stop is not None and stop.is_set()) or time.monotonic() > deadline:
            child.kill()
            child.wait()
            return False
        time.sleep(0.05)
    return child.returncode == 0


def main(argv=None) -> int:
    from ladartui.scenario import load_scenario

    args = sys.argv[1:] if argv is None else argv
    tiny_run(load_scenario(args[0]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
