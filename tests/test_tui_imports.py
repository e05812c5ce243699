"""The core never imports textual: only ladartui.tui does."""

import subprocess
import sys

CORE = [
    "ladartui",
    "ladartui.scenario",
    "ladartui.simulation",
    "ladartui.tracing",
    "ladartui.measures",
    "ladartui.cli",
    "ladartui.views",
    "ladartui.flight",
    "ladartui.sensor",
    "ladartui.scene.model",
    "ladartui.precompile",
]


def _textual_modules_after(modules):
    code = (
        "import importlib, sys\n"
        f"for name in {modules!r}:\n"
        "    importlib.import_module(name)\n"
        "print(sorted(m for m in sys.modules if m == 'textual' or m.startswith('textual.')))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    return out.stdout.strip().splitlines()[-1]


def test_core_modules_do_not_import_textual():
    assert _textual_modules_after(CORE) == "[]"


def test_the_check_would_see_textual_if_it_were_imported():
    # the same probe reports textual once the UI is imported, so the test above can fail
    assert "'textual'" in _textual_modules_after(CORE + ["ladartui.tui.app"])


def test_cli_builds_its_parser_without_textual():
    code = (
        "import sys\nfrom ladartui.cli import build_parser\nbuild_parser()\n"
        "print(any(m.startswith('textual') for m in sys.modules))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    assert out.stdout.strip().splitlines()[-1] == "False"
