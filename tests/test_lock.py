"""The environment the suite runs in is exactly the set locked in uv.lock.

`make test` installs with `uv sync --locked`; this walks the lock's dependency graph
from ladartui (with its `test` extra) for this interpreter and platform, and checks
that every package it reaches is installed at the locked version and that nothing
else is installed beside them (pip excepted: the venv is seeded with it).
"""

from __future__ import annotations

import tomllib
from importlib import metadata
from pathlib import Path

from packaging.markers import Marker
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]
PROJECT = "ladartui"
SEEDED = {"pip", "setuptools"}  # left by `python -m venv`, outside the lock's graph


def _marker_holds(dependency: dict, extra: str) -> bool:
    marker = dependency.get("marker")
    return marker is None or Marker(marker).evaluate({"extra": extra})


def locked_requirements(lock: dict, extras: tuple[str, ...] = ("test",)) -> dict[str, str]:
    """name -> version of every package the lock installs here for PROJECT[extras]."""
    # A package locked at two versions (a fork by Python version) is named with its version.
    packages: dict[str, list[dict]] = {}
    for locked in lock["package"]:
        packages.setdefault(canonicalize_name(locked["name"]), []).append(locked)
    wanted: dict[str, str] = {}
    todo: list[tuple[str, str | None, tuple[str, ...]]] = [(PROJECT, None, extras)]
    seen: set[tuple[str, str]] = set()
    while todo:
        name, version, want_extras = todo.pop()
        key = canonicalize_name(name)
        (package,) = [p for p in packages[key] if version in (None, p["version"])]
        wanted[key] = package["version"]
        groups = [("", package.get("dependencies", []))]
        groups += [(e, package.get("optional-dependencies", {}).get(e, [])) for e in want_extras]
        for extra, dependencies in groups:
            if (key, extra) in seen:
                continue
            seen.add((key, extra))
            for dependency in dependencies:
                if _marker_holds(dependency, extra):
                    todo.append(
                        (dependency["name"], dependency.get("version"), tuple(dependency.get("extra", ())))
                    )
    return wanted


def installed_versions() -> dict[str, str]:
    return {canonicalize_name(d.metadata["Name"]): d.version for d in metadata.distributions()}


def test_lock_names_every_direct_pin_at_its_pinned_version() -> None:
    lock = tomllib.loads((ROOT / "uv.lock").read_text())
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())
    wanted = locked_requirements(lock)
    pins = pyproject["project"]["dependencies"] + pyproject["project"]["optional-dependencies"]["test"]
    for pin in map(Requirement, pins):
        (spec,) = pin.specifier  # one exact pin each, a platform marker at most
        assert spec.operator == "==", f"{pin} is not pinned"
        if pin.marker is None or pin.marker.evaluate():
            locked = wanted[canonicalize_name(pin.name)]
            assert locked == spec.version, f"uv.lock disagrees with pyproject on {pin}"


def test_installed_versions_equal_the_lock() -> None:
    wanted = locked_requirements(tomllib.loads((ROOT / "uv.lock").read_text()))
    installed = installed_versions()
    assert len(wanted) > 20  # the graph walk reached the transitive set, not only the pins
    wrong = {n: (v, installed.get(n)) for n, v in wanted.items() if installed.get(n) != v}
    assert not wrong, f"locked version != installed (run `make setup`): {wrong}"
    extra = sorted(set(installed) - set(wanted) - SEEDED)
    assert not extra, f"installed but not in uv.lock: {extra}"


def test_graph_walk_follows_markers_and_extras() -> None:
    lock = {
        "package": [
            {
                "name": PROJECT,
                "version": "0.1.0",
                "dependencies": [{"name": "a"}, {"name": "win-only", "marker": "sys_platform == 'win32x'"}],
                "optional-dependencies": {"test": [{"name": "b", "extra": ["fast"]}]},
            },
            {"name": "a", "version": "1.0"},
            {"name": "win-only", "version": "9"},
            {"name": "b", "version": "2.0", "optional-dependencies": {"fast": [{"name": "c"}]}},
            {
                "name": "c",
                "version": "3.0",
                "dependencies": [
                    {"name": "d", "version": "1", "marker": "python_full_version < '3.0'"},
                    {"name": "d", "version": "2", "marker": "python_full_version >= '3.0'"},
                ],
            },
            {"name": "d", "version": "1"},
            {"name": "d", "version": "2"},
        ]
    }
    assert locked_requirements(lock) == {PROJECT: "0.1.0", "a": "1.0", "b": "2.0", "c": "3.0", "d": "2"}
    assert locked_requirements(lock, extras=()) == {PROJECT: "0.1.0", "a": "1.0"}
