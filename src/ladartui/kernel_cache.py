"""numba's on-disk kernel cache, cleared where it was compiled from other sources.

numba keys a cached kernel on its own file alone, yet a kernel compiles the kernels
and helpers it calls from other files into itself (the tracing kernels take axis.py,
bundle.py and config.py; the returns take scene/keys.py). After one of those changed
(a `git pull`, an upgrade in place) a kernel kept its old machine code and ran the old
helper without a word. A stamp in each cache folder holds a digest of every file
kernels are compiled from; where it differs, that folder's cached kernels are
removed, to be compiled again on first use.

numba's cache sits beside the sources in ``__pycache__``, or under ``NUMBA_CACHE_DIR``
when that is set (a folder per source folder, named by numba's rule, followed here).
A cache that cannot be changed (a read-only install) is left as it is.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

STAMP_NAME = "ladartui-kernel-sources.sha256"
KERNEL_SUFFIXES = (".nbi", ".nbc")  # numba's index and compiled code
# The files numba kernels are compiled from, relative to the package: the folders of
# kernels whole, and the top level's kernel modules.
KERNEL_SOURCES = ("tracing/*.py", "scene/*.py", "detection/*.py", "returns.py", "sensor.py")


def kernel_files(root, sources=KERNEL_SOURCES) -> list[Path]:
    root = Path(root)
    return sorted({path for pattern in sources for path in root.glob(pattern)})


def sources_digest(root, sources=KERNEL_SOURCES) -> str:
    """SHA-256 over the names (from ``root``) and bytes of the kernel source files."""
    root = Path(root)
    digest = hashlib.sha256()
    for path in kernel_files(root, sources):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


def cache_folders(root, sources=KERNEL_SOURCES) -> list[Path]:
    """Where numba keeps the kernels compiled from the source files' folders."""
    folders = []
    for folder in sorted({Path(os.path.abspath(path.parent)) for path in kernel_files(root, sources)}):
        folders.append(folder / "__pycache__")
        if user_cache := os.environ.get("NUMBA_CACHE_DIR"):
            # numba's rule: the source folder's name and the SHA-1 of its absolute path
            named = f"{folder.name}_{hashlib.sha1(str(folder).encode()).hexdigest()}"
            folders.append(Path(user_cache) / named)
    return folders


def clear_stale_kernels(root, sources=KERNEL_SOURCES) -> bool:
    """Remove the kernels cached from ``root``'s kernel sources unless a folder's stamp
    matches those sources now; True when any cache was found stale and cleared."""
    try:
        digest = sources_digest(root, sources)
    except OSError:
        return False
    cleared = False
    for cache in cache_folders(root, sources):
        stamp = cache / STAMP_NAME
        try:
            if stamp.is_file() and stamp.read_text() == digest:
                continue
            # stamped before numba makes the folder: else its first kernels, unstamped,
            # would be taken for stale ones at the next start and compiled again
            cache.mkdir(parents=True, exist_ok=True)
            for path in cache.iterdir():
                if path.suffix in KERNEL_SUFFIXES:
                    os.unlink(path)
                    cleared = True
            stamp.write_text(digest)
        except OSError:  # read-only, or another process clearing it too: left as it is
            continue
    return cleared
