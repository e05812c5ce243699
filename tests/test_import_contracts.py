"""The import contracts in pyproject.toml hold, and would fail on a broken import.

`make test` runs lint-imports itself; these tests run it too, and run it on a
copy of the package with one forbidden import written in, to show the check can
fail. No cache is written (``--no-cache``), so nothing is left in the tree.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "ladartui"
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")
SHELLS = {"tui", "cli", "__main__"}


def _config() -> dict:
    with open(ROOT / "pyproject.toml", "rb") as stream:
        return tomllib.load(stream)["tool"]["importlinter"]


def _contract(contract_id: str) -> dict:
    return next(c for c in _config()["contracts"] if c["id"] == contract_id)


def _lint_imports(cwd: Path, pythonpath: Path | None = None) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    if pythonpath is not None:
        env["PYTHONPATH"] = str(pythonpath)
    return subprocess.run(
        [str(LINT_IMPORTS), "--no-cache", "--no-logo"],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_the_contracts_hold_and_leave_no_cache_behind():
    done = _lint_imports(ROOT)
    count = len(_config()["contracts"])
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"Contracts: {count} kept, 0 broken." in done.stdout
    assert not (ROOT / ".import_linter_cache").exists()


def test_every_top_level_module_is_named_core_or_shell():
    # a new module must take a side, or the textual contract would silently skip it
    children = {
        p.stem if p.suffix == ".py" else p.name
        for p in PACKAGE.iterdir()
        if (p.suffix == ".py" and p.stem != "__init__") or (p / "__init__.py").is_file()
    }
    core = {name.removeprefix("ladartui.") for name in _contract("core-below-shells")["source_modules"]}
    assert core == children - SHELLS


# One forbidden import per contract, written into a copy of the package.
BREAKS = [
    ("flight/plan.py", "import textual", "The core imports neither the shells (tui, cli) nor textual"),
    ("measures.py", "import ladartui.tui.app", "The core imports neither the shells (tui, cli) nor textual"),
    ("tracing/axis.py", "import ladartui.scenario", "Tracing knows rays and occupancy"),
    ("scene/model.py", "import ladartui.measures", "Layers: shells over studies"),
    ("errors.py", "import ladartui.textsafe", None),  # allowed: textsafe sits beside errors
]


@pytest.mark.parametrize(("module", "line", "broken"), BREAKS, ids=[b[0] for b in BREAKS])
def test_a_forbidden_import_written_into_a_copy_breaks_its_contract(tmp_path, module, line, broken):
    copy = tmp_path / "ladartui"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    with open(copy / module, "a") as stream:
        stream.write(f"\n{line}  # noqa\n")
    done = _lint_imports(tmp_path, pythonpath=tmp_path)
    if broken is None:
        assert done.returncode == 0, done.stdout
        return
    assert done.returncode == 1, done.stdout
    assert "0 broken" not in done.stdout
    assert f"{broken}" in done.stdout.split("Broken contracts")[1]


def test_a_cycle_written_into_a_copy_is_found(tmp_path):
    # tracing imports scene (occupancy); scene importing tracing back closes a loop
    copy = tmp_path / "ladartui"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    with open(copy / "scene" / "model.py", "a") as stream:
        stream.write("\ndef _late():\n    import ladartui.tracing  # noqa\n")
    done = _lint_imports(tmp_path, pythonpath=tmp_path)
    assert done.returncode == 1
    broken = done.stdout.split("Broken contracts")[1]
    assert "No import cycles between sibling modules" in broken
    assert ".scene -> .tracing" in broken or ".tracing -> .scene" in broken
