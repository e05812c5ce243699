"""Atomic file writes: write a temporary file beside the target, then rename over it.

A writer holds a lock on its temporary (flock) for as long as it writes, and the
system lets go of it when the writer ends, killed or not; so a temporary no one
holds, and not made just now, is a killed write's, and the next write of the same
file removes it (otherwise each kill left one, as large as the file, for good).
Where the file system gives no such lock (flock refused, as on some network
file systems), nothing is held and nothing is removed.
"""

import contextlib
import os
import string
import tempfile
import time
from pathlib import Path

from ladartui.errors import OutputFileError, os_reason


@contextlib.contextmanager
def atomic_path(target):
    """Yield a temporary path beside ``target``; on success it replaces ``target``.

    On any exception the temporary file is removed and ``target`` is left as it was.
    """
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    remove_abandoned(target)
    fd, tmp = held_temporary(target)
    try:
        yield tmp
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise
    finally:
        os.close(fd)  # lets go of the hold


# A writer is exposed between making its temporary and holding it: one younger than
# this is never taken for a killed write's.
ABANDONED_AFTER_S = 10.0
# What tempfile puts between a temporary's prefix and suffix: eight of these.
_RANDOM_PART = (8, frozenset(string.ascii_lowercase + string.digits + "_"))


def held_temporary(target: Path, mode: int | None = None) -> tuple[int, Path]:
    """A new hidden temporary beside ``target`` (".NAME.XXXXXXXX.tmp"), held: the
    descriptor to close when done with it, and its path. ``mode``: its permissions
    (default: those a plain open() would give ``target``; mkstemp's are owner-only)."""
    import fcntl

    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with contextlib.suppress(OSError):  # a file system without locks: held by no one
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        os.chmod(tmp, _default_mode(target) if mode is None else mode)
    except BaseException:
        os.close(fd)
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return fd, Path(tmp)


def is_temporary_of(name: str, target_name: str) -> bool:
    """Whether ``name`` is one ``held_temporary`` makes for a file named ``target_name``
    (".NAME." + eight random characters + ".tmp"), not a person's ".NAME.mine.tmp"."""
    prefix, suffix = f".{target_name}.", ".tmp"
    if not (name.startswith(prefix) and name.endswith(suffix)):
        return False
    middle = name[len(prefix) : -len(suffix)]
    length, characters = _RANDOM_PART
    return len(middle) == length and set(middle) <= characters


def remove_abandoned(target: Path) -> None:
    """Remove the temporaries of ``target`` that killed writes left: held by no one,
    and older than ``ABANDONED_AFTER_S``. Another file's, or one still held, is kept."""
    try:
        entries = list(os.scandir(target.parent))
    except OSError:
        return
    now = time.time()
    for entry in entries:
        if not is_temporary_of(entry.name, target.name):
            continue
        try:
            if now - entry.stat(follow_symlinks=False).st_mtime < ABANDONED_AFTER_S:
                continue
        except OSError:
            continue
        unlink_unheld(Path(entry.path))


def unlink_unheld(path: Path) -> bool:
    """Remove the regular file ``path`` unless a live writer holds it; whether it went."""
    import fcntl

    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOFOLLOW)
    except OSError:
        return False
    try:
        if not os.path.isfile(path) or os.path.islink(path):
            return False
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # refused while its writer lives
        os.unlink(path)
        return True
    except OSError:
        return False
    finally:
        os.close(fd)


@contextlib.contextmanager
def write_errors_named(target):
    """An OSError inside as an ``OutputFileError`` naming ``target``, not the temporary
    file beside it that ``atomic_path`` was writing."""
    try:
        yield
    except OSError as error:
        reason = os_reason(error)
        raise OutputFileError(target, f"cannot be written ({reason.lower()})") from None


def _default_mode(target: Path) -> int:
    if target.exists():
        return target.stat().st_mode & 0o7777
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def write_bytes_atomic(target, data: bytes, durable: bool = False):
    """``data`` as ``target``, whole or not at all; ``durable``: on the disk (fsync)
    before it takes the name, so a crash of the machine leaves the old file or the new."""
    with atomic_path(target) as tmp:
        with open(tmp, "wb") as handle:
            handle.write(data)
            if durable:
                handle.flush()
                os.fsync(handle.fileno())


def write_text_atomic(target, text: str, durable: bool = False):
    write_bytes_atomic(target, text.encode("utf-8"), durable)


def numbered_paths(path, most: int | None = None):
    """``path``, then ``STEM-2.SUFFIX``, ``STEM-3.SUFFIX`` ... (up to ``STEM-most`` when
    given): the names a file goes to beside one it must not replace."""
    path = Path(path)
    yield path
    number = 2
    while most is None or number <= most:
        yield path.with_name(f"{path.stem}-{number}{path.suffix}")
        number += 1


def unused_path(path) -> Path:
    """``path``, or the first of ``STEM-2.SUFFIX``, ``STEM-3.SUFFIX``, ... not on disk."""
    return next(candidate for candidate in numbered_paths(path) if not candidate.exists())
