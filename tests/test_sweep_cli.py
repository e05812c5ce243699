"""`ladartui sweep`, serially on the tiny base: a spec error in one line, the ranking as
JSON, impossible values not called failures, the summary in words, a Ctrl-C after the
last variant; and one sweep at a time writing a results folder."""

import os
import re
import time

import pytest

from ladartui.errors import OutputSetBusy
from ladartui.sweep import read_table, run_sweep
from tiny_sweep import tiny_folder, write_spec


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    return tiny_folder(tmp_path_factory)


def test_cli_reports_a_spec_error_in_one_line(tmp_path, capsys):
    from ladartui.cli import main

    spec = write_spec(tmp_path, "[grid]\nscans = ['many']\n")
    assert main(["sweep", str(spec), "--serial"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "grid.scans" in err and str(spec) in err


def test_cli_serial_sweep_prints_the_ranking_as_json(tiny, tmp_path, capsys):
    import json

    from ladartui.cli import main

    spec = write_spec(tiny, "[grid]\nradius = [10.0, 20.0]\n", name="cli.toml")
    assert (
        main(
            [
                "sweep",
                str(spec),
                "--serial",
                "--out",
                str(tmp_path),
                "--json",
                "--objective",
                "coverage-per-km",
            ]
        )
        == 0
    )
    report = json.loads(capsys.readouterr().out)
    assert report["objective"] == "coverage-per-km" and report["variants"] == 2
    values = [entry["objective"] for entry in report["top"]]
    assert values == sorted(values, reverse=True)
    rows, _ = read_table(tmp_path / "results.csv")
    by_id = {r["variant"]: r for r in rows}
    for entry in report["top"]:
        row = by_id[entry["variant"]]
        assert entry["objective"] == pytest.approx(row["obscured_coverage"] / (row["path_length_m"] / 1000.0))
    assert os.path.isfile(report["best_scenario"])


def test_impossible_values_are_not_called_failures(tiny, tmp_path, capsys):
    # "failed" rows run again on resume; "error" rows (impossible values) never do
    import json

    from ladartui.cli import main

    spec = write_spec(tiny, "[grid]\nradius = [10.0]\nsensor_grid = [8, 0]\n", name="impossible.toml")
    assert main(["sweep", str(spec), "--serial", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "\n1 variant with impossible values (kept as errors, not run again); first: " in out
    assert "failed" not in out
    assert main(["sweep", str(spec), "--show", "--out", str(tmp_path), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert (report["failed"], report["impossible"]) == (0, 1)


def test_the_summary_counts_in_words_and_says_when_every_variant_was_resumed(tiny, tmp_path, capsys):
    """A fully resumed sweep said '0 variant(s) run in 0.0 s on 0 worker(s); 2 resumed'."""
    from ladartui.cli import main

    spec = write_spec(tiny, "[grid]\nradius = [10.0, 12.0]\n", name="words.toml")
    assert main(["sweep", str(spec), "--serial", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"\n2 variants run in [\d.]+ s \([\d.]+ variants/min\) on 1 worker\n", out), out
    assert main(["sweep", str(spec), "--serial", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "\nnothing to run: all 2 variants resumed from earlier runs\n" in out
    assert " run in " not in out and "(s)" not in out


def test_a_ctrl_c_after_the_last_variant_says_the_sweep_finished(tiny, tmp_path, capsys, monkeypatch):
    """A Ctrl-C once every variant had run left 'stopping; finished variants are kept'
    on the bar and exited 0 with the whole set written, the interrupt not mentioned."""
    import _thread

    import ladartui.sweep.ranked_set as ranked_set
    from ladartui.cli import main

    real = ranked_set.ranking_text

    def interrupted_first(*args, **kwargs):
        _thread.interrupt_main()
        time.sleep(1.0)  # the main thread sees the Ctrl-C and waits for this one
        return real(*args, **kwargs)

    monkeypatch.setattr(ranked_set, "ranking_text", interrupted_first)
    spec = write_spec(tiny, "[grid]\nradius = [10.0, 12.0]\n", name="late.toml")
    assert main(["sweep", str(spec), "--serial", "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    said = captured.out + captured.err
    assert "the interrupt came after the last variant: the sweep finished" in said
    assert "sweep interrupted" not in said and (tmp_path / "ranking.csv").exists()


def test_two_sweeps_never_write_one_folder_at_once(tiny, tmp_path):
    fcntl = pytest.importorskip("fcntl")  # POSIX only
    spec = write_spec(tiny, "[grid]\nscans = [2]\n", name="locked.toml")
    with open(tmp_path / ".lock", "a+b") as held:
        fcntl.flock(held, fcntl.LOCK_EX)  # as a running sweep holds it
        with pytest.raises(OutputSetBusy, match="another sweep"):
            run_sweep(spec, serial=True, out=tmp_path)
    assert not (tmp_path / "results.csv").exists()
    assert run_sweep(spec, serial=True, out=tmp_path).ran == 1


def test_a_folder_another_sweep_holds_is_refused_before_the_bar(tiny, tmp_path, capsys):
    """The second sweep drew 'sweep 0/1 starting; a first run compiles kernels' before
    it was refused."""
    fcntl = pytest.importorskip("fcntl")
    from cli_support import one_error_line
    from ladartui.cli import main

    spec = write_spec(tiny, "[grid]\nscans = [2]\n", name="held.toml")
    with open(tmp_path / ".lock", "a+b") as held:
        fcntl.flock(held, fcntl.LOCK_EX)
        assert main(["sweep", str(spec), "--serial", "--out", str(tmp_path)]) == 75  # try again later
    assert "another sweep is writing its results here" in one_error_line(capsys)


def test_the_command_to_open_the_best_path_runs_as_written_from_a_folder_with_spaces(
    tiny, tmp_path, capsys, monkeypatch
):
    """'(open it with: ladartui my results/cli-best.toml)': pasted into a shell, that opened
    'my' and 'results/cli-best.toml', neither the best path."""
    import shlex

    from ladartui.cli import main

    monkeypatch.setenv("COLUMNS", "400")  # the line unwrapped, as a terminal copies it
    spec = write_spec(tiny, "[grid]\nradius = [10.0]\n", name="cli.toml")
    out = tmp_path / "my results"
    assert main(["sweep", str(spec), "--serial", "--out", str(out)]) == 0
    line = next(s for s in capsys.readouterr().out.splitlines() if s.startswith("best "))
    command = line.split("(open it with: ", 1)[1].removesuffix(")")
    assert shlex.split(command) == ["ladartui", str(out / "cli-best.toml")]


def test_a_disk_full_mid_sweep_says_how_many_variants_the_table_keeps(tiny, tmp_path, capsys, monkeypatch):
    """The disk filled as the table was rewritten: the sweep stopped saying only that
    results.csv could not be written, as if nothing were kept, where an interruption says
    how many variants are kept and that the same command resumes."""
    import errno
    import functools
    import tempfile

    from ladartui.cli import main
    from ladartui.sweep.table import TableWriter

    spec = write_spec(tiny, "[grid]\nradius = [10.0, 12.0, 14.0, 16.0]\n", name="filling.toml")
    real, made = tempfile.mkstemp, []

    def filling(suffix=None, prefix=None, dir=None, text=False):
        if prefix == ".results.csv." and suffix == ".tmp":  # the table's rewrites
            made.append(prefix)
            if len(made) > 2:
                raise OSError(errno.ENOSPC, "No space left on device", os.path.join(dir, prefix + suffix))
        return real(suffix, prefix, dir, text)

    monkeypatch.setattr(tempfile, "mkstemp", filling)
    each_row = functools.partial(TableWriter, spacing=0.0)  # each row rewrites the table
    monkeypatch.setattr("ladartui.sweep.execute.TableWriter", each_row)
    assert main(["sweep", str(spec), "--serial", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1] == (
        f"ladartui: error: {tmp_path / 'results.csv'}: cannot be written (no space left on device); "
        "it keeps 2 of 4 variants, as last written: run the sweep again to resume once it can be written"
    )
    assert len(read_table(tmp_path / "results.csv")[0]) == 2
    monkeypatch.undo()
    assert main(["sweep", str(spec), "--serial", "--out", str(tmp_path)]) == 0
    assert run_sweep(spec, serial=True, out=tmp_path).resumed == 4
