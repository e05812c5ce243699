"""The tiny base scenario the sweep tests share (a module, not a test file: tests import it)."""

import numpy as np

CENTRE = (15.5, 15.5, 0.5)


def write_tiny_scenario(folder, name="base.toml"):
    """A 32 x 32 canopy with gaps over a 4 x 2 x 2 vehicle, 8 x 8 detectors, a 4-scan orbit."""
    from ladartui.flight import FlightPlan, Orbit
    from ladartui.scenario import Scenario
    from ladartui.scene.voxels import save_voxels
    from ladartui.sensor import Sensor

    target = np.array([(i, j, k) for i in range(14, 18) for j in range(15, 17) for k in range(2)], np.int32)
    canopy = np.array(
        [(i, j, 6) for i in range(32) for j in range(32) if (i * 7 + j * 13) % 3 == 0], np.int32
    )
    save_voxels(folder / "tiny.txt", np.concatenate([target, canopy]))
    save_voxels(folder / "tiny_Target.txt", target)
    flight = FlightPlan(segments=(Orbit(centre=CENTRE, radius=20.0, altitude=20.0, scans=4),))
    scenario = Scenario(
        folder / name, "tiny.txt", 1.0, Sensor(grid=8, ray_grid=2, fov=20.0), flight, backend="numba"
    )
    return scenario.save()
