"""Large voxel lists are read in blocks cut at line ends: the rows, the errors and their
line numbers are those of reading the file whole, wherever the blocks fall."""

from __future__ import annotations

import numpy as np
import pytest

import ladartui.scene.voxels as voxels_module
from ladartui.errors import InputFileError
from ladartui.scene.target_model import load_target
from ladartui.scene.voxels import load_voxels


def _outcome(load, path):
    try:
        result = load(path)
    except InputFileError as error:
        return "error", str(error)
    return "ok", [np.asarray(part).tolist() for part in (result if isinstance(result, tuple) else (result,))]


def _both(monkeypatch, load, path, block):
    monkeypatch.setattr(voxels_module, "_PLAIN_BYTES", 1 << 30)  # whole
    whole = _outcome(load, path)
    monkeypatch.setattr(voxels_module, "_PLAIN_BYTES", 0)  # streamed, tiny blocks
    monkeypatch.setattr(voxels_module, "_BLOCK_BYTES", block)
    return whole, _outcome(load, path)


LINES = [f"{i % 97},{(i * 7) % 89},{i % 13}" for i in range(300)]
CASES = {
    "plain": "\n".join(LINES) + "\n",
    "no final newline": "\n".join(LINES),
    "crlf": "\r\n".join(LINES) + "\r\n",
    "spaces and bom": "\ufeff" + "\n".join(" " + line.replace(",", " , ") + "  " for line in LINES) + "\n",
    "blank lines at the end": "\n".join(LINES) + "\n\n  \n\n",
    "bad line late": "\n".join(LINES[:250] + ["1,2,x"] + LINES[250:]) + "\n",
    "blank line before voxels": "\n".join(LINES[:150] + [""] + LINES[150:]) + "\n",
    "blank lines before voxels": "\n".join(LINES[:150] + ["", " ", ""] + LINES[150:]) + "\n",
    "stray carriage return": "\n".join(LINES[:200] + ["1,\r2,3"] + LINES[200:]) + "\n",
    "repeats": "\n".join(LINES + LINES[:40]) + "\n",
}


BAD_LINES = {
    "bad line late": 251,
    "blank line before voxels": 151,
    "blank lines before voxels": 151,
    "stray carriage return": 201,
}


@pytest.mark.parametrize("block", [5, 8, 13, 64, 1000])
@pytest.mark.parametrize("case", sorted(CASES))
def test_streamed_reading_equals_reading_whole(tmp_path, monkeypatch, case, block):
    path = tmp_path / "model.txt"
    path.write_bytes(CASES[case].encode("utf-8"))
    whole, streamed = _both(monkeypatch, load_voxels, path, block)
    assert streamed == whole
    bad_line = BAD_LINES.get(case)
    if bad_line is None:
        assert whole[0] == "ok"
    else:
        assert whole[0] == "error" and f":{bad_line}:" in whole[1], whole


@pytest.mark.parametrize("block", [7, 50, 4096])
def test_streamed_target_models_keep_their_ids_and_errors(tmp_path, monkeypatch, block):
    lines = [f"{i},{i % 5},{i % 3},{1 + i % 3}" for i in range(200)]
    path = tmp_path / "model_Target.txt"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    whole, streamed = _both(monkeypatch, load_target, path, block)
    assert whole[0] == "ok" and streamed == whole
    path.write_text("\n".join(lines[:120] + ["4,4,4"] + lines[120:]) + "\n", encoding="utf-8")
    whole, streamed = _both(monkeypatch, load_target, path, block)
    assert whole[0] == "error" and ":121:" in whole[1] and streamed == whole


def test_a_large_file_is_read_in_blocks_not_whole(tmp_path, monkeypatch):
    path = tmp_path / "model.txt"
    path.write_text(CASES["plain"], encoding="utf-8")
    monkeypatch.setattr(voxels_module, "_PLAIN_BYTES", 0)
    monkeypatch.setattr(voxels_module, "_BLOCK_BYTES", 256)
    seen = []
    original = voxels_module._parse_voxel_bytes

    def spy(buf, start, out):
        seen.append(len(buf))
        return original(buf, start, out)

    monkeypatch.setattr(voxels_module, "_parse_voxel_bytes", spy)
    monkeypatch.setattr(np, "fromfile", lambda *a, **k: pytest.fail("the whole file was read"))
    assert len(load_voxels(path)) == len(set(LINES))
    assert len(seen) >= 10 and max(seen) < 256 + 20  # a block and the line it cut


def watched_open(on_read):
    """An ``open`` for the reader whose files call ``on_read(bytes read)`` after each read."""

    class WatchedFile:
        def __init__(self, *args):
            self._file = open(*args)  # noqa: SIM115 (closed by __exit__)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self._file.close()

        def read(self, size=-1):
            data = self._file.read(size)
            on_read(len(data))
            return data

        def fileno(self):
            return self._file.fileno()

    return WatchedFile


def test_a_large_file_is_read_once(tmp_path, monkeypatch):
    """The first bytes, read to tell a small file from a large one, are not read again."""
    path = tmp_path / "model.txt"
    path.write_text(CASES["plain"], encoding="utf-8")
    monkeypatch.setattr(voxels_module, "_PLAIN_BYTES", 100)
    monkeypatch.setattr(voxels_module, "_BLOCK_BYTES", 64)
    read = []
    monkeypatch.setattr(voxels_module, "open", watched_open(read.append), raising=False)
    assert len(load_voxels(path)) == len(set(LINES))
    assert sum(read) == path.stat().st_size


def test_a_file_replaced_while_read_is_read_whole_as_it_was(tmp_path, monkeypatch):
    """The first bytes and the rest came from two opens: a model replaced in between (as
    generate writes its files) was read as part of each, parsed without a word."""
    import os

    path = tmp_path / "model.txt"
    path.write_text(CASES["plain"], encoding="utf-8")
    other = tmp_path / "other.txt"
    other.write_text("\n".join(f"{i},{i},{i}" for i in range(400)) + "\n", encoding="utf-8")
    monkeypatch.setattr(voxels_module, "_PLAIN_BYTES", 100)
    monkeypatch.setattr(voxels_module, "_BLOCK_BYTES", 64)
    reads = []

    def replace_after_the_first_read(size):
        reads.append(size)
        if len(reads) == 1:  # the first bytes are read: the file is replaced
            os.replace(other, path)

    monkeypatch.setattr(voxels_module, "open", watched_open(replace_after_the_first_read), raising=False)
    rows = load_voxels(path).tolist()
    assert rows == [list(map(int, line.split(","))) for line in dict.fromkeys(LINES)]


def test_large_lists_are_checked_for_order_in_place_and_repeats_still_dropped():
    from ladartui.scene.voxels import unique_voxels

    grid = np.stack(np.meshgrid(np.arange(80), np.arange(80), np.arange(80), indexing="ij"), -1)
    rows = grid.reshape(-1, 3).astype(np.int32)  # 512,000 rows, sorted by (x, y, z)
    assert rows.nbytes > voxels_module._PLAIN_BYTES
    same, dropped = unique_voxels(rows)
    assert dropped == 0 and np.shares_memory(same, rows)  # no copy made
    repeated = np.insert(rows, 1000, rows[999], axis=0)  # one voxel twice, side by side
    kept, dropped = unique_voxels(repeated)
    assert dropped == 1 and np.array_equal(kept, rows)
    swapped = rows.copy()
    swapped[[10, 11]] = swapped[[11, 10]]  # out of order, nothing repeated
    kept, dropped = unique_voxels(swapped)
    assert dropped == 0 and np.array_equal(kept, swapped)


def test_any_text_reads_the_same_streamed_as_whole(tmp_path):
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    lines = st.lists(
        st.one_of(
            st.tuples(*[st.integers(0, 300)] * 3).map(lambda v: ",".join(map(str, v))),
            st.text(alphabet="0123456789, \t\r-x", max_size=12),
        ),
        max_size=60,
    )
    path = tmp_path / "fuzz.txt"

    @settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(lines=lines, block=st.integers(1, 40), final_newline=st.booleans())
    def check(lines, block, final_newline):
        path.write_bytes(("\n".join(lines) + ("\n" if final_newline else "")).encode())
        with pytest.MonkeyPatch.context() as patch:
            whole, streamed = _both(patch, load_voxels, path, block)
        assert streamed == whole

    check()
