"""Compile the numba kernels a run uses before it needs them, two halves at once.

numba compiles a kernel on its first call, holding the interpreter lock, and
keeps it in its on-disk cache. Child processes compile the two halves of the
kernels side by side instead (``compile_in_children``), each into the cache,
and the caller then loads them in moments. With an empty cache on two cores,
`ladartui run default` took 131-151 s compiling in its own process, 67-81 s
this way:

- "object": a scan in object order (its bins, the voxels in view, the tile
  lists and tests), on a small made-up scene, for each backend the scenario
  may trace with;
- "run": a one-ray run of the scenario itself (sensor rays, its scene's
  occupancy, rays to cells, ray order or the march, the depth rule, the
  measures), and the depth rule of a whole scan's rays.

Run as ``python -m ladartui.precompile HALF SCENARIO.toml BACKEND METHOD
PRECISION MODEL`` (MODEL: the detection model, "geiger" for Geiger-mode
looks). Failing here fails nothing: a run compiles what it still needs.
"""

from __future__ import annotations

import functools
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

HALVES = ("object", "run")
SCAN_SIDE = 64  # rays a side of the made-up scan: 4,096, enough for object order


def compile_half(half: str, scenario, scene=None, cancel=None) -> None:
    """Compile (or load from the cache) the kernels of ``half`` for ``scenario``."""
    if half == "object":
        _object_order(scenario)
    elif half == "run":
        one_ray_run(scenario, scene, cancel)
        _made_up_scan(scenario, "ray", SCAN_SIDE**2)  # what one ray skips (a GPU's bundles)
    else:
        raise ValueError(f"half {half!r}: expected one of {', '.join(HALVES)}")


def _object_order(scenario) -> None:
    if scenario.method != "exact" or scenario.precision != "f64":
        return  # only exact f64 scans go in object order
    # a whole scan (one ray a bin), then one ray short of it (the bins' sort)
    for rays in (SCAN_SIDE**2, SCAN_SIDE**2 - 1):
        _made_up_scan(scenario, "object", rays)


def _made_up_scan(scenario, order: str, rays: int) -> None:
    """``rays`` of a scan over a small slab, traced in ``order`` by each backend the
    scenario may use."""
    from ladartui.tracing import TINY
    from ladartui.tracing.prepare import rays_to_cells

    occupancy = _slab()
    origins, directions = _pinhole_scan(np.array([12.0, 12.0, 40.0]))
    cells, unit, bounds = rays_to_cells(origins[:rays], directions[:rays], 1.0, TINY)
    for engine in _engines(scenario.backend):
        engine.trace_cells(
            occupancy,
            cells,
            unit,
            method=scenario.method,
            precision=scenario.precision,
            block_bounds=bounds,
            order=order,
        )


@functools.cache
def _slab():
    """The occupancy of a 24 x 24 x 3 slab of voxels (built once a process)."""
    from ladartui.scene.model import Scene

    slab = np.stack(np.meshgrid(np.arange(24), np.arange(24), np.arange(3), indexing="ij"), -1).reshape(-1, 3)
    return Scene(slab, slab[:10], 1.0).occupancy


def _pinhole_scan(origin):
    """A SCAN_SIDE x SCAN_SIDE grid of unit rays looking down, each from its own point
    of a focal plane around ``origin`` as a sensor's are (rays from one shared
    point take kernels of another type)."""
    tangents = np.tan(np.radians(np.linspace(-10.0, 10.0, SCAN_SIDE)))
    across, along = np.meshgrid(tangents, tangents, indexing="ij")
    directions = np.stack([across.ravel(), along.ravel(), -np.ones(across.size)], axis=1)
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    return origin + 1e-3 * directions * [1.0, 1.0, 0.0], directions


def _backend_names(backend) -> list[str]:
    """The backends a scenario's run may trace with: its own, or under auto the one
    chosen here and, beside a GPU, numba (auto learns which is faster)."""
    from ladartui.tracing import choose_backend

    return list(dict.fromkeys([choose_backend(), "numba"] if backend in (None, "auto") else [backend]))


def _engines(backend) -> list:
    from ladartui.errors import BackendUnavailable
    from ladartui.tracing.backend import get_backend

    engines = []
    for name in _backend_names(backend):
        try:
            engines.append(get_backend(name))
        except BackendUnavailable:
            pass
    return engines


def one_ray_run(scenario, scene=None, cancel=None) -> None:
    """Simulate one ray of the scenario's first scan, then a whole scan's depth rule:
    every kernel of a run but the object order's."""
    from ladartui.flight import FlightPlan, Manual
    from ladartui.returns import kept_returns
    from ladartui.sensor import Sensor
    from ladartui.simulation import simulate

    tiny = scenario.with_changes(
        sensor=Sensor(grid=1, ray_grid=1, fov=scenario.sensor.fov),
        flight=FlightPlan(None, (Manual((scenario.poses()[0],)),)),
    )
    simulate(tiny, write=False, scene=scene, cancel=cancel)
    # A whole scan's depth rule runs in parallel parts (one ray above takes the serial one).
    rays = 1 << 14
    detector = np.repeat(np.arange(rays // 4, dtype=np.int32), 4)  # the sensor's ids are int32
    kept_returns(
        detector, np.ones(rays, np.uint8), np.linspace(1.0, 2.0, rays), scenario.sensor.depth_resolution
    )


def kernels_cached(scenario) -> bool:
    """Whether numba's cache already holds the largest kernels a run of ``scenario``
    compiles, for this source (then a run loads them in moments); True when it
    cannot tell."""
    try:
        from ladartui.tracing.prepare import _rays_to_cells

        kernels: list[Any] = [_rays_to_cells]  # every run's
        exact = scenario.method == "exact"
        for name in _backend_names(scenario.backend):
            if name == "numba" and exact:
                from ladartui.tracing.numba_backend import _exact_kernel
                from ladartui.tracing.tile_tests import test_tiles

                kernels += [_exact_kernel, test_tiles]
            elif name == "numba":
                from ladartui.tracing.march import march_kernel

                kernels.append(march_kernel)
            elif name == "wgpu" and exact and scenario.precision == "f64":
                from ladartui.tracing.shader_scan import entry_answers

                kernels.append(entry_answers)
        if getattr(scenario, "geiger", False):
            from ladartui.detection.geiger import _fire_kernel

            kernels.append(_fire_kernel)
        # (numba's own index: empty when missing or made from another source)
        return all(bool(kernel._cache._cache_file._load_index()) for kernel in kernels)
    except Exception:
        return True


def compile_ahead(scenario, stop=None, load_scene: bool = False):
    """Before a run in this process: when the cache lacks the scenario's kernels, the
    two halves in child processes side by side (on two cores about half the wait
    of compiling them here one by one). With ``load_scene`` the scenario's scene is
    read first then, and returned (a mistake in a model file is told before the
    minutes of compiling, not after them); else, and when nothing was compiled, None.
    """
    if kernels_cached(scenario) or not Path(scenario.path).is_file():
        return None
    scene = scenario.load_scene() if load_scene else None
    compile_in_children(scenario, stop=stop)
    return scene


def compile_in_children(scenario, stop=None, timeout: float = 600.0) -> bool:
    """Compile both halves for ``scenario`` (its file, with its tracing settings as
    they are now) in child processes at once; True when both finished cleanly.

    ``stop`` (a threading.Event) ends them early, e.g. when the app quits.
    """
    model = "geiger" if getattr(scenario, "geiger", False) else "ideal"
    settings = [scenario.backend, scenario.method, scenario.precision, model]
    children = []
    try:
        for half in HALVES:
            children.append(
                subprocess.Popen(
                    # -P: never a ladartui module in the working folder
                    [sys.executable, "-P", "-m", "ladartui.precompile", half, str(scenario.path), *settings],
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                )
            )
        deadline = time.monotonic() + timeout
        while any(child.poll() is None for child in children):
            if (stop is not None and stop.is_set()) or time.monotonic() > deadline:
                return False
            time.sleep(0.05)
        return all(child.returncode == 0 for child in children)
    except OSError:
        return False
    finally:  # (a Ctrl-C here too)
        _end(children)


def _end(children) -> None:
    for child in children:
        if child.poll() is None:
            child.kill()
        child.wait()


def _end_with_parent() -> None:
    """Exit when the process that started this one ends (killed, it cannot end us)."""
    import os
    import threading

    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


def main(argv=None) -> int:
    from ladartui.scenario import load_scenario

    _end_with_parent()
    half, path, backend, method, precision, model = sys.argv[1:] if argv is None else argv
    scenario = load_scenario(path).with_changes(backend=backend, method=method, precision=precision)
    if model == "geiger" and not scenario.geiger:  # a pulse study's looks
        from dataclasses import replace

        from ladartui.detection.settings import DetectionSettings

        detection = replace(scenario.detection or DetectionSettings(), model="geiger")
        scenario = scenario.with_changes(detection=detection)
    compile_half(half, scenario)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
