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


def tiny_folder(tmp_path_factory):
    """A new folder holding the tiny base scenario (for a module-scoped fixture)."""
    folder = tmp_path_factory.mktemp("tiny")
    write_tiny_scenario(folder)
    return folder


def write_spec(folder, body, name="spec.toml", scenario="base.toml"):
    """A sweep spec over ``scenario`` with ``body`` after its [sweep] table."""
    path = folder / name
    path.write_text(f'[sweep]\nscenario = "{scenario}"\n{body}', encoding="utf-8")
    return path


TWO_CENTRE = (15.5, 15.5, 0.5)


def write_two_target_scenario(folder, name="two.toml"):
    """Two 3 x 3 x 2 vehicles on open ground, "open" (id 1) and "roofed" (id 2) under a solid
    roof two voxels above it: a path looking down (high, close) never sees the roofed one;
    a path low beside it sees its sides under the roof."""
    from ladartui.flight import FlightPlan, Orbit
    from ladartui.scenario import Scenario
    from ladartui.scene.voxels import save_voxels
    from ladartui.sensor import Sensor

    def box(x0, y0):
        return [(i, j, k) for i in range(x0, x0 + 3) for j in range(y0, y0 + 3) for k in range(2)]

    open_box, roofed = box(8, 8), box(20, 20)
    target = np.array(open_box + roofed, np.int32)
    ids = np.array([1] * len(open_box) + [2] * len(roofed), np.int32)
    roof = np.array([(i, j, 3) for i in range(18, 25) for j in range(18, 25)], np.int32)
    save_voxels(folder / "two.txt", np.concatenate([target, roof]))
    save_voxels(folder / "two_Target.txt", target, ids=ids)
    flight = FlightPlan(segments=(Orbit(centre=TWO_CENTRE, radius=30.0, altitude=2.0, scans=4),))
    scenario = Scenario(
        folder / name,
        "two.txt",
        1.0,
        Sensor(grid=16, ray_grid=2, fov=50.0),
        flight,
        backend="numba",
        target_names=((1, "open"), (2, "roofed")),
    )
    return scenario.save()


# Identification at 30 % of a target's visible voxels and footprint, so the low paths identify both.
TWO_LEVELS = (0.1, 0.2, 0.3, 0.1, 0.2, 0.3)


def write_two_target_spec(folder, objective):
    """The two-target scenario (thresholds ``TWO_LEVELS``) and a 4-variant spec: altitude 2 or
    40 m, orbit radius 5 or 30 m."""
    from ladartui.levels import LevelThresholds

    base = write_two_target_scenario(folder)
    base.with_changes(levels=LevelThresholds(*TWO_LEVELS)).save()
    spec = folder / "two-spec.toml"
    spec.write_text(
        f'[sweep]\nscenario = "two.toml"\nobjective = "{objective}"\nbudget = 2.0\n'
        "[grid]\naltitude = [2.0, 40.0]\nradius = [5.0, 30.0]\n",
        encoding="utf-8",
    )
    return spec
