import os
import stat

import pytest

from ladartui.atomic import atomic_path, write_text_atomic


def test_write_replaces_target_and_keeps_no_temporary(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    write_text_atomic(target, "new")
    assert target.read_text() == "new"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_failed_write_leaves_target_untouched(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("interrupted")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_new_file_gets_umask_mode_and_existing_keeps_its_mode(tmp_path):
    umask = os.umask(0o022)
    try:
        fresh = tmp_path / "fresh.txt"
        write_text_atomic(fresh, "x")
        assert stat.S_IMODE(fresh.stat().st_mode) == 0o644
        kept = tmp_path / "kept.txt"
        kept.write_text("x")
        kept.chmod(0o640)
        write_text_atomic(kept, "y")
        assert stat.S_IMODE(kept.stat().st_mode) == 0o640
    finally:
        os.umask(umask)


def _writer_paused_mid_write(target, started):
    """A child that writes ``target`` atomically and stops halfway, as a long write does."""
    import time

    with atomic_path(target) as tmp:
        tmp.write_text("half")
        started.set()
        time.sleep(60)


def _aged(path, seconds=3600):
    import time

    past = time.time() - seconds
    os.utime(path, (past, past))


def test_a_killed_write_s_temporary_is_removed_by_the_next_write_and_a_live_one_kept(tmp_path):
    """A write killed (SIGKILL) left its hidden temporary, 40-70 MB for a trace or a
    voxelised mesh, and every later write left it there: they piled up one a kill."""
    import multiprocessing
    import signal

    target = tmp_path / "hits.npy"
    target.write_text("old")
    context = multiprocessing.get_context("spawn")  # no threads of this process copied
    writers = []
    for _ in range(2):
        started = context.Event()
        writer = context.Process(target=_writer_paused_mid_write, args=(target, started))
        writer.start()
        assert started.wait(30)
        writers.append(writer)
    killed, alive = writers
    os.kill(killed.pid, signal.SIGKILL)
    killed.join()
    temporaries = sorted(p for p in tmp_path.iterdir() if p.name != "hits.npy")
    assert len(temporaries) == 2
    for temporary in temporaries:
        _aged(temporary)  # both old: only the live writer's hold keeps its own
    try:
        write_text_atomic(target, "new")
        assert target.read_text() == "new"
        left = [p for p in tmp_path.iterdir() if p.name != "hits.npy"]
        assert len(left) == 1  # the live writer's, still being written
    finally:
        alive.kill()
        alive.join()


def test_a_fresh_temporary_no_one_holds_is_left_for_a_writer_about_to_hold_it(tmp_path):
    """Between making its temporary and holding it a writer is exposed: a temporary a
    few seconds old is never taken for a killed write's."""
    target = tmp_path / "out.txt"
    fresh = tmp_path / ".out.txt.abcd1234.tmp"
    fresh.write_text("just made")
    old = tmp_path / ".out.txt.efgh5678.tmp"
    old.write_text("left by a kill")
    _aged(old)
    other = tmp_path / ".other.txt.ijkl9012.tmp"  # another file's: not this write's to judge
    other.write_text("x")
    _aged(other)
    write_text_atomic(target, "new")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([fresh.name, other.name, "out.txt"])


def test_only_the_names_a_write_makes_are_taken_for_its_temporaries(tmp_path):
    """'.notes.txt.mine.tmp', a person's own file, was removed as an abandoned
    temporary the next time notes.txt was written."""
    own = [
        tmp_path / ".notes.txt.mine.tmp",
        tmp_path / ".notes.txt.backup-1.tmp",
        tmp_path / ".notes.txt.tmp",
    ]
    made = tmp_path / ".notes.txt.k2_9zqa0.tmp"  # as tempfile names them: eight of [a-z0-9_]
    for path in (*own, made):
        path.write_text("x")
        _aged(path)
    write_text_atomic(tmp_path / "notes.txt", "new")
    assert all(path.exists() for path in own) and not made.exists()


def test_an_output_set_keeps_a_temporary_a_live_write_holds(tmp_path):
    """Entering an output set removed every temporary of its files, a live write's too,
    whose rename then failed."""
    from ladartui.atomic import held_temporary
    from ladartui.outputset import OutputSet

    target = tmp_path / "run.cmf"
    fd, live = held_temporary(target)  # held, as a plain write of the same name holds it
    try:
        left = tmp_path / ".run.cmf.abcd1234.tmp"  # a killed write's: no one holds it
        left.write_text("x")
        with OutputSet({"measures": target}, tmp_path / ".run.lock") as outputs:
            outputs.write_contents({"measures": b"m"})
        assert live.exists() and not left.exists() and target.read_bytes() == b"m"
    finally:
        os.close(fd)


def test_a_temporary_that_cannot_be_given_its_mode_is_not_left_behind(tmp_path, monkeypatch):
    def refused(path, mode):
        raise PermissionError(1, "Operation not permitted")

    monkeypatch.setattr(os, "chmod", refused)
    with pytest.raises(PermissionError):
        write_text_atomic(tmp_path / "out.txt", "x")
    assert list(tmp_path.iterdir()) == []
