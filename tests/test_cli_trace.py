"""``ladartui trace`` from the command line: its outputs, flags and messages."""

import numpy as np
import pytest

from cli_support import file_size_limit, one_error_line
from ladartui.cli import main


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "X.txt"
    path.write_text("5,5,0\n5,5,1\n6,5,1\n9,9,3\n")
    return path


def test_trace_writes_hits(tmp_path, scene_file, capsys):
    rays = np.array(
        [
            [5.0, 5.0, 20.0, 0.0, 0.0, -1.0],  # onto voxel (5, 5, 1), top face at z = 1.5
            [2.0, 2.0, 20.0, 0.0, 0.0, -1.0],  # ground at (2, 2)
            [2.0, 2.0, 20.0, 0.0, 0.0, 1.0],  # upward: miss
        ]
    )
    np.save(tmp_path / "rays.npy", rays)
    out = tmp_path / "hits.npy"
    code = main(
        [
            "trace",
            "--scene",
            str(scene_file),
            "--rays",
            str(tmp_path / "rays.npy"),
            "--out",
            str(out),
            "--backend",
            "numba",
        ]
    )
    assert code == 0
    hits = np.load(out)
    assert hits.shape == (3, 5) and hits.dtype == np.float64
    assert hits[0, :4].tolist() == [1, 5, 5, 1] and hits[0, 4] == pytest.approx(18.5)
    assert hits[1, :4].tolist() == [2, 2, 2, 0] and hits[1, 4] == pytest.approx(20.5)
    assert hits[2, 0] == 0 and np.isinf(hits[2, 4])
    err = capsys.readouterr().err
    # the voxel size was not given: a user of a 0.25 m scene must see 1 m was assumed
    assert err == (
        "3 rays (numba, exact, f64), voxel size 1 m (assumed; --voxel-size sets it): "
        f"1 voxel hit, 1 ground hit, 1 miss -> {out}\n"
    )


def test_the_summary_writes_every_count_with_thousands_separators(tmp_path, scene_file, capsys):
    """It read '4,000,000 rays ...: 1032144 voxel, 1595342 ground, ...', and '2 voxel'."""
    rays = np.repeat(
        [[5.0, 5.0, 20.0, 0.0, 0.0, -1.0], [2.0, 2.0, 20.0, 0.0, 0.0, -1.0]], [1200, 3400], axis=0
    )
    np.save(tmp_path / "rays.npy", rays)
    out = tmp_path / "hits.npy"
    args = ["trace", "--scene", str(scene_file), "--rays", str(tmp_path / "rays.npy"), "--out", str(out)]
    assert main([*args, "--voxel-size", "1"]) == 0
    assert capsys.readouterr().err.endswith(f": 1,200 voxel hits, 3,400 ground hits, 0 misses -> {out}\n")


def test_trace_march_with_voxel_size(tmp_path, scene_file, capsys):
    rays = np.array([[1.25, 1.25, 10.0, 0.0, 0.0, -1.0]])  # 0.25 m voxels: cell (5, 5)
    np.save(tmp_path / "rays.npy", rays)
    out = tmp_path / "hits.npy"
    assert (
        main(
            [
                "trace",
                "--scene",
                str(scene_file),
                "--rays",
                str(tmp_path / "rays.npy"),
                "--out",
                str(out),
                "--method",
                "march",
                "--step",
                "0.25",
                "--voxel-size",
                "0.25",
            ]
        )
        == 0
    )
    assert np.load(out)[0, :4].tolist() == [1, 5, 5, 1]
    # given: not "assumed"; one ray, not "1 rays"
    assert capsys.readouterr().err.startswith("1 ray (numba, march, f64), voxel size 0.25 m: 1 voxel hit,")


def _three_rays(tmp_path):
    rays = np.array(
        [
            [5.0, 5.0, 20.0, 0.0, 0.0, -1.0],
            [2.0, 2.0, 20.0, 0.0, 0.0, -1.0],
            [2.0, 2.0, 20.0, 0.0, 0.0, 1.0],
        ]
    )
    np.save(tmp_path / "rays.npy", rays)
    return tmp_path / "rays.npy"


def test_trace_precision_f32_on_wgpu(tmp_path, scene_file, capsys, wgpu_backend):
    rays = _three_rays(tmp_path)
    hits = {}
    for precision in ("f64", "f32"):
        out = tmp_path / f"hits-{precision}.npy"
        assert (
            main(
                [
                    "trace",
                    "--scene",
                    str(scene_file),
                    "--rays",
                    str(rays),
                    "--out",
                    str(out),
                    "--backend",
                    "wgpu",
                    "--precision",
                    precision,
                ]
            )
            == 0
        )
        hits[precision] = np.load(out)
        err = capsys.readouterr().err
    # the message names the arithmetic the backend used
    assert "wgpu, exact, f32" in err
    np.testing.assert_array_equal(hits["f32"][:, :4], hits["f64"][:, :4])
    assert hits["f32"][0, 4] == pytest.approx(18.5)


def test_trace_precision_reported_and_checked(tmp_path, scene_file, capsys):
    rays = _three_rays(tmp_path)
    out = tmp_path / "hits.npy"
    assert (
        main(
            [
                "trace",
                "--scene",
                str(scene_file),
                "--rays",
                str(rays),
                "--out",
                str(out),
                "--backend",
                "numba",
                "--precision",
                "f32",
            ]
        )
        == 0
    )
    # numba has only f64 kernels: the line says what was traced, and that f32 was asked
    assert "(numba, exact, f64, not the f32 asked for)" in capsys.readouterr().err
    with pytest.raises(SystemExit) as stop:
        main(
            [
                "trace",
                "--scene",
                str(scene_file),
                "--rays",
                str(rays),
                "--out",
                str(out),
                "--precision",
                "f16",
            ]
        )
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "--precision" in err and "f16" in err and "Traceback" not in err


@pytest.mark.parametrize(
    "array, expected",
    [
        (np.zeros((4, 5)), "(4, 5)"),
        (np.zeros(6), "(6,)"),
        (np.array([[0, 0, 1, 0, 0, 0.0]]), "zero direction"),
    ],
)
def test_bad_rays_file_is_one_clear_line(tmp_path, scene_file, capsys, array, expected):
    np.save(tmp_path / "rays.npy", array)
    out = tmp_path / "hits.npy"
    out.write_bytes(b"earlier")
    code = main(
        ["trace", "--scene", str(scene_file), "--rays", str(tmp_path / "rays.npy"), "--out", str(out)]
    )
    err = capsys.readouterr().err
    assert code == 2
    assert "rays.npy" in err and expected in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert out.read_bytes() == b"earlier"  # nothing overwritten


def test_missing_and_non_npy_rays(tmp_path, scene_file, capsys):
    (tmp_path / "rays.npy").write_text("not numpy")
    for rays in (tmp_path / "none.npy", tmp_path / "rays.npy"):
        code = main(
            ["trace", "--scene", str(scene_file), "--rays", str(rays), "--out", str(tmp_path / "h.npy")]
        )
        assert code == 2
        assert rays.name in capsys.readouterr().err
    assert not (tmp_path / "h.npy").exists()


@pytest.mark.parametrize(
    "content, said",
    [
        (b"hello\n\n", "not a NumPy .npy file (no .npy header)"),  # 7 bytes of text
        (b"\x93NUM", "empty or cut short: expected a NumPy .npy array"),  # the magic, cut
        (b"", "empty or cut short: expected a NumPy .npy array"),
    ],
)
def test_a_short_file_of_other_bytes_is_not_called_cut_short(tmp_path, scene_file, capsys, content, said):
    """A 7-byte text file was 'empty or cut short', as if it were a .npy file cut short."""
    rays = tmp_path / "rays.npy"
    rays.write_bytes(content[:7])
    out = tmp_path / "h.npy"
    assert main(["trace", "--scene", str(scene_file), "--rays", str(rays), "--out", str(out)]) == 2
    assert one_error_line(capsys) == f"ladartui: error: {rays}: {said}"
    assert not out.exists()


def test_a_missing_scene_is_said_missing_without_the_line_format(tmp_path, capsys):
    """--scene naming no file was told the format of a voxel list's lines."""
    rays = _three_rays(tmp_path)
    scene = tmp_path / "nothere.txt"
    assert main(["trace", "--scene", str(scene), "--rays", str(rays), "--out", str(tmp_path / "h.npy")]) == 2
    assert one_error_line(capsys) == f"ladartui: error: {scene}: no such file; expected a voxel-list file"


def test_npz_and_object_rays_and_a_bad_out_are_one_line(tmp_path, scene_file, capsys):
    rays = np.array([[5.0, 5.0, 20.0, 0.0, 0.0, -1.0]])
    np.savez(tmp_path / "rays.npz", rays=rays)
    np.save(tmp_path / "objects.npy", np.array([{"a": 1}], dtype=object), allow_pickle=True)
    np.save(tmp_path / "rays.npy", rays)

    def trace(rays_file, out):
        code = main(["trace", "--scene", str(scene_file), "--rays", str(rays_file), "--out", str(out)])
        return code, capsys.readouterr().err.strip()

    code, err = trace(tmp_path / "rays.npz", tmp_path / "h.npy")
    assert code == 2 and err == (
        f"ladartui: error: {tmp_path / 'rays.npz'}: a NumPy .npz archive: "
        "expected one (N, 6) array in a .npy file"
    )
    code, err = trace(tmp_path / "objects.npy", tmp_path / "h.npy")
    assert code == 2 and err == (
        f"ladartui: error: {tmp_path / 'objects.npy'}: holds Python objects: "
        "expected an (N, 6) array of numbers"
    )
    code, err = trace(tmp_path / "rays.npy", tmp_path / "missing" / "h.npy")
    assert code == 2 and err == (
        f"ladartui: error: --out = '{tmp_path / 'missing' / 'h.npy'}': expected a file in an existing folder"
    )
    assert not (tmp_path / "missing").exists()
    code, err = trace(tmp_path / "rays.npy", tmp_path / "rays.npy")
    assert (
        code == 2
        and err == f"ladartui: error: --out = '{tmp_path / 'rays.npy'}': expected a file other than --rays"
    )
    assert np.array_equal(np.load(tmp_path / "rays.npy"), rays)


def test_a_rays_file_is_checked_from_its_header_before_it_is_read(tmp_path, scene_file, capsys):
    """A header claiming 10**10 rows ended in a MemoryError traceback; a text file was
    said to hold Python objects. The header says what the file holds, before loading."""
    import numpy.lib.format as npy

    huge = tmp_path / "huge.npy"
    with open(huge, "wb") as handle:
        npy.write_array_header_1_0(handle, {"descr": "<f8", "fortran_order": False, "shape": (10**10, 6)})
        handle.write(b"\0" * 48)
    text = tmp_path / "text.npy"
    text.write_text("not numpy\n")

    def trace(rays_file):
        code = main(
            ["trace", "--scene", str(scene_file), "--rays", str(rays_file), "--out", str(tmp_path / "h")]
        )
        return code, capsys.readouterr().err.strip()

    code, err = trace(huge)
    assert code == 2 and len(err.splitlines()) == 1, err
    assert f"{huge}: about 1e+10 rays to trace, more than the limit" in err
    assert err.endswith("(raise it with LADARTUI_MAX_RAYS if this is meant)")  # trace has no --max-rays
    code, err = trace(text)
    assert code == 2 and err == f"ladartui: error: {text}: not a NumPy .npy file (no .npy header)"
    assert not (tmp_path / "h").exists()


def test_a_scene_too_large_to_trace_is_named_by_its_file(tmp_path, capsys):
    far = tmp_path / "far.txt"
    far.write_text("0,0,0\n100000000,100000000,1000\n")  # its root grid alone: about 284 GiB
    rays = tmp_path / "rays.npy"
    np.save(rays, np.array([[5.0, 5.0, 50.0, 0.0, 0.0, -1.0]]))
    code = main(["trace", "--scene", str(far), "--rays", str(rays), "--out", str(tmp_path / "h.npy")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and err.startswith(
        f"ladartui: error: {far}: 2 voxels spanning 100000001 x 100000001 x 1001"
    )


def test_a_march_step_too_fine_names_the_flag(tmp_path, scene_file, capsys):
    """At 1e-7 voxels wgpu's march answered misses and numba's ran without end."""
    rays = _three_rays(tmp_path)
    out = tmp_path / "hits.npy"
    command = ["trace", "--scene", str(scene_file), "--rays", str(rays), "--out", str(out)]
    assert main([*command, "--method", "march", "--step", "1e-7", "--voxel-size", "0.25"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "ladartui: error: --step = 1e-07: expected a number from 0.001 to 10"
    assert not out.exists()


@pytest.mark.parametrize("size", ["inf", "nan", "-1", "0", "1e308", "101", "1e-300", "0.0009"])
def test_trace_and_info_refuse_the_same_voxel_sizes(tmp_path, scene_file, capsys, size):
    """'--voxel-size inf' was named 'voxel_size'; info took inf and 1e308 and showed an
    extent of 'inf x inf x inf' m. Both refuse what a scenario's files.voxel_size refuses."""
    rays = _three_rays(tmp_path)
    out = tmp_path / "hits.npy"
    expected = (
        f"ladartui: error: --voxel-size = {float(size)!r}: expected a number of metres from 0.001 to 100"
    )
    command = ["trace", "--scene", str(scene_file), "--rays", str(rays), "--out", str(out)]
    assert main([*command, "--voxel-size", size]) == 2
    assert one_error_line(capsys) == expected
    assert not out.exists()
    assert main(["info", str(scene_file), "--voxel-size", size]) == 2
    assert one_error_line(capsys) == expected


def test_an_empty_or_folder_path_names_its_flag(tmp_path, scene_file, capsys, monkeypatch):
    """'--out ""' said '.: is a folder, expected a file name', naming no flag."""
    monkeypatch.chdir(tmp_path)
    rays = _three_rays(tmp_path)
    given = {"--scene": str(scene_file), "--rays": str(rays), "--out": str(tmp_path / "hits.npy")}
    for flag in given:
        command = ["trace"] + [
            part for name, value in given.items() for part in (name, "" if name == flag else value)
        ]
        assert main(command) == 2
        assert one_error_line(capsys) == f"ladartui: error: {flag} = '': expected a file name"
    (tmp_path / "folder").mkdir()
    assert main(["trace", "--scene", str(scene_file), "--rays", str(rays), "--out", "folder"]) == 2
    assert one_error_line(capsys) == "ladartui: error: --out = 'folder': expected a file name, not a folder"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["X.txt", "folder", "rays.npy"]


def test_a_step_without_the_march_is_refused_naming_both_flags(tmp_path, scene_file, capsys):
    """'--step 0.3' without '--method march' was dropped without a word."""
    rays = _three_rays(tmp_path)
    out = tmp_path / "hits.npy"
    command = ["trace", "--scene", str(scene_file), "--rays", str(rays), "--out", str(out), "--step", "0.3"]
    for method in ([], ["--method", "exact"]):
        assert main([*command, *method]) == 2
        assert one_error_line(capsys) == (
            "ladartui: error: --step 0.3 sets the march's step, and this trace is --method exact: "
            "add --method march, or drop --step"
        )
    assert not out.exists()
    assert main([*command, "--method", "march"]) == 0 and out.is_file()


def test_a_bad_ray_is_named_by_its_row_from_1_and_its_index(tmp_path, scene_file, capsys):
    """The second row was 'row 1': file lines are counted from 1 everywhere else."""
    good = [5.0, 5.0, 20.0, 0.0, 0.0, -1.0]
    for bad, says in (
        ([2.0, 2.0, 20.0, 0.0, 0.0, 0.0], "has a zero direction: expected a unit vector"),
        ([np.nan, 2.0, 20.0, 0.0, 0.0, -1.0], "is not finite: expected finite numbers"),
        # so far that f64 has no room left for the voxels: at 1e16 m the hit was the wrong
        # voxel, from 1e17 m ground (where the f32 GPU shader was still right)
        (
            [5.0, 5.0, 1e16, 0.0, 0.0, -1.0],
            "has its origin 1e+16 m from the scene's origin: expected within 1,000,000 m, "
            "as a scenario's points",
        ),
    ):
        np.save(tmp_path / "rays.npy", np.array([good, bad, bad]))
        command = ["trace", "--scene", str(scene_file), "--rays", str(tmp_path / "rays.npy")]
        assert main([*command, "--out", str(tmp_path / "h.npy")]) == 2
        assert one_error_line(capsys) == f"ladartui: error: {tmp_path / 'rays.npy'}: row 2 (index 1) {says}"


def test_ctrl_c_or_sigterm_says_what_was_written(tmp_path, scene_file, capsys, monkeypatch):
    """A Ctrl-C said only 'interrupted', where run and voxelize say nothing was written."""
    import signal

    import ladartui.cli.trace as cli_trace
    import ladartui.tracing as tracing

    rays = _three_rays(tmp_path)
    out = tmp_path / "hits.npy"
    out.write_bytes(b"earlier")
    command = ["trace", "--scene", str(scene_file), "--rays", str(rays), "--out", str(out)]
    real_trace = tracing.trace

    def stopped(*args, **kwargs):
        handler = signal.getsignal(signal.SIGTERM)
        assert callable(handler), "SIGTERM is not taken as a stop while tracing"
        handler(signal.SIGTERM, None)  # as `kill` would

    monkeypatch.setattr(tracing, "trace", stopped)
    assert main(command) == 143
    assert capsys.readouterr().err == f"ladartui: trace cancelled; nothing was written, {out} is unchanged\n"
    assert out.read_bytes() == b"earlier"
    out.unlink()

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(tracing, "trace", interrupted)
    assert main(command) == 130
    assert capsys.readouterr().err == "ladartui: trace cancelled; nothing was written\n"
    assert sorted(tmp_path.iterdir()) == sorted([scene_file, rays])  # no temporary left either

    def interrupted_while_saying(text):
        raise KeyboardInterrupt  # a Ctrl-C landing once the hits were written

    monkeypatch.setattr(tracing, "trace", real_trace)
    monkeypatch.setattr(cli_trace, "single_line", interrupted_while_saying)
    assert main(command) == 130
    assert capsys.readouterr().err == f"ladartui: interrupted after the trace; it wrote {out}\n"
    assert np.load(out).shape == (3, 5)


@pytest.mark.parametrize("step", ["inf", "11", "0"])
def test_a_march_step_is_held_to_the_limits_run_holds_it_to(tmp_path, scene_file, capsys, step):
    """trace took --step 50 where run refuses past 10, and said 'from 0.001' of inf."""
    rays = _three_rays(tmp_path)
    out = tmp_path / "hits.npy"
    command = ["trace", "--scene", str(scene_file), "--rays", str(rays), "--out", str(out)]
    assert main([*command, "--method", "march", "--step", step]) == 2
    assert (
        one_error_line(capsys)
        == f"ladartui: error: --step = {float(step)!r}: expected a number from 0.001 to 10"
    )
    assert not out.exists()


def test_out_may_not_be_the_scene_it_traces(tmp_path, scene_file, capsys):
    """--out naming the --scene file wrote the hits over the scene model."""
    np.save(tmp_path / "rays.npy", np.array([[5.0, 5.0, 20.0, 0.0, 0.0, -1.0]]))
    before = scene_file.read_bytes()
    code = main(
        ["trace", "--scene", str(scene_file), "--rays", str(tmp_path / "rays.npy"), "--out", str(scene_file)]
    )
    assert code == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: --out = '{scene_file}': expected a file other than --scene"
    )
    assert scene_file.read_bytes() == before


def test_a_long_trace_shows_its_progress_in_blocks_of_rays(tmp_path, scene_file, capsys, monkeypatch):
    """20 million rays traced for seconds, after seconds of reading, with nothing on the
    terminal: the rays are now traced in blocks, the bar counting them (same hits)."""
    import io

    from rich.console import Console

    import ladartui.cli.console as cli_console
    import ladartui.cli.trace as cli_trace
    import ladartui.tracing as tracing

    rays = np.array([[x + 0.5, 5.0, 20.0, 0.0, 0.0, -1.0] for x in range(5)])
    np.save(tmp_path / "rays.npy", rays)
    command = [
        "trace",
        "--scene",
        str(scene_file),
        "--rays",
        str(tmp_path / "rays.npy"),
        "--backend",
        "numba",
    ]
    assert main([*command, "--out", str(tmp_path / "whole.npy")]) == 0
    terminal = io.StringIO()
    monkeypatch.setattr(
        cli_console, "CliConsole", lambda **kwargs: Console(file=terminal, force_terminal=True, width=80)
    )
    monkeypatch.setattr(cli_trace, "TRACE_BLOCK", 2)
    calls = []
    real_trace = tracing.trace

    def counted(occupancy, origins, directions, **kwargs):
        calls.append(len(origins))
        return real_trace(occupancy, origins, directions, **kwargs)

    monkeypatch.setattr(tracing, "trace", counted)
    capsys.readouterr()
    # A long folder (as the tests' own in several processes) cut the count off at 80
    # columns: the bar names the file alone.
    deep = tmp_path / ("folder-" * 12)
    deep.mkdir()
    assert main([*command, "--out", str(deep / "blocks.npy")]) == 0
    assert calls == [2, 2, 1]
    assert np.array_equal(np.load(deep / "blocks.npy"), np.load(tmp_path / "whole.npy"), equal_nan=True)
    assert "5/5 rays" in terminal.getvalue() and "writing blocks.npy" in terminal.getvalue()
    assert capsys.readouterr().err.startswith("5 rays (numba, exact, f64)")

    def last_block_in_f32(occupancy, origins, directions, **kwargs):
        # as auto may choose by block: a GPU's f32 for one, numba's f64 for another
        result = real_trace(occupancy, origins, directions, **kwargs)
        if len(origins) == 1:
            result.info["precision"] = "f32"
        return result

    monkeypatch.setattr(tracing, "trace", last_block_in_f32)
    assert main([*command, "--out", str(deep / "mixed.npy")]) == 0
    # the summary gave the last block's precision as the whole run's: "f32, not the f64 asked for"
    assert capsys.readouterr().err.startswith("5 rays (numba, exact, f64 for 4 rays, f32 for 1)")


def test_hits_that_cannot_be_written_are_one_line_naming_the_out_file(tmp_path, scene_file, capsys):
    """A write failing part way (a file size limit) ended in numpy's traceback, 'OSError:
    400000 requested and 65408 written'; the earlier hits are kept."""
    rays = np.repeat([[5.0, 5.0, 20.0, 0.0, 0.0, -1.0]], 10_000, axis=0)  # 400,000 bytes of hits
    np.save(tmp_path / "rays.npy", rays)
    out = tmp_path / "hits.npy"
    command = ["trace", "--scene", str(scene_file), "--rays", str(tmp_path / "rays.npy"), "--out", str(out)]
    assert main([*command, "--backend", "numba"]) == 0  # the earlier hits, the kernels compiled
    capsys.readouterr()
    earlier = out.read_bytes()
    with file_size_limit(100_000):
        code = main([*command, "--backend", "numba"])
    assert code == 2
    assert one_error_line(capsys) == f"ladartui: error: {out}: cannot be written (file too large)"
    assert out.read_bytes() == earlier
    assert sorted(p.name for p in tmp_path.iterdir()) == ["X.txt", "hits.npy", "rays.npy"]
