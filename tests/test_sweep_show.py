"""`ladartui sweep --show`: it ranks the rows of the current base, writes nothing, refuses
the flags of a run and names what it cannot read."""

import pytest

from cli_support import one_error_line
from ladartui.errors import InputFileError
from ladartui.sweep import load_sweep_results, load_sweep_spec, read_table, run_sweep
from tiny_sweep import tiny_folder, write_spec, write_tiny_scenario


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    return tiny_folder(tmp_path_factory)


def test_rows_of_variants_dropped_from_the_grid_are_not_blamed_on_an_earlier_base(tmp_path, capsys):
    """A spec whose grid lost a value, run again on the same base, said '1 row of other
    variants or an earlier base left out (a run of this spec runs its variants again for
    the base as it is now)': the base had not changed."""
    from ladartui.cli import main

    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [20.0, 30.0]\n", name="grid.toml")
    run_sweep(spec, serial=True)
    spec.write_text(spec.read_text(encoding="utf-8").replace("[20.0, 30.0]", "[20.0]"))
    assert main(["sweep", str(spec), "--serial"]) == 0
    said = capsys.readouterr()
    text = said.out.replace("\n", " ")
    assert "left out: 1 row of other variants (not in the spec now)" in text
    assert "sweep of 1 variant on this process" in said.err  # not "1 variants"
    assert "earlier base" not in text


def test_show_ranks_the_rows_of_the_current_base_only(tmp_path, capsys):
    """The table keeps rows from an earlier base; a run ranks only the current base's,
    and so must --show and load_sweep_results given the spec (each variant was
    ranked once per base it had run with)."""
    import json

    from ladartui.cli import main

    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [20.0, 30.0]\n", name="bases.toml")
    run_sweep(spec, serial=True)
    base = tmp_path / "base.toml"
    base.write_text(base.read_text(encoding="utf-8").replace("fov_deg = 20.0", "fov_deg = 18.0"))
    ran = run_sweep(spec, serial=True, charts=True)  # as the command draws them
    assert ran.ran == 2 and len(ran.rows) == 2
    out = tmp_path / "bases-results"
    assert len(read_table(out / "results.csv")[0]) == 4  # both bases' rows are kept
    shown = load_sweep_results(out, spec=load_sweep_spec(spec))
    assert [r.row["variant"] for r in shown.ranking] == [r.row["variant"] for r in ran.ranking]
    assert [r.value for r in shown.ranking] == [r.value for r in ran.ranking]
    assert main(["sweep", str(spec), "--show", "--json"]) == 0
    shown_json = json.loads(capsys.readouterr().out)
    assert [t["variant"] for t in shown_json["top"]] == [r.row["variant"] for r in ran.ranking]
    assert shown_json["left_out"] == 2 and ran.left_out == 2
    # the base edited again and not run: nothing of it to rank, and --show says why
    base.write_text(base.read_text(encoding="utf-8").replace("fov_deg = 18.0", "fov_deg = 16.0"))
    charts = {p: p.read_bytes() for p in out.glob("pareto.*")}
    assert charts
    assert main(["sweep", str(spec), "--show"]) == 1  # nothing to rank: a script must know
    captured = capsys.readouterr()
    text = captured.out.replace("\n", " ")
    assert "left out: 4 rows of an earlier base (a run of this spec" in text
    assert "other variants" not in text  # every row left out is of the spec's own variants
    assert "no variant finished (no row of this spec's variants from its base as it is now)" in captured.err
    assert {p: p.read_bytes() for p in out.glob("pareto.*")} == charts  # never redrawn by --show
    # base as it ran: ranked by another objective, the charts stay the sweep's, as its
    # ranking.csv and best path do (they starred the other ranking's best)
    base.write_text(base.read_text(encoding="utf-8").replace("fov_deg = 16.0", "fov_deg = 18.0"))
    assert main(["sweep", str(spec), "--show", "--objective", "time-to-identify", "--cost", "distance"]) == 0
    said = capsys.readouterr().err
    assert f"ranking.csv, pareto.svg, pareto.png, bases-best.toml in {out} stay as the last sweep" in said
    assert {p: p.read_bytes() for p in out.glob("pareto.*")} == charts
    # the base gone: every row of the table, said so
    base.unlink()
    assert main(["sweep", str(spec), "--show", "--json"]) == 0
    out_err = capsys.readouterr()
    assert len(json.loads(out_err.out)["top"]) == 4
    assert "base scenario" in out_err.err and "every row of the table is ranked" in out_err.err


def test_load_sweep_results_takes_the_spec_as_run_sweep_does_and_names_a_wrong_one(tmp_path):
    """load_sweep_results(..., spec="x") raised AttributeError: 'str' object has no
    attribute 'scenario_path'; run_sweep takes a SweepSpec or its path, so this takes
    either too, and anything else is a FieldError naming spec."""
    from ladartui.errors import FieldError

    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [20.0, 30.0]\n", name="either.toml")
    ran = run_sweep(spec, serial=True)
    out = tmp_path / "either-results"
    by_path = load_sweep_results(out, spec=spec)
    by_text = load_sweep_results(out, spec=str(spec))
    for shown in (by_path, by_text):
        assert [r.row["variant"] for r in shown.ranking] == [r.row["variant"] for r in ran.ranking]
    for wrong in (5, ["either.toml"]):
        with pytest.raises(FieldError) as raised:
            load_sweep_results(out, spec=wrong)
        assert str(raised.value).startswith("spec = ")
        assert "SweepSpec" in str(raised.value) and "\n" not in str(raised.value)
    with pytest.raises(InputFileError) as raised:
        load_sweep_results(out, spec=tmp_path / "none.toml")
    assert "none.toml" in str(raised.value)


def test_show_writes_nothing_and_leaves_the_folder_as_the_sweep_ranked_it(tmp_path, capsys):
    """A sweep ranked with --objective coverage-per-km, then --show without it: the
    charts were redrawn by the spec's objective, starring another best than the
    folder's ranking.csv and best path, without a word."""
    from ladartui.cli import main

    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [20.0, 30.0]\nscans = [2, 4]\n", name="terms.toml")
    out = tmp_path / "terms-results"
    assert main(["sweep", str(spec), "--serial", "--objective", "coverage-per-km"]) == 0
    capsys.readouterr()
    written = {p.name: p.read_bytes() for p in out.iterdir()}
    assert {"pareto.svg", "pareto.png", "ranking.csv", "terms-best.toml"} <= set(written)
    assert main(["sweep", str(spec), "--show"]) == 0
    captured = capsys.readouterr()
    assert {p.name: p.read_bytes() for p in out.iterdir()} == written
    assert "chart " not in captured.out
    assert "ranking.csv, pareto.svg, pareto.png, terms-best.toml in " in captured.err


def test_show_names_a_file_given_as_its_results_folder(tiny, tmp_path, capsys):
    from ladartui.cli import main

    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="showfile.toml")
    assert main(["sweep", str(spec), "--show", "--out", str(spec)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"ladartui: error: --out = '{spec}': expected a sweep's results folder; it is a file"


@pytest.mark.parametrize(
    "flags, named",
    [
        (["--workers", "2"], "--workers"),
        (["--serial"], "--serial"),
        (["--scheduler", "tcp://127.0.0.1:8786"], "--scheduler"),
        (["--tls-ca-file", "ca.pem", "--insecure"], "--tls-ca-file, --insecure"),
        (["--connect-timeout", "5"], "--connect-timeout"),
    ],
)
def test_show_refuses_the_flags_of_a_run_it_does_not_start(tiny, tmp_path, capsys, flags, named):
    """--show --workers 2 ranked the table and exited 0, the --workers taken without a word."""
    from ladartui.cli import main

    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="showflags.toml")
    assert main(["sweep", str(spec), "--show", "--out", str(tmp_path / "o"), *flags]) == 2
    assert one_error_line(capsys) == (
        f"ladartui: error: {named}: only a run uses "
        f"{'it' if ',' not in named else 'them'}; --show ranks the results in OUT and runs nothing"
    )


def test_show_prints_text_from_the_results_table_as_text(tmp_path, capsys):
    """A cell holding an escape sequence reached the terminal raw (a window title change,
    a colour), and one holding [markup] was read as markup."""
    from ladartui.cli import main

    write_tiny_scenario(tmp_path)
    spec = write_spec(tmp_path, "[grid]\nradius = [20.0, 30.0]\nsensor_grid = [0, 8]\n", name="esc.toml")
    run_sweep(spec, serial=True)
    results = tmp_path / "esc-results" / "results.csv"
    rows = results.read_text(encoding="utf-8").splitlines()
    rows[1:] = [row.replace(",20.0,", ",\x1b]0;pwn\x07[bold]20,") for row in rows[1:]]
    rows[1:] = [row.replace("expected", "expected \x1b[31m[red]") for row in rows[1:]]
    results.write_text("\n".join(rows) + "\n", encoding="utf-8")
    assert main(["sweep", str(spec), "--show"]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\x07" not in out
    assert "[bold]" in out and "[red]" in out  # shown as typed, not taken as markup


def test_rows_the_table_cannot_read_are_named_not_dropped_silently(tmp_path, capsys):
    """A row cut short in results.csv vanished from --show without a word."""
    import json

    from ladartui.cli import main

    def torn(lines):
        lines[2] = lines[2][:40]  # the second row, torn

    spec, results = _swept_then_edited(tmp_path, capsys, "torn", torn)
    assert main(["sweep", str(spec), "--show"]) == 0
    out = capsys.readouterr().out
    assert "1 row of results.csv could not be read (line 3) and is left out" in out
    assert main(["sweep", str(spec), "--show", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["unreadable_lines"] == [3]
    # a run that rewrites the table says so too: the line is gone from the file after it
    spec.write_text(spec.read_text().replace("[20.0, 30.0]", "[20.0, 30.0, 40.0]"))
    assert main(["sweep", str(spec), "--serial"]) == 0
    out = capsys.readouterr().out
    assert "(line 3) and is left out; the table was rewritten without it" in out
    unreadable = []
    assert len(read_table(results, unreadable)[0]) == 3 and not unreadable  # the torn one ran again


def test_a_row_of_a_status_no_sweep_writes_says_so_not_none(tmp_path, capsys):
    """A status edited by hand ('okay') read '1 variant failed ...; first: ID: None'."""
    from ladartui.cli import main

    def edited(lines):
        lines[1] = lines[1].replace(",ok,", ",okay,", 1)

    spec, _ = _swept_then_edited(tmp_path, capsys, "edited", edit=edited)
    assert main(["sweep", str(spec), "--show"]) == 0
    out = capsys.readouterr().out.replace("\n", " ")
    assert "status 'okay', not one a sweep writes (ok, failed, error)" in out and ": None" not in out


def _swept_then_edited(folder, capsys, name, edit):
    """A two-variant sweep NAME.toml run in ``folder``, then its results.csv lines
    changed by ``edit(lines)`` as a hand or a crash would: (spec, results path)."""
    from ladartui.cli import main

    write_tiny_scenario(folder)
    spec = write_spec(folder, "[grid]\nradius = [20.0, 30.0]\n", name=f"{name}.toml")
    assert main(["sweep", str(spec), "--serial"]) == 0
    results = folder / f"{name}-results" / "results.csv"
    lines = results.read_text(encoding="utf-8").splitlines()
    edit(lines)
    results.write_text("\n".join(lines) + "\n", encoding="utf-8")
    capsys.readouterr()
    return spec, results
