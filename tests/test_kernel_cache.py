"""numba's on-disk cache is keyed on a kernel's own file: a kernel that compiles in a
helper from another file (the tracing kernels take axis.py, bundle.py, config.py) kept
its old machine code after that file changed, as after a `git pull` or an upgrade in
place, and traced with the old helper without a word."""

from __future__ import annotations

import os

from ladartui.kernel_cache import STAMP_NAME, clear_stale_kernels, sources_digest

SOURCES = ("tracing/*.py", "returns.py")


def _package(root):
    (root / "tracing" / "__pycache__").mkdir(parents=True)
    (root / "__pycache__").mkdir()
    (root / "tracing" / "kernel.py").write_text("from helper import clamp\n")
    (root / "tracing" / "helper.py").write_text("def clamp(x):\n    return max(x, 0.0)\n")
    (root / "returns.py").write_text("from tracing.helper import clamp\n")
    (root / "tui.py").write_text("# no kernels here\n")
    return root


def _cache(root):
    for cache, stem in ((root / "tracing" / "__pycache__", "kernel"), (root / "__pycache__", "returns")):
        for name in (f"{stem}.step-12.py311.nbi", f"{stem}.step-12.py311.1.nbc", f"{stem}.cpython-311.pyc"):
            (cache / name).write_bytes(b"compiled")


def _kernels(root):
    return sorted(p.name for p in root.rglob("*") if p.suffix in (".nbi", ".nbc"))


def test_kernels_compiled_from_other_sources_are_cleared_once(tmp_path):
    root = _package(tmp_path / "pkg")
    _cache(root)
    # no stamp: whatever is cached may come from other sources
    assert clear_stale_kernels(root, SOURCES) is True
    assert _kernels(root) == []
    assert len(list(root.rglob("*.pyc"))) == 2  # Python's own cache is Python's
    for cache in (root / "__pycache__", root / "tracing" / "__pycache__"):
        assert (cache / STAMP_NAME).read_text() == sources_digest(root, SOURCES)
    # compiled again from these sources: kept while they stay as they are
    _cache(root)
    assert clear_stale_kernels(root, SOURCES) is False
    assert len(_kernels(root)) == 4
    # a file with no kernels edited: nothing to compile again
    (root / "tui.py").write_text("# still no kernels\n")
    assert clear_stale_kernels(root, SOURCES) is False
    # a helper edited (no kernel's own file touched): every kernel that may take it goes
    (root / "tracing" / "helper.py").write_text("def clamp(x):\n    return max(0.0, x)\n")
    assert clear_stale_kernels(root, SOURCES) is True
    assert _kernels(root) == []
    assert clear_stale_kernels(root, SOURCES) is False


def test_a_cache_that_cannot_be_changed_is_left_alone(tmp_path, monkeypatch):
    root = _package(tmp_path / "pkg")
    _cache(root)
    real_unlink = os.unlink

    def refused(path, *args, **kwargs):
        if "__pycache__" in str(path):
            raise PermissionError(13, "Permission denied")
        return real_unlink(path, *args, **kwargs)

    monkeypatch.setattr(os, "unlink", refused)
    assert clear_stale_kernels(root, SOURCES) is False  # nothing raised: numba then compiles anew
    assert not list(root.rglob(STAMP_NAME))


def test_a_numba_cache_dir_is_cleared_too(tmp_path, monkeypatch):
    import hashlib

    root = _package(tmp_path / "pkg")
    folder = (root / "tracing").resolve()
    user = tmp_path / "numba-cache" / f"tracing_{hashlib.sha1(str(folder).encode()).hexdigest()}"
    user.mkdir(parents=True)
    (user / "kernel.step-12.py311.nbi").write_bytes(b"compiled")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba-cache"))
    assert clear_stale_kernels(root, SOURCES) is True
    assert [p.name for p in user.iterdir()] == [STAMP_NAME]


def test_the_package_s_caches_are_stamped_on_import():
    from pathlib import Path

    import ladartui

    root = Path(ladartui.__file__).parent
    stamp = root / "tracing" / "__pycache__" / STAMP_NAME
    assert stamp.read_text() == sources_digest(root)


def test_kernels_cached_into_a_folder_made_since_are_kept(tmp_path, monkeypatch):
    """A cache folder numba had not made yet (a new NUMBA_CACHE_DIR, a package's first
    kernels) got no stamp: the kernels numba then cached there were taken for stale ones
    at the next start and compiled again, though no source had changed."""
    root = _package(tmp_path / "pkg")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba-cache"))
    assert clear_stale_kernels(root, SOURCES) is False  # nothing cached yet: nothing cleared
    user = next((tmp_path / "numba-cache").glob("tracing_*"))
    (user / "kernel.step-12.py311.nbi").write_bytes(b"compiled")  # as numba caches it
    assert clear_stale_kernels(root, SOURCES) is False
    assert (user / "kernel.step-12.py311.nbi").exists()
