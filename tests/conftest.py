"""Suite-wide set-up: tests never write into the user's home folder; shared backends."""

import atexit
import os
import shutil
import tempfile

import pytest

# pytest-xdist starts its workers with COLUMNS=80 and LINES=24 set; the CLI takes
# COLUMNS as the width the user chose, so every test runs without them, in a worker
# as in one process.
for _name in ("COLUMNS", "LINES"):
    os.environ.pop(_name, None)

# The default scenario and benchmark scenes live under LADARTUI_HOME; point it
# at a throw-away folder before any test imports ladartui, removed at exit.
if "LADARTUI_HOME" not in os.environ:
    os.environ["LADARTUI_HOME"] = tempfile.mkdtemp(prefix="ladartui-test-home-")
    atexit.register(shutil.rmtree, os.environ["LADARTUI_HOME"], ignore_errors=True)
if "PYTEST_XDIST_WORKER" in os.environ:  # a home of its own (recent files, settings)
    os.environ["LADARTUI_HOME"] = os.path.join(os.environ["LADARTUI_HOME"], os.environ["PYTEST_XDIST_WORKER"])
    os.makedirs(os.environ["LADARTUI_HOME"], exist_ok=True)


@pytest.fixture(scope="module")
def wgpu_backend():
    """A fresh wgpu backend; the test is skipped where no adapter exists."""
    from ladartui.tracing.wgpu_backend import WgpuBackend

    backend = WgpuBackend()
    reason = backend.probe()
    if reason:
        pytest.skip(f"no wgpu adapter on this machine: {reason}")
    return backend


@pytest.fixture(scope="module")
def numba_backend():
    from ladartui.tracing.numba_backend import NumbaBackend

    return NumbaBackend()


@pytest.fixture(scope="module")
def scene_files(tmp_path_factory):
    """A small seeded forest for the TUI tests: (scene path, target centre, voxel size).

    Module-scoped; it also compiles the kernels once, so the apps skip their warm-up.
    """
    from ladartui.precompile import one_ray_run
    from ladartui.scene.generate import generate_scene
    from tui_support import make_scenario

    folder = tmp_path_factory.mktemp("scene")
    generated = generate_scene("small", seed=11, width=16.0, depth=16.0, trees=5)
    scene_path, _ = generated.write(folder / "forest")
    files = scene_path, tuple(float(v) for v in generated.target_centre), generated.voxel_size
    one_ray_run(make_scenario(folder, files, name="warm"))
    return files


@pytest.fixture(scope="session")
def finished(tmp_path_factory):
    """A sweep run to the end by the core (serially): its spec and results folder, made
    once for the sweep screen's tests, which copy it before they change it."""
    from sweep_screen_support import finished_sweep

    return finished_sweep(tmp_path_factory)
