"""The WGSL shaders and the numba kernels they mirror stay in step.

Every "numba: NAME" note in a shader names a function that exists in the
tracing package (in the file it cites, where it cites one), and the constants
both sides share come from tracing/config.py, never restated in a shader.
No adapter is needed: these read the sources.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from ladartui.tracing import config

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "ladartui"
SHADERS = sorted((PACKAGE / "shaders").glob("*.wgsl"))
# "numba: NAME", "(numba: the per-ray body of NAME, steps 1 to 5)", "numba: NAME (tracing/x.py)"
NOTE = re.compile(r"numba:\s*([^()\n]*)(?:\((tracing/[\w/]+\.py)\))?")
NAME = re.compile(r"\b_?[a-z][a-z0-9]*(?:_[a-z0-9]+)+\b|\b_[a-z][a-z0-9]*\b")


def defined_functions(files) -> dict[str, set[str]]:
    """Function names defined in each Python file (relative path -> names)."""
    found = {}
    for path in files:
        tree = ast.parse(path.read_text())
        found[path.relative_to(PACKAGE).as_posix()] = {
            node.name for node in ast.walk(tree) if isinstance(node, ast.FunctionDef)
        }
    return found


def broken_references(text: str, functions: dict[str, set[str]]) -> list[str]:
    """Each "numba: NAME" in ``text`` whose function is not defined (where cited)."""
    everywhere = set().union(*functions.values())
    broken = []
    for number, line in enumerate(text.splitlines(), 1):
        for note in NOTE.finditer(line):
            names = NAME.findall(note.group(1))
            cited = note.group(2)
            if not names:
                broken.append(f"{number}: no function named in {note.group(0)!r}")
            for name in names:
                home = functions.get(cited, set()) if cited else everywhere
                if name not in home:
                    broken.append(f"{number}: {name} is not defined in {cited or 'ladartui/tracing'}")
    return broken


@pytest.fixture(scope="module")
def functions():
    return defined_functions(sorted((PACKAGE / "tracing").glob("*.py")))


@pytest.mark.parametrize("shader", SHADERS, ids=[s.name for s in SHADERS])
def test_every_numba_reference_in_the_shaders_names_a_function_that_exists(shader, functions):
    text = shader.read_text()
    assert broken_references(text, functions) == []


def test_the_shaders_cite_the_kernels_they_mirror():
    cited = "\n".join(s.read_text() for s in SHADERS)
    for name in ("_exact_kernel", "march_kernel", "ground_answers", "test_tiles"):
        assert f"numba: {name}" in cited or f"of {name}" in cited or f" {name} and" in cited


def test_a_reference_to_a_missing_or_moved_function_is_reported(functions):
    text = (
        "// numba: _no_such_kernel\n"
        "// The ground rule (numba: _ground).\n"
        "// numba: test_tiles (tracing/numba_backend.py)\n"  # exists, but not in that file
        "// numba: the per-ray body of march_kernel\n"  # fine
    )
    assert broken_references(text, functions) == [
        "1: _no_such_kernel is not defined in ladartui/tracing",
        "2: _ground is not defined in ladartui/tracing",
        "3: test_tiles is not defined in tracing/numba_backend.py",
    ]


SHARED = (
    "MISS",
    "VOXEL",
    "GROUND",
    "UNFINISHED",
    "CUT",
    "NO_VOXEL",
    "CUT_WORD",
    "INF",
    "BUNDLE",
    "NO_CELL",
    "NO_COLUMNS",
    "METHOD_EXACT",
    "METHOD_MARCH",
    "MARCH_SKIP_MARGIN",
)


@pytest.mark.parametrize("shader", SHADERS, ids=[s.name for s in SHADERS])
def test_no_shader_restates_a_shared_constant(shader):
    text = shader.read_text()
    for name in SHARED:
        assert not re.search(rf"\bconst\s+{name}\b", text), f"{shader.name} declares {name}"
    assert "1e30" not in text
    assert not re.search(r"workgroup_size\(\s*\d", text), "workgroup size written as a number"
    assert not re.search(r"\b64u\b", text), "the bundle size written as a number"


@pytest.mark.parametrize("real", ["f64", "f32"])
def test_the_shader_header_carries_the_python_values(real):
    header = config.wgsl_constants(real)
    consts = dict(re.findall(r"const (\w+): \w+ = ([^;]+);", header))
    assert f"alias real = {real};" in header
    assert set(consts) == set(SHARED)
    codes = ("MISS", "VOXEL", "GROUND", "UNFINISHED", "CUT", "NO_VOXEL", "CUT_WORD")
    assert {name: int(consts[name]) for name in codes} == {name: getattr(config, name) for name in codes}
    assert float(consts["INF"]) == config.SHADER_INF
    assert float(consts["MARCH_SKIP_MARGIN"]) == config.MARCH_SKIP_MARGIN
    assert consts["NO_CELL"] == f"{config.NO_CELL}u" and config.NO_CELL == 2**32 - 1
    assert consts["NO_COLUMNS"] == f"{config.NO_COLUMNS}u" and config.NO_COLUMNS == 2**32 - 1
    assert consts["BUNDLE"] == f"{config.BUNDLE}u"
    assert int(consts["METHOD_EXACT"]) == config.METHOD_CODES["exact"]
    assert int(consts["METHOD_MARCH"]) == config.METHOD_CODES["march"]


def test_every_name_the_shaders_use_from_the_header_is_declared_there():
    # a name used but declared nowhere would fail only when an adapter compiles it
    header = config.wgsl_constants("f64")
    declared = set(re.findall(r"const (\w+):", header))
    used = set()
    for shader in SHADERS:
        code = re.sub(r"//[^\n]*", "", shader.read_text())
        used |= set(re.findall(r"\b[A-Z][A-Z_]{2,}\b", code))
        used -= set(re.findall(r"(?:const|override) (\w+):", code))  # declared in the shader itself
    assert used <= declared, used - declared
