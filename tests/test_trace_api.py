"""trace(): metres in and out, argument checks, backend choice and registry behaviour."""

import threading

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ladartui.errors import BackendUnavailable, Cancelled, FieldError
from ladartui.scene.occupancy import Occupancy
from ladartui.tracing import GROUND, MISS, VOXEL, TraceResult, choose_backend, trace
from ladartui.tracing.backend import backend_names, backend_status, get_backend
from ladartui.tracing.reference import reference_trace_cells


def make_block():
    g = np.arange(10, 20)
    vox = np.stack(np.meshgrid(g, g, np.arange(0, 5), indexing="ij"), -1).reshape(-1, 3)
    return Occupancy.build(vox, (40, 40, 10))


BLOCK = make_block()


@pytest.fixture
def block():
    return BLOCK


def test_ranges_and_indices_in_metres(block):
    size = 0.25
    # Straight down onto voxel (12, 13, 4): its top face is z = 4.5 voxels = 1.125 m.
    o = np.array([[12 * size, 13 * size, 10.0], [30 * size, 30 * size, 10.0]])
    d = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, -1.0]])
    r = trace(block, o, d, voxel_size=size)
    # "auto": numba, or wgpu where the adapter is a GPU (tests/test_wgpu_backend.py)
    assert isinstance(r, TraceResult) and r.backend == choose_backend() and r.method == "exact"
    assert r.kind.tolist() == [VOXEL, GROUND]
    assert r.index.tolist() == [[12, 13, 4], [30, 30, 0]]
    assert r.range[0] == pytest.approx(10.0 - 4.5 * size)
    assert r.range[1] == pytest.approx(10.0 + 0.5 * size)  # ground plane at z = -0.5 voxel
    assert r.as_array().shape == (2, 5)


def test_directions_are_normalised(block):
    o = np.array([[3.0, 3.0, 9.0]])
    a = trace(block, o, np.array([[1.0, 2.0, -3.0]]))
    b = trace(block, o, np.array([[1.0, 2.0, -3.0]]) * 7.5)
    assert a.kind[0] == b.kind[0] and np.array_equal(a.index, b.index)
    assert a.range[0] == pytest.approx(b.range[0])


def test_top_level_export_is_the_function():
    import ladartui.tracing  # noqa: F401  (a submodule import must not shadow the function)

    assert ladartui.trace is trace
    assert ladartui.Occupancy is Occupancy


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"method": "bogus"}, "method"),
        ({"method": "march", "step": 0}, "step"),
        ({"method": "march", "step": -1.0}, "step"),
        # a march this fine never ends (or its sample count overflows: misses)
        ({"method": "march", "step": 1e-12}, "step"),
        ({"method": "march", "step": 1e-7}, "step"),
        # True marched at one voxel a step, as if 1 had been given
        ({"method": "march", "step": True}, "step"),
        ({"method": "march", "step": np.True_}, "step"),
        ({"voxel_size": 0}, "voxel_size"),
        ({"precision": "f16"}, "precision"),
    ],
)
def test_bad_arguments_are_field_errors(block, kwargs, field):
    with pytest.raises(FieldError) as error:
        trace(block, np.zeros((2, 3)), np.ones((2, 3)), **kwargs)
    assert error.value.field == field


def test_bad_ray_arrays_are_field_errors(block):
    with pytest.raises(FieldError, match="directions"):
        trace(block, np.zeros((2, 3)), np.ones((3, 3)))
    with pytest.raises(FieldError, match="origins"):
        trace(block, np.zeros((2, 2)), np.ones((2, 2)))
    with pytest.raises(FieldError, match=r"directions\[1\]"):
        trace(block, np.zeros((2, 3)), np.array([[0, 0, -1.0], [0, 0, 0]]))
    with pytest.raises(FieldError):
        trace(block, np.full((1, 3), np.nan), np.ones((1, 3)))


def test_rays_of_true_and_false_are_refused_not_read_as_ones_and_zeros(block):
    """A mask given for the rays traced from (1, 1, 1) along (0, 0, 1), silently."""
    flags = np.array([[True, True, True]])
    with pytest.raises(
        FieldError, match=r"^origins is an array of bool: expected an \(N, 3\) array of numbers"
    ):
        trace(block, flags, np.ones((1, 3)))
    with pytest.raises(FieldError, match=r"^directions = \[\[False, False, True\]\]: expected an \(N, 3\)"):
        trace(block, np.zeros((1, 3)), [[False, False, True]])


def test_unknown_backend_is_a_field_error(block):
    with pytest.raises(FieldError, match="backend"):
        trace(block, np.zeros((1, 3)), np.ones((1, 3)), backend="nope")


@pytest.mark.parametrize("name", [["numba"], {"numba": 1}])
def test_a_backend_that_is_no_name_is_a_field_error(block, name):
    """backend=["numba"] failed with "unhashable type: 'list'" from the registry."""
    with pytest.raises(FieldError) as caught:
        trace(block, np.zeros((1, 3)), np.ones((1, 3)), backend=name)
    assert str(caught.value) == f"backend = {name!r}: expected one of auto, " + ", ".join(backend_names())


def test_registry_lists_numba_and_explains_unavailable_backends():
    assert "numba" in backend_names()
    status = backend_status()
    assert status["numba"] is None
    for name, reason in status.items():
        if reason is not None:
            with pytest.raises(BackendUnavailable):
                get_backend(name)
            assert name in reason


def test_cancel_before_start_raises(block):
    stop = threading.Event()
    stop.set()
    with pytest.raises(Cancelled):
        trace(block, np.zeros((5, 3)), np.ones((5, 3)), cancel=stop)


def test_empty_ray_list(block):
    r = trace(block, np.zeros((0, 3)), np.zeros((0, 3)))
    assert len(r) == 0 and r.index.shape == (0, 3)


def test_every_available_backend_agrees_with_numba():
    rng = np.random.default_rng(0)
    vox = rng.integers(0, (30, 30, 12), size=(800, 3))
    occ = Occupancy.build(vox, (30, 30, 12))
    o = rng.uniform([0, 0, 14], [30, 30, 30], size=(500, 3))
    d = rng.normal(size=(500, 3))
    d[:, 2] = -np.abs(d[:, 2])
    base = trace(occ, o, d, backend="numba")
    # numba against the slab reference, in cell space (a voxel's centre is its index in
    # metres at voxel size 1, its cell [i, i + 1)): kinds, cells and ranges.
    unit = d / np.linalg.norm(d, axis=1)[:, None]
    exact = reference_trace_cells(vox, (30, 30, 12), o + 0.5, unit)
    assert np.array_equal(base.kind, exact.kind) and np.array_equal(base.index, exact.index)
    assert np.allclose(base.range, exact.t, rtol=0, atol=1e-9)
    assert {VOXEL, GROUND} <= set(base.kind.tolist())  # the comparison covers both kinds of hit
    others = [name for name, reason in backend_status().items() if reason is None and name != "numba"]
    for name in others:
        other = trace(occ, o, d, backend=name, precision="f64")
        assert other.backend == name
        assert np.array_equal(other.kind, base.kind), name
        assert np.array_equal(other.index, base.index), name
        assert np.allclose(other.range, base.range, rtol=1e-12, atol=1e-9), name


@settings(max_examples=30, deadline=None)
@given(
    origins=st.lists(
        st.tuples(*[st.floats(-1e4, 1e4, allow_nan=False) for _ in range(3)]), min_size=1, max_size=8
    ),
    direction=st.tuples(*[st.floats(-1, 1, allow_nan=False) for _ in range(3)]).filter(
        lambda v: max(abs(c) for c in v) > 1e-6
    ),
    method=st.sampled_from(["exact", "march"]),
    size=st.floats(0.05, 5.0),
)
def test_no_crash_no_nan_valid_kinds(origins, direction, method, size):
    o = np.array(origins)
    d = np.tile(direction, (len(o), 1))
    block = BLOCK
    r = trace(block, o, d, method=method, voxel_size=size, step=1.0)
    assert set(r.kind.tolist()) <= {MISS, VOXEL, GROUND}
    assert not np.isnan(r.range).any()
    hit = r.kind != MISS
    assert np.all(r.range[hit] >= 0) and np.all(np.isinf(r.range[~hit]))
    assert np.all(r.index[~hit] == -1)
    assert np.all(r.index[hit] >= 0) and np.all(r.index[hit] < block.shape)


def test_a_scene_supplies_its_voxel_size():
    from ladartui.scene.model import Scene

    vox = np.array([[4, 4, 0], [4, 4, 1]])
    scene = Scene(vox, vox[:1], 0.5, shape=(10, 10, 10))
    r = trace(scene, np.array([[2.0, 2.0, 5.0]]), np.array([[0.0, 0.0, -1.0]]))
    assert r.kind[0] == VOXEL and r.index[0].tolist() == [4, 4, 1]
    assert r.range[0] == pytest.approx(5.0 - 1.5 * 0.5)  # top face of voxel 1 at z = 0.75 m
    same = trace(scene, np.array([[2.0, 2.0, 5.0]]), np.array([[0.0, 0.0, -1.0]]), voxel_size=0.5)
    assert same.range[0] == r.range[0]
    # another size put the scene's voxels elsewhere in metres: a wrong answer, silently
    with pytest.raises(
        FieldError, match=r"^voxel_size = 2\.0: expected the scene's voxel size \(0\.5\) or None"
    ):
        trace(scene, np.array([[2.0, 2.0, 5.0]]), np.array([[0.0, 0.0, -1.0]]), voxel_size=2.0)


def test_registry_lists_every_builtin_backend_even_after_a_direct_import():
    # Importing one backend module first must not hide the others.
    import subprocess
    import sys

    code = (
        "import ladartui.tracing.wgpu_backend\n"
        "from ladartui.tracing.backend import backend_names\n"
        "print(sorted(backend_names()))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "['numba', 'wgpu']"


def test_every_public_name_resolves_and_unknown_names_fail():
    # The lazy exports of the package and of ladartui.scene point at real objects.
    import ladartui.scene

    for package in (ladartui, ladartui.scene):
        for name in package.__all__:
            assert getattr(package, name) is not None, (package.__name__, name)
    with pytest.raises(AttributeError, match="has no attribute 'no_such_name'"):
        _ = ladartui.scene.no_such_name


def test_ranges_are_scaled_without_touching_a_backends_own_arrays(block, monkeypatch):
    # trace() turns the backend's cell ranges into metres in place when the array is
    # the backend's own new one; an array that is a view (of memory the backend
    # keeps) is copied instead, so the backend's memory keeps its cell ranges.
    from ladartui.tracing import backend as registry
    from ladartui.tracing.backend import CellHits

    kept = np.arange(6.0)

    class KeepsItsRanges:
        def probe(self):
            return None

        def trace_cells(self, occupancy, origins, directions, **kwargs):
            n = len(origins)
            ranges = kept[:n] if kwargs.get("step") == 0.25 else np.arange(float(n))
            return CellHits(np.ones(n, np.uint8), np.zeros((n, 3), np.int32), ranges, {})

    monkeypatch.setitem(registry._FACTORIES, "keeps", KeepsItsRanges)
    monkeypatch.setattr(registry, "_INSTANCES", dict(registry._INSTANCES))
    origins = np.zeros((3, 3))
    directions = np.tile([0.0, 0.0, -1.0], (3, 1))
    fresh = trace(block, origins, directions, backend="keeps", voxel_size=0.5)
    assert np.array_equal(fresh.range, [0.0, 0.5, 1.0])
    viewed = trace(block, origins, directions, backend="keeps", voxel_size=0.5, step=0.25)
    assert np.array_equal(viewed.range, [0.0, 0.5, 1.0])
    assert np.array_equal(kept, np.arange(6.0))


def test_the_finest_march_step_is_taken_and_named_when_refused(block):
    from ladartui.tracing.config import MIN_STEP

    origins, directions = np.zeros((2, 3)) + [1.5, 1.5, 9.0], np.tile([0.0, 0.0, -1.0], (2, 1))
    fine = trace(block, origins, directions, method="march", step=MIN_STEP, backend="numba")
    exact = trace(block, origins, directions, backend="numba")
    assert np.array_equal(fine.kind, exact.kind) and np.array_equal(fine.index, exact.index)
    with pytest.raises(FieldError) as error:
        trace(block, origins, directions, method="march", step=MIN_STEP / 2)
    assert str(error.value) == f"step = {MIN_STEP / 2!r}: expected a number of voxels from 0.001"


@pytest.mark.parametrize("name", ["numba", "wgpu"])
def test_each_backend_refuses_a_march_step_too_fine_itself(block, name):
    """Backends are called directly too (trace_cells): the same floor as trace()'s."""
    from ladartui.tracing import get_backend
    from ladartui.tracing.backend import BackendUnavailable

    try:
        backend = get_backend(name)
    except BackendUnavailable:
        pytest.skip(f"{name} unavailable here")
    origins, directions = np.zeros((2, 3)) + [1.5, 1.5, 9.0], np.tile([0.0, 0.0, -1.0], (2, 1))
    with pytest.raises(FieldError, match="from 0.001"):
        backend.trace_cells(block, origins, directions, method="march", step=1e-7)


def test_complex_rays_and_a_cancel_that_is_no_event_are_field_errors(block):
    """Complex rays lost their imaginary parts with only numpy's warning; cancel=True
    ended in an AttributeError from deep inside the backend."""
    origins, directions = np.zeros((2, 3)) + [1.5, 1.5, 9.0], np.tile([0.0, 0.0, -1.0], (2, 1))
    with pytest.raises(FieldError) as error:
        trace(block, origins + 1j, directions)
    assert error.value.field == "origins" and "real numbers" in str(error.value)
    with pytest.raises(FieldError) as error:
        trace(block, origins, directions.astype(complex))
    assert error.value.field == "directions"
    with pytest.raises(FieldError) as error:
        trace(block, origins, directions, cancel=True)
    assert str(error.value) == "cancel = True: expected a threading.Event (or None)"


def test_a_value_of_the_wrong_kind_is_told_by_its_kind_not_quoted_as_text():
    """An argument of the wrong type was named by its type in quotes, as if the caller had
    written that text ("scene = 'dict'", "origins = 'array of shape (4,)'")."""
    from ladartui import trace
    from ladartui.errors import FieldError, described

    class Scenario:  # given where its scene was meant
        pass

    with pytest.raises(FieldError, match=r"^scene is a Scenario: expected a Scene or an Occupancy$"):
        trace(Scenario(), np.zeros((1, 3)), np.ones((1, 3)))
    with pytest.raises(
        FieldError, match=r"^origins is an array of shape \(4,\): expected an \(N, 3\) array$"
    ):
        trace(Occupancy.build(np.zeros((1, 3), np.int64)), np.zeros(4), np.ones((1, 3)))
    assert str(FieldError("x", described(object()), "a number")) == "x is an object: expected a number"
    assert (
        str(FieldError("x", described(np.zeros((4, 2))), "(N, 3)"))
        == "x is an array of shape (4, 2): expected (N, 3)"
    )
    assert str(FieldError("x", described("text"), "a number")) == "x = 'text': expected a number"
    assert str(FieldError("x", described(7), "a list")) == "x = 7: expected a list"
    # a numpy number is the number it holds; what was given is told, not numpy's conversion
    assert str(FieldError("x", described(np.float64(2.5)), "a list")) == "x = 2.5: expected a list"
    with pytest.raises(FieldError, match=r"^origins is not set: expected an \(N, 3\) array"):
        trace(Occupancy.build(np.zeros((1, 3), np.int64)), None, np.ones((1, 3)))
