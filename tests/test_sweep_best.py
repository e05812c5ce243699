"""The best flight path's scenario file: a sweep replaces its own, never the analyst's edits."""

import pytest

from ladartui.scenario import load_scenario
from ladartui.sweep import run_sweep
from ladartui.sweep.best_file import best_files, write_best_scenario
from tiny_sweep import write_tiny_scenario


@pytest.fixture
def base(tmp_path):
    return write_tiny_scenario(tmp_path)


def _write(base, out, radius, variant="v1"):
    row = {"variant": variant, "radius": radius}
    return write_best_scenario(out / "base-best.toml", base, row, ["radius"], base.load_scene)


def _radius(path) -> float:
    return load_scenario(path).flight.segments[0].radius


def test_a_later_best_path_replaces_the_sweeps_own_unedited_file(base, tmp_path):
    first = _write(base, tmp_path, 35.0)
    assert first.path == tmp_path / "base-best.toml" and first.kept is None
    second = _write(base, tmp_path, 45.0, "v2")
    assert second.path == first.path and second.kept is None
    assert _radius(second.path) == 45.0
    assert not (tmp_path / "base-best-2.toml").exists()


def test_a_best_path_saved_with_edits_is_kept_and_the_next_goes_beside_it(base, tmp_path):
    first = _write(base, tmp_path, 35.0)
    # the analyst opens it, changes the speed and saves (comments and layout kept)
    edited = load_scenario(first.path)
    edited.with_changes(speed=edited.speed + 10).save()
    mine = first.path.read_bytes()
    again = _write(base, tmp_path, 45.0, "v2")
    assert first.path.read_bytes() == mine
    assert again.kept == first.path and again.path == tmp_path / "base-best-2.toml"
    assert _radius(again.path) == 45.0
    # the file beside it is the sweep's own: the next best path replaces it
    third = _write(base, tmp_path, 55.0, "v3")
    assert third.path == again.path and third.kept == first.path
    assert _radius(third.path) == 55.0 and first.path.read_bytes() == mine


def test_a_file_the_sweep_did_not_write_is_never_replaced(base, tmp_path):
    own = tmp_path / "base-best.toml"
    own.write_text(base.path.read_text(encoding="utf-8"), encoding="utf-8")  # no fingerprint
    before = own.read_bytes()
    written = _write(base, tmp_path, 35.0)
    assert own.read_bytes() == before and written.kept == own
    assert written.path == tmp_path / "base-best-2.toml"


def test_best_files_lists_the_files_sweeps_wrote_newest_first(base, tmp_path):
    import os

    first = _write(base, tmp_path, 35.0)
    load_scenario(first.path).with_changes(speed=12.0).save()  # edited: still a best path
    second = _write(base, tmp_path, 45.0)
    os.utime(first.path, ns=(1, 1))  # the older of the two
    (tmp_path / "other-best.toml").write_text("# mine\n", encoding="utf-8")
    assert best_files(tmp_path) == [second.path, first.path]
    assert best_files(tmp_path, "base") == [second.path, first.path]
    assert best_files(tmp_path, "other") == []


def test_a_best_path_an_earlier_version_wrote_is_kept_and_said_to_be_unmarked(base, tmp_path):
    """Files written before fingerprints were called 'edited since a sweep wrote it'."""
    written = _write(base, tmp_path, 35.0)
    header, _, body = written.path.read_text(encoding="utf-8").split("\n", 2)
    written.path.write_text(f"{header}\n{body}", encoding="utf-8")  # as earlier versions wrote it
    again = _write(base, tmp_path, 45.0)
    assert again.kept == written.path and again.path.name == "base-best-2.toml"
    assert again.kept_why == "written before sweeps marked their own files; it may hold edits"
    assert best_files(tmp_path)[-1] == written.path


def test_a_sweep_keeps_an_edited_best_path_and_says_where_the_new_one_is(base, tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text('[sweep]\nscenario = "base.toml"\n[grid]\nradius = [20.0, 30.0]\n', encoding="utf-8")
    out = tmp_path / "out"
    first = run_sweep(spec, serial=True, out=out)
    best = first.best_scenario_path
    assert best == out / "spec-best.toml" and first.best_kept is None
    load_scenario(best).with_changes(speed=12.0).save()
    mine = best.read_bytes()
    second = run_sweep(spec, serial=True, out=out)
    assert best.read_bytes() == mine
    assert second.best_kept == best and second.best_scenario_path == out / "spec-best-2.toml"


def test_the_cli_names_the_kept_file_in_its_summary_and_json(base, tmp_path, capsys):
    import json

    from ladartui.cli import main

    spec = tmp_path / "spec.toml"
    spec.write_text('[sweep]\nscenario = "base.toml"\n[grid]\nradius = [20.0, 30.0]\n', encoding="utf-8")
    assert main(["sweep", str(spec), "--serial", "--json"]) == 0
    first = json.loads(capsys.readouterr().out)
    assert first["best_scenario_kept"] is None
    best = tmp_path / "spec-results" / "spec-best.toml"
    assert first["best_scenario"] == str(best)
    load_scenario(best).with_changes(speed=12.0).save()
    assert main(["sweep", str(spec), "--serial"]) == 0  # every variant resumed, ranked again
    text = capsys.readouterr().out.replace("\n", "")
    assert f"kept     {best}  (edited since a sweep wrote it: not replaced)" in text
    assert f"best     {best.with_name('spec-best-2.toml')}" in text


def test_a_missing_base_scenario_is_named_on_its_spec_line_before_the_sweep_starts(tmp_path, capsys):
    from ladartui.cli import main

    spec = tmp_path / "spec.toml"
    body = '[sweep]\nname = "x"\nscenario = "nope.toml"\n[grid]\nradius = [20.0]\n'
    spec.write_text(body, encoding="utf-8")
    assert main(["sweep", str(spec)]) == 2
    err = capsys.readouterr().err
    assert err.strip() == (
        f"ladartui: error: {spec}:3: sweep.scenario: expected an existing scenario file; "
        f"{str(tmp_path / 'nope.toml')!r} does not exist"
    )
    assert not (tmp_path / "x-results").exists()


def test_a_ctrl_c_while_the_charts_are_drawn_waits_for_the_whole_set(base, tmp_path, capsys, monkeypatch):
    """The charts were drawn after the sweep, outside its cancel: a Ctrl-C then left this
    run's ranking and best path beside the last run's charts, saying only 'interrupted'."""
    import _thread

    import ladartui.charts.sweep as charts
    from ladartui.cli import main

    spec = tmp_path / "spec.toml"
    spec.write_text('[sweep]\nscenario = "base.toml"\n[grid]\nradius = [20.0, 30.0]\n', encoding="utf-8")
    draw = charts.sweep_figure
    drawn = []

    def interrupted_while_drawing(result):
        _thread.interrupt_main()  # as the key lands on the main thread
        drawn.append(draw(result))
        return drawn[-1]

    monkeypatch.setattr(charts, "sweep_figure", interrupted_while_drawing)
    assert main(["sweep", str(spec), "--serial"]) == 0
    out = capsys.readouterr().out.replace("\n", "")
    assert drawn
    for name in ("pareto.svg", "pareto.png"):
        path = tmp_path / "spec-results" / name
        assert path.is_file() and f"chart    {path}" in out


def test_a_ranking_with_no_best_says_the_best_path_file_is_from_an_earlier_one(base, tmp_path, capsys):
    """An objective that ranked nothing left the earlier objective's best path in the
    folder, and the summary said nothing of it (JSON: best_scenario null)."""
    import json

    from ladartui.cli import main

    spec = tmp_path / "spec.toml"
    spec.write_text('[sweep]\nscenario = "base.toml"\n[grid]\nradius = [20.0, 30.0]\n', encoding="utf-8")
    assert main(["sweep", str(spec), "--serial"]) == 0
    best = tmp_path / "spec-results" / "spec-best.toml"
    assert best.is_file()
    capsys.readouterr()
    budget = ["--objective", "identified-within-budget", "--budget", "1e-9"]  # nothing identified so soon
    assert main(["sweep", str(spec), "--serial", *budget, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["best_scenario"] is None and out["best_scenario_earlier"] == str(best)
    assert main(["sweep", str(spec), "--serial", *budget]) == 0
    text = capsys.readouterr().out.replace("\n", "")
    assert f"earlier  {best}  (the best path of an earlier ranking: none is ranked now)" in text
    assert best.is_file()  # kept: it is what that ranking found


@pytest.mark.parametrize("name", ["ranking.csv", "spec-best.toml", "pareto.png"])
def test_a_ranking_file_the_folder_will_not_replace_is_one_line(base, tmp_path, capsys, monkeypatch, name):
    """A ranking, best path or chart the folder would not let be replaced (immutable, or
    another user's in a sticky folder) ended the sweep in a PermissionError traceback."""
    import errno
    import os

    import ladartui.atomic
    from ladartui.cli import main

    spec = tmp_path / "spec.toml"
    spec.write_text('[sweep]\nscenario = "base.toml"\n[grid]\nradius = [20.0, 30.0]\n', encoding="utf-8")
    assert main(["sweep", str(spec), "--serial"]) == 0
    capsys.readouterr()
    refused = tmp_path / "spec-results" / name
    before = refused.read_bytes()
    real = os.replace

    real_rename = os.rename

    def refusing(real):
        def move(src, dst):
            if str(refused) in (os.path.abspath(src), os.path.abspath(dst)):
                raise PermissionError(errno.EPERM, "Operation not permitted", str(src), str(dst))
            return real(src, dst)

        return move

    monkeypatch.setattr(ladartui.atomic.os, "replace", refusing(real))
    monkeypatch.setattr(ladartui.atomic.os, "rename", refusing(real_rename))
    assert main(["sweep", str(spec), "--serial", "--objective", "obscured-coverage"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1] == (
        f"ladartui: error: {refused}: could not be replaced (operation not permitted); nothing was "
        f"replaced, earlier outputs are unchanged; {refused.parent / 'results.csv'} keeps this sweep's "
        "rows (2 variants): the same command ranks them, running none again"
    )
    assert refused.read_bytes() == before
    assert not [p.name for p in refused.parent.iterdir() if p.name.endswith(".tmp")]


def test_a_full_disk_at_the_charts_leaves_the_earlier_ranking_whole(base, tmp_path, capsys, monkeypatch):
    """ranking.csv and the best path were replaced, then the disk filled at the charts:
    the folder held the new ranking beside the earlier ranking's charts, and the one line
    said only that pareto.png could not be written."""
    import errno
    import os
    import tempfile

    from ladartui.cli import main
    from ladartui.sweep import read_table

    spec = tmp_path / "spec.toml"
    spec.write_text('[sweep]\nscenario = "base.toml"\n[grid]\nradius = [20.0, 30.0]\n', encoding="utf-8")
    assert main(["sweep", str(spec), "--serial"]) == 0
    out = tmp_path / "spec-results"
    ranked = [out / name for name in ("ranking.csv", "spec-best.toml", "pareto.svg", "pareto.png")]
    before = [path.read_bytes() for path in ranked]
    spec.write_text(
        '[sweep]\nscenario = "base.toml"\n[grid]\nradius = [20.0, 30.0, 12.0]\n', encoding="utf-8"
    )
    real = tempfile.mkstemp

    def disk_full(suffix=None, prefix=None, dir=None, text=False):
        if prefix == ".pareto.png." and suffix == ".tmp":  # the chart's temporary
            raise OSError(errno.ENOSPC, "No space left on device", os.path.join(dir, prefix + suffix))
        return real(suffix, prefix, dir, text)

    monkeypatch.setattr(tempfile, "mkstemp", disk_full)
    capsys.readouterr()
    assert main(["sweep", str(spec), "--serial"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1] == (
        f"ladartui: error: {out / 'pareto.png'}: could not be written (no space left on device); "
        "nothing was replaced, earlier outputs are unchanged; "
        f"{out / 'results.csv'} keeps this sweep's rows (3 variants): the same command ranks them, "
        "running none again"
    )
    assert [path.read_bytes() for path in ranked] == before
    assert len(read_table(out / "results.csv")[0]) == 3
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == [".lock"]
    monkeypatch.undo()
    assert main(["sweep", str(spec), "--serial"]) == 0
    assert "nothing to run: all 3 variants resumed" in capsys.readouterr().out
    assert all(path.read_bytes() != old for path, old in zip(ranked[::2], before[::2]))
