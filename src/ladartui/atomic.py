"""Atomic file writes: write a temporary file beside the target, then rename over it."""

import contextlib
import os
import tempfile
from pathlib import Path

from ladartui.errors import OutputFileError, os_reason


@contextlib.contextmanager
def atomic_path(target):
    """Yield a temporary path beside ``target``; on success it replaces ``target``.

    On any exception the temporary file is removed and ``target`` is left as it was.
    """
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    os.close(fd)
    # mkstemp makes the file owner-only; give it the mode a plain open() would.
    os.chmod(tmp, _default_mode(target))
    try:
        yield Path(tmp)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


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
