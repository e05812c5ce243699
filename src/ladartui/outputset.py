"""All-or-nothing output sets: a run's files are replaced together or not at all.

``OutputSet`` checks every path can be written before any work starts, holds a
lock file per set (a second writer is refused), writes every file to a hidden
temporary beside its target, fsyncs, and then swaps them in under a journal:
each old file is renamed to a hidden backup, the new one renamed into place,
and only when all are in place is the journal removed (the commit point) and
the backups deleted. A failure rolls the old files back; a run killed during
the swap leaves the journal, and the next run over the same set rolls it back
before anything else and removes the hidden temporaries of killed runs.
"""

from __future__ import annotations

import contextlib
import errno
import glob
import json
import os
import stat
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ladartui.atomic import held_temporary, unlink_unheld
from ladartui.errors import OutputFileError, OutputSetBusy, check_cancelled, os_reason
from ladartui.fileprobe import SPECIAL_FILE

# Called with a step name ("temporaries", "swap", "backups") at each stage of the
# write; None in use. Tests set it to pause a run there and kill it.
_step_hook: Callable[[str], None] | None = None


# A file is written through hidden companions beside it: ".NAME.XXXXXXXX.tmp" (its
# temporary, 14 bytes more than the name) and ".NAME.PID.old" (a backup). In an
# output set a writer that is atomic itself makes a temporary of the temporary (28
# more); a set's lock has its journal and the journal's temporary (12 more).
TEMPORARY_EXTRA = 14
SET_MEMBER_EXTRA = 28
LOCK_EXTRA = 12


def name_problem(path, extra: int = TEMPORARY_EXTRA) -> str | None:
    """None when ``path``'s name, and its hidden companions' ``extra`` bytes more, fit
    this system; else why not."""
    path = Path(path)
    name_max = _name_max(path.parent)
    length = len(os.fsencode(path.name))
    if length > name_max:
        return f"name too long for this system ({length} bytes; at most {name_max} a name)"
    if length + extra > name_max:
        return (
            f"name too long for this system ({length} bytes, and {length + extra} for the hidden "
            f"file written beside it; at most {name_max} a name)"
        )
    return None


def check_names(*paths, extra: int = TEMPORARY_EXTRA, advice: str = "") -> None:
    """Raise ``OutputFileError`` naming the first path ``name_problem`` refuses (``advice``
    added to the message)."""
    for path in paths:
        problem = name_problem(path, extra)
        if problem:
            raise OutputFileError(path, problem + advice)


def not_a_file(folder: bool) -> str:
    """What is wrong with an output name that a folder (``folder``) or a special file holds."""
    return f"{'is a folder' if folder else SPECIAL_FILE}, expected a file name"


def output_problem(path) -> str | None:
    """None when ``path`` can be written as a file; else what is wrong, in words."""
    path = Path(path)
    try:
        if path.is_dir():
            return not_a_file(folder=True)
        if path.exists() and not path.is_file():  # a pipe would be replaced, a device written over
            return not_a_file(folder=False)
        problem = name_problem(path)
        if problem:
            return problem
        folder = path.parent
        while not folder.exists():
            if folder == folder.parent:
                break
            folder = folder.parent
        if not folder.is_dir():
            return f"cannot be written: {folder} is a file, not a folder"
        # Root ignores permission bits and /proc refuses new files: try for real.
        fd, probe = tempfile.mkstemp(prefix=f".{path.name[:64]}.", suffix=".probe", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as error:
        reason = os_reason(error)
        return f"cannot be written ({reason.lower()})"
    return None


def _name_max(folder: Path) -> int:
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


def check_writable(*paths) -> None:
    """Raise ``OutputFileError`` naming the first path that cannot be written."""
    for path in paths:
        problem = output_problem(path)
        if problem:
            raise OutputFileError(path, problem)


def check_writable_folder(folder) -> None:
    """Raise ``OutputFileError`` unless ``folder`` is (or can be made) a writable folder."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise OutputFileError(folder, "is a file, expected a folder")
    problem = output_problem(folder / "probe")
    if problem:
        raise OutputFileError(folder, problem.replace("probe", str(folder)))


LOCK_FOLDER = (
    "is a folder, expected the lock file of this set of outputs (made while they are written): "
    "remove the folder"
)


def check_lock(lock) -> None:
    """``OutputFileError`` for a folder where a set's lock file goes (asked before the work)."""
    if Path(lock).is_dir():
        raise OutputFileError(lock, LOCK_FOLDER)


# How long a run waits on a held lock before it is refused: ``lock_holder`` holds it shared
# for microseconds (the pid it finds may be a killed run's), and a run writes its pid at
# once after locking.
LOOK_SECONDS = 0.2


def lock_holder(lock) -> str | None:
    """The pid of the run that holds ``lock`` now (as it wrote it; "?" before it has),
    or None when no run does (no file, or one a killed run left). The lock is only
    asked for, shared and let go at once: it is never held, nor its file made."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock to ask
        return None
    try:  # (not waiting: a pipe there would hold an open for reading until written)
        fd = os.open(lock, os.O_RDONLY | os.O_NONBLOCK)
    except OSError:  # none (or a folder, said where the run would be refused)
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # no run's lock
            return None
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except OSError as error:
            if error.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                return None
            return os.read(fd, 32).decode("ascii", "replace").strip() or "?"
        fcntl.flock(fd, fcntl.LOCK_UN)
        return None
    finally:
        os.close(fd)


def held_refusal(lock, holder: str) -> OutputSetBusy:
    """The refusal of a run whose set's ``lock`` the run of pid ``holder`` holds."""
    return OutputSetBusy(
        lock, f"another run (pid {holder}) is writing this output set; wait for it to finish"
    )


def check_not_held(lock) -> None:
    """``held_refusal`` when a run holds ``lock`` now: asked before long work (compiling the
    kernels, loading the scene) that the lock, taken after it, would refuse."""
    holder = lock_holder(lock)
    if holder is not None:
        raise held_refusal(lock, holder)


class OutputSet:
    """The files of one run, written together; use as a context manager around the work.

    Entering checks every path, takes the lock (refusing a second writer),
    repairs a killed run's half-done swap and removes stale temporaries.
    """

    def __init__(self, paths: dict[str, Path], lock: Path):
        self.paths = {name: Path(path) for name, path in paths.items()}
        self.lock = Path(lock)
        self.journal = journal_path(self.lock)
        self._lock_fd: int | None = None
        # True once every new file is in place for good: an interruption after it (as the
        # old files' backups go) leaves the new set written, not the earlier one
        self.committed = False

    def __enter__(self) -> OutputSet:
        check_writable(*self.paths.values())
        check_names(*self.paths.values(), extra=SET_MEMBER_EXTRA)
        check_names(self.lock, extra=LOCK_EXTRA)
        self._acquire()
        try:
            recover(self.journal)
            self._remove_stale()
        except BaseException:
            self._release()
            raise
        return self

    def __exit__(self, *exc) -> None:
        self._release()

    # -- lock --

    def _acquire(self):
        import fcntl

        self.lock.parent.mkdir(parents=True, exist_ok=True)
        looked_at_until = time.monotonic() + LOOK_SECONDS
        while True:
            try:
                fd = os.open(self.lock, os.O_RDWR | os.O_CREAT, 0o644)
            except IsADirectoryError:
                raise OutputFileError(self.lock, LOCK_FOLDER) from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as error:
                holder = os.read(fd, 32).decode("ascii", "replace").strip()
                os.close(fd)
                busy = error.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES)
                if busy and time.monotonic() < looked_at_until:
                    # a look at the lock (``lock_holder``; the pid in it may be a killed run's),
                    # or a run about to say its pid: a real holder is told after this wait
                    time.sleep(0.002)
                    continue
                if busy:
                    raise held_refusal(self.lock, holder or "?") from None
                raise
            # The holder before us removes the file as it lets go: lock the one on disk.
            try:
                if os.stat(self.lock).st_ino == os.fstat(fd).st_ino:
                    break
            except FileNotFoundError:
                pass
            os.close(fd)
        self._lock_fd = fd  # held: released (the file removed) however the rest goes
        try:
            os.ftruncate(fd, 0)
            os.write(fd, str(os.getpid()).encode("ascii"))
        except OSError as error:  # a full disk: the pid is the set's first byte written
            self._release()
            raise _write_error(self.lock, error) from None
        except BaseException:
            self._release()
            raise

    def _release(self):
        if self._lock_fd is not None:
            with contextlib.suppress(OSError):
                os.unlink(self.lock)  # still held, so no one else has it open and locked
            os.close(self._lock_fd)
            self._lock_fd = None

    def _remove_stale(self):
        with contextlib.suppress(OSError):
            self.journal.with_name(self.journal.name + ".tmp").unlink()
        for path in self.paths.values():
            name = glob.escape(path.name)  # "[" in a name is no pattern
            # this set's temporaries (and their writers' own) that no live writer holds: a
            # plain write of one of the names may be under way, the lock is the set's alone
            for pattern in (f".{name}.*.tmp", f"..{name}.*.tmp"):
                for stale in path.parent.glob(pattern):
                    unlink_unheld(stale)
            for stale in path.parent.glob(f".{name}.*.old"):
                with contextlib.suppress(OSError):
                    stale.unlink()

    # -- write --

    def write(
        self, writers: dict[str, Callable[[Path], None]], cancel: threading.Event | None = None
    ) -> dict[str, str]:
        """Write every file with ``writers[name](temporary_path)``, then swap them all in.

        Before the swap a set ``cancel`` stops with ``Cancelled`` and nothing
        replaced; once the swap has begun it runs to the end (or is rolled back
        on failure), so the files on disk always belong to one run.
        """
        temps: dict[str, Path] = {}
        holds: list[int] = []  # so a plain atomic write of one of the names keeps them
        try:
            for name, path in self.paths.items():
                try:  # a folder out of inodes (or over its quota) refuses the temporary itself
                    fd, temps[name] = held_temporary(path)
                    holds.append(fd)
                    writers[name](temps[name])
                except OSError as error:
                    raise _write_error(path, error) from None
                _fsync_file(temps[name])
            _step("temporaries")
            check_cancelled(cancel, "run cancelled; nothing was written, earlier outputs are unchanged")
            self._swap(temps)
        finally:
            for temp in temps.values():
                with contextlib.suppress(OSError):
                    temp.unlink()
            for fd in holds:
                os.close(fd)
        return {name: str(path) for name, path in self.paths.items()}

    def write_contents(
        self,
        contents: dict[str, bytes],
        cancel: threading.Event | None = None,
        modes: dict[str, int] | None = None,
    ) -> dict[str, str]:
        """``write`` for files whose bytes are made already; ``modes`` gives a file its
        permissions before its bytes go in (a private key: owner only)."""

        def writer(name: str) -> Callable[[Path], None]:
            def write(tmp: Path) -> None:
                if modes and name in modes:
                    os.chmod(tmp, modes[name])
                Path(tmp).write_bytes(contents[name])

            return write

        return self.write({name: writer(name) for name in contents}, cancel)

    def _swap(self, temps):
        entries: list[dict[str, Any]] = []  # the journal's: path, backup, existed
        for path in self.paths.values():
            backup = path.with_name(f".{path.name}.{os.getpid()}.old")
            entries.append({"path": str(path), "backup": str(backup), "existed": os.path.lexists(path)})
        try:
            _write_journal(self.journal, entries)
        except OSError as error:  # no rename has started
            with contextlib.suppress(OSError):
                os.unlink(self.journal.with_name(self.journal.name + ".tmp"))
            raise _write_error(self.journal, error) from None
        replacing = self.journal  # the file being replaced when a rename fails
        try:
            for entry, tmp in zip(entries, temps.values()):
                replacing = Path(entry["path"])
                if entry["existed"]:
                    os.rename(entry["path"], entry["backup"])
                _step("swap")
                os.rename(tmp, entry["path"])
            replacing = self.journal
            for folder in {Path(e["path"]).parent for e in entries}:
                _fsync_dir(folder)
            os.unlink(self.journal)  # the commit point
            _fsync_dir(self.journal.parent)
        except BaseException as error:
            # what failed: a rename of an output, or (the journal) the commit after them
            failed = "could not be removed" if replacing == self.journal else "could not be replaced"
            try:
                _roll_back(entries)
            except OSError as also:  # the journal stays: the next run puts them back
                raise OutputFileError(
                    replacing,
                    f"{failed} ({_reason(error)}), and the earlier outputs could not be put back "
                    f"({os_reason(also).lower()}); the next run puts them back first",
                ) from None
            with contextlib.suppress(OSError):
                os.unlink(self.journal)
            if isinstance(error, OSError):  # a rename the folder refused: one line, not a traceback
                raise OutputFileError(
                    replacing,
                    f"{failed} ({_reason(error)}); nothing was replaced, earlier outputs are unchanged",
                ) from None
            raise
        self.committed = True
        _step("backups")
        for entry in entries:
            with contextlib.suppress(OSError):
                os.unlink(entry["backup"])


def journal_path(lock: Path) -> Path:
    """Where a set's swap keeps its journal while it runs (left there by a killed run)."""
    return Path(lock).with_name(Path(lock).name + ".journal")


def recover(journal: Path) -> bool:
    """Undo the swap a killed run left half done (its journal is on disk); True if it did."""
    try:
        entries = json.loads(Path(journal).read_text(encoding="utf-8"))
    except FileNotFoundError:
        return False
    except (OSError, ValueError):
        entries = []  # torn before it was complete: no rename had started
    _roll_back(entries)
    with contextlib.suppress(FileNotFoundError):
        os.unlink(journal)
    return True


def _roll_back(entries):
    for entry in entries:
        path, backup = entry["path"], entry["backup"]
        if entry["existed"]:
            if os.path.lexists(backup):
                os.replace(backup, path)
        elif os.path.lexists(path):
            os.unlink(path)


def _write_journal(journal: Path, entries):
    tmp = journal.with_name(journal.name + ".tmp")
    with open(tmp, "w", encoding="utf-8") as handle:
        json.dump(entries, handle)
        handle.flush()
        os.fsync(handle.fileno())
    os.replace(tmp, journal)
    _fsync_dir(journal.parent)


def _reason(error: BaseException) -> str:
    """Why a swap stopped, in words: the system's reason, or "interrupted" (Ctrl-C, SIGTERM)."""
    return os_reason(error).lower() if isinstance(error, OSError) else "interrupted"


def _write_error(path, error: OSError) -> OutputFileError:
    reason = os_reason(error)
    return OutputFileError(
        path, f"could not be written ({reason.lower()}); nothing was replaced, earlier outputs are unchanged"
    )


def _step(name):
    if _step_hook is not None:
        _step_hook(name)


def _fsync_file(path: Path):
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(folder: Path):
    with contextlib.suppress(OSError):  # some file systems cannot fsync a folder
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
