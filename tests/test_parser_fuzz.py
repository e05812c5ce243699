"""Bounded property-based fuzzers (hypothesis) over the voxel parser, the scenario
loader, the sweep spec and the command line: text mutated from a valid seed is read or
refused in one line of the project's own error, never a traceback; the seeds are valid.
"""

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ladartui.cli import main
from ladartui.errors import LadarError
from ladartui.scenario import load_scenario
from ladartui.scene.voxels import load_voxels, save_voxels
from ladartui.sweep.spec import load_sweep_spec
from scenario_support import VALID_SCENARIO

# More examples for a long search by hand: LADARTUI_FUZZ_EXAMPLES=2000.
EXAMPLES = int(os.environ.get("LADARTUI_FUZZ_EXAMPLES", "60"))
FUZZ = settings(
    max_examples=EXAMPLES, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck)
)


def assert_one_line(error):
    text = str(error)
    assert text and "\n" not in text and "Traceback" not in text


VALID_VOXELS = b"0,0,0\n1,2,3\n10,0,7\n"
VALID_SPEC = """[sweep]
scenario = "default"
objective = "obscured-coverage"

[grid]
scans = [2, 3]
radius = [10.0, 20.0]

[random]
samples = 2
seed = 1
altitude = { min = 20, max = 40 }
"""
# Tokens a careless or hostile hand puts in these files.
TOKENS = [
    "",
    "0",
    "-1",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "9" * 30,
    "2147483647",
    "\r",
    "\t",
    "\x00",
    "\x1b]0;x\x07",
    "[/oops]",
    "[",
    "]",
    "{",
    "}",
    "=",
    ",",
    '"',
    "'",
    "\n",
    "[]",
    "{}",
    "true",
    "é",
    "\ufeff",
    " ",
]


@st.composite
def mutated(draw, text):
    """``text`` with a few spans replaced by tokens or arbitrary characters."""
    for _ in range(draw(st.integers(1, 4))):
        start = draw(st.integers(0, len(text)))
        stop = draw(st.integers(start, min(len(text), start + 8)))
        insert = draw(st.one_of(st.sampled_from(TOKENS), st.text(max_size=6)))
        text = text[:start] + insert + text[stop:]
    return text


@FUZZ
@given(mutated(VALID_VOXELS.decode()))
def test_fuzz_voxel_parser(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("v") / "v.txt"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))
    try:
        voxels = load_voxels(path)
    except LadarError as error:
        assert_one_line(error)
        assert "v.txt" in str(error)
    else:
        assert voxels.ndim == 2 and voxels.shape[1] == 3 and voxels.dtype == np.int32


@pytest.fixture(scope="module")
def scene_folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("scene")
    save_voxels(folder / "s.txt", np.array([[0, 0, 0], [1, 1, 1]], np.int32))
    save_voxels(folder / "s_Target.txt", np.array([[0, 0, 0]], np.int32))
    return folder


@FUZZ
@given(text=mutated(VALID_SCENARIO))
def test_fuzz_scenario_loader(scene_folder, text):
    path = scene_folder / "fuzz.toml"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))
    try:
        load_scenario(path)
    except LadarError as error:
        assert_one_line(error)


@FUZZ
@given(text=mutated(VALID_SPEC))
def test_fuzz_sweep_spec(scene_folder, text):
    path = scene_folder / "spec.toml"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))
    try:
        spec = load_sweep_spec(path)
        assert len(spec.variants) >= 1
    except LadarError as error:
        assert_one_line(error)


@settings(
    max_examples=max(1, EXAMPLES * 2 // 3),
    deadline=None,
    derandomize=True,
    suppress_health_check=list(HealthCheck),
)
@given(
    command=st.sampled_from(["validate", "info", "run", "sweep", "trace"]),
    words=st.lists(
        st.one_of(
            st.sampled_from(
                [
                    "--step",
                    "--backend",
                    "--max-rays",
                    "--out",
                    "--precision",
                    "--method",
                    "--rays",
                    "--scene",
                    "-1",
                    "nan",
                    "1e400",
                    "--",
                    "-",
                ]
            ),
            st.sampled_from(TOKENS),
        ),
        max_size=4,
    ),
)
def test_fuzz_command_line(scene_folder, capsys, command, words):
    # Only bad invocations: a missing or broken scenario file keeps each one cheap.
    argv = [command, str(scene_folder / "missing.toml"), *words]
    if command == "run":
        argv.append("--no-write")
    try:
        code = main(argv)
    except SystemExit as stop:  # argparse: one line, status 2
        code = stop.code
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "Traceback" not in err, err


def test_fuzz_seeds_are_valid(scene_folder):
    path = scene_folder / "seed.toml"
    path.write_text(VALID_SCENARIO)
    assert load_scenario(path).scan_count() == 4
    path.write_text(VALID_SPEC)
    assert len(load_sweep_spec(path).variants) == 8
    (scene_folder / "v.txt").write_bytes(VALID_VOXELS)
    assert len(load_voxels(scene_folder / "v.txt")) == 3
