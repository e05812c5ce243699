"""A sweep's result table: values round-trip, rows are written as they come and
rewrites are spaced, torn lines are dropped or named."""

import random

from ladartui.sweep import read_table, write_table
from ladartui.sweep.table import LEAD_COLUMNS, TEXT_COLUMNS, TableWriter, order_columns, table_text


def test_table_round_trips_values_and_grows_columns(tmp_path):
    rows = [
        {
            "variant": "1e50000000000000",
            "status": "error",
            "base": "b",
            "radius": 10.0,
            "error": 'bad "quote", comma',
        },
        {
            "variant": "00000000000000ff",
            "status": "ok",
            "base": "b",
            "radius": 0.1 + 0.2,
            "scans": 3,
            "obscured_coverage": 1 / 3,
            "after": [0.25, 0.5],
            "flag": True,
            "nothing": None,
        },
    ]
    path = tmp_path / "results.csv"
    write_table(path, rows, ["radius", "scans"])
    back, header = read_table(path)
    assert header[:5] == ["variant", "status", "base", "radius", "scans"]
    assert header[-1] == "error"
    assert back[0]["variant"] == "1e50000000000000"  # a hex id is never read as a number
    assert back[0]["error"] == 'bad "quote", comma' and back[0]["scans"] is None
    assert back[1]["radius"] == 0.1 + 0.2 and back[1]["obscured_coverage"] == 1 / 3
    assert back[1]["after"] == [0.25, 0.5] and back[1]["flag"] is True
    assert back[1]["nothing"] is None and back[1]["scans"] == 3
    assert "variant" in TEXT_COLUMNS


def test_reader_drops_a_torn_last_line(tmp_path):
    path = tmp_path / "results.csv"
    write_table(path, [{"variant": "a" * 16, "status": "ok", "base": "b", "radius": 1.0}])
    with open(path, "a", encoding="utf-8") as handle:
        handle.write("bbbbbbbbbbbbbbbb,ok")  # a line cut short by a crash elsewhere
    rows, _ = read_table(path)
    assert [r["variant"] for r in rows] == ["a" * 16]


def test_the_table_writer_writes_what_write_table_writes_row_by_row(tmp_path):
    """Each row is formatted once, and again only when a later row changes the columns;
    the file is the table of every row so far, in order, a row replaced in place."""
    rng = random.Random(5)
    extra = ["coverage", "levels", "path_length_m", "obscured_coverage"]
    rows = []
    path = tmp_path / "results.csv"
    path.write_bytes(b"")
    writer = TableWriter(path, [], ["radius"], spacing=0.0)
    for i in range(60):
        variant = f"{rng.randrange(25):016x}"  # some variants again: a failed row retried
        row = {"variant": variant, "status": rng.choice(["ok", "failed"]), "base": "b", "radius": i / 7}
        row.update({key: rng.random() for key in rng.sample(extra, rng.randrange(len(extra)))})
        at = next((k for k, r in enumerate(rows) if r["variant"] == variant), None)
        if at is None:
            rows.append(row)
        else:
            rows[at] = row
        writer.put(row)
        back, header = read_table(path)
        assert set(header) == set(order_columns(rows, ["radius"])) and header[:4] == [*LEAD_COLUMNS, "radius"]
        assert [{k: v for k, v in r.items() if v is not None} for r in back] == rows
    assert writer.rows == rows
    assert path.read_text() == table_text(rows, ["radius"], columns=header)


def test_the_table_writer_spaces_its_rewrites_and_loses_no_row(tmp_path, monkeypatch):
    """Rewriting the whole table after every variant grew with the table (20,000 rows:
    seconds a variant); the rewrites are spaced to a share of the time, and flush
    writes the rows held back."""
    import ladartui.sweep.table as table

    now = [0.0]
    writes = []
    real = table.write_text_atomic

    def slow_write(path, text, durable=False):
        writes.append(text.count("\n") - 1)
        now[0] += 1.0  # each rewrite takes a second
        real(path, text, durable)

    monkeypatch.setattr(table, "write_text_atomic", slow_write)
    path = tmp_path / "results.csv"
    writer = TableWriter(path, [], [], spacing=9.0, clock=lambda: now[0])
    for i in range(40):
        writer.put({"variant": f"{i:016x}", "status": "ok", "base": "b"})
        now[0] += 0.5  # half a second a variant
    assert writes[0] == 1 and len(writes) <= 40 * 1.5 / 10 + 1  # at most a tenth of the time
    assert len(read_table(path)[0]) < 40
    writer.flush()
    assert len(read_table(path)[0]) == 40 and writes[-1] == 40
    count = len(writes)
    writer.flush()  # nothing new: not written again
    assert len(writes) == count


def test_rows_read_back_are_replaced_without_formatting_the_table_again(tmp_path, monkeypatch):
    """Rows read from the file hold every column, empty ones as None: replacing one (a
    failed variant run again on resume) formatted the whole table each time."""
    import ladartui.sweep.table as table

    path = tmp_path / "results.csv"
    rows = [
        {"variant": f"{i:016x}", "status": "failed" if i % 2 else "ok", "base": "b", "coverage": 0.5}
        for i in range(20)
    ]
    rows[0]["error"] = "x"
    write_table(path, rows)
    formats = []
    real = table.TableWriter._format_all
    monkeypatch.setattr(table.TableWriter, "_format_all", lambda self: formats.append(1) or real(self))
    read, _ = read_table(path)
    writer = TableWriter(path, read, [], spacing=0.0)
    assert not formats  # nothing formatted before a row comes
    for i in range(1, 20, 2):
        writer.put({"variant": f"{i:016x}", "status": "ok", "base": "b", "coverage": 0.25})
    assert len(formats) == 1
    back, _ = read_table(path)
    assert [r["status"] for r in back] == ["ok"] * 20 and back[0]["error"] == "x"
    writer.put({"variant": f"{0:016x}", "status": "ok", "base": "b", "coverage": 0.5})  # its error gone
    assert len(formats) == 2 and read_table(path)[0][0]["error"] is None


def test_the_table_reader_names_a_torn_row_by_its_first_line(tmp_path):
    path = tmp_path / "results.csv"
    write_table(path, [{"variant": f"{i:016x}", "status": "ok", "base": "b"} for i in range(6)])
    lines = path.read_text().splitlines()
    lines[2] = lines[2].replace("ok", '"ok')  # a stray quote swallows the lines after it
    path.write_text("\n".join(lines[:4] + [""] + lines[4:]) + "\n")  # and a blank line
    unreadable = []
    rows, _ = read_table(path, unreadable)
    assert unreadable == [3] and [r["variant"] for r in rows] == [f"{i:016x}" for i in (0,)]
