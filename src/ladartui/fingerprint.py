"""Content fingerprints of input files: the size and SHA-256 of their bytes.

A run record keeps one for each file the run read (scene and target models,
flight logs) and wrote (its outputs), so that ``validate`` can name a file
changed since the run. The loaders hash the bytes as they read them
(``Digest``): nothing is read twice.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass


@dataclass(frozen=True)
class Fingerprint:
    size: int  # bytes
    sha256: str  # hex digest of the contents


class Digest:
    """The fingerprint of bytes fed in pieces, in file order."""

    def __init__(self) -> None:
        self._hash = hashlib.sha256()
        self._size = 0

    def update(self, data) -> None:
        view = memoryview(data)
        self._hash.update(view)
        self._size += view.nbytes

    def fingerprint(self) -> Fingerprint:
        return Fingerprint(self._size, self._hash.hexdigest())


def fingerprint_of(data) -> Fingerprint:
    """The fingerprint of bytes read whole."""
    digest = Digest()
    digest.update(data)
    return digest.fingerprint()


def file_fingerprint(path) -> Fingerprint | None:
    """The fingerprint of a file's bytes as they are on disk now; None when it cannot
    be read (read in 1 MB pieces, not whole)."""
    digest = Digest()
    try:
        with open(path, "rb") as file:
            for block in iter(lambda: file.read(1 << 20), b""):
                digest.update(block)
    except OSError:
        return None
    return digest.fingerprint()
