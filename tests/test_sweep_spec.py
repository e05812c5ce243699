"""Sweep specs: grids, random draws and presets read into variants, each mistake named by
file, key and line (a scenario given as a spec told so); variant ids stable across key
order, number spelling and processes."""

import itertools
import os
import subprocess
import sys

import pytest

from ladartui.errors import InputFileError
from ladartui.sweep import load_sweep_spec, variant_id
from tiny_sweep import write_spec

# -- specs ---------------------------------------------------------------------------


def test_grid_is_the_product_of_its_axes(tmp_path):
    spec = load_sweep_spec(
        write_spec(
            tmp_path,
            """
[grid]
radius = [100, 150.5]
altitude = { start = 100, stop = 300, step = 100 }
fov = 10
""",
        )
    )
    points = [v.params for v in spec.variants]
    expected = [
        {"radius": r, "altitude": a, "fov": 10.0}
        for r, a in itertools.product([100.0, 150.5], [100.0, 200.0, 300.0])
    ]
    assert points == expected
    assert spec.scenario_path == tmp_path / "base.toml"


def test_random_draws_follow_the_seed_and_the_bounds(tmp_path):
    body = """
[grid]
preset = ["orbit"]
[random]
samples = 20
seed = {seed}
heading_offset = {{ min = 10, max = 20 }}
scans = {{ min = 3, max = 5 }}
fov = [5.0, 7.5]
"""
    first = load_sweep_spec(write_spec(tmp_path, body.format(seed=7), "a.toml")).variants
    again = load_sweep_spec(write_spec(tmp_path, body.format(seed=7), "b.toml")).variants
    other = load_sweep_spec(write_spec(tmp_path, body.format(seed=8), "c.toml")).variants
    assert [v.params for v in first] == [v.params for v in again]
    assert [v.params for v in first] != [v.params for v in other]
    for variant in first:
        p = variant.params
        assert 10 <= p["heading_offset"] <= 20
        assert p["scans"] in (3, 4, 5) and isinstance(p["scans"], int)
        assert p["fov"] in (5.0, 7.5)
    assert {v.params["scans"] for v in first} == {3, 4, 5}  # 20 draws reach every integer


def test_parameters_that_do_not_apply_to_a_preset_make_no_extra_variants(tmp_path):
    spec = load_sweep_spec(
        write_spec(
            tmp_path,
            """
[grid]
preset = ["orbit", "flypast"]
radius = [50, 60, 70]
standoff = [10, 20]
""",
        )
    )
    # 3 orbits (radius only) + 2 fly-pasts (standoff only), not 2 x 3 x 2.
    assert sorted(
        (p["preset"], p.get("radius"), p.get("standoff")) for p in (v.params for v in spec.variants)
    ) == sorted(
        [("orbit", r, None) for r in (50.0, 60.0, 70.0)] + [("flypast", None, s) for s in (10.0, 20.0)]
    )


@pytest.mark.parametrize(
    "body, key, line",
    [
        ("[grid]\nradius = []\n", "grid.radius", 4),
        ("[grid]\nscans = [2, 2.5]\n", "grid.scans", 4),
        ("[grid]\nradious = [1]\n", "grid.radious", 4),
        ("[grid]\npreset = ['circle']\n", "grid.preset", 4),
        ("objective = 'fastest'\n[grid]\nradius = [1]\n", "sweep.objective", 3),
        ("objective = 'coverage-within-budget'\n[grid]\nradius = [1]\n", "sweep.budget", None),
        ("[random]\nseed = 1\nfov = { min = 5, max = 1 }\n", "random.samples", None),
        ("[random]\nsamples = 2\nfov = { min = 5, max = 1 }\n", "random.fov", 5),
        ("[grid]\nfov = [1]\n[random]\nsamples = 2\nfov = [1, 2]\n", "random.fov", 7),
        ("", "grid", None),
    ],
)
def test_spec_errors_name_the_file_key_and_what_was_expected(tmp_path, body, key, line):
    path = write_spec(tmp_path, body)
    with pytest.raises(InputFileError) as caught:
        load_sweep_spec(path)
    message = str(caught.value)
    assert message.startswith(str(path))
    assert f" {key}" in message or f"{key}:" in message
    assert "expected" in message and "\n" not in message
    assert "None" not in message  # a key never written is missing, not "got None"
    if line is not None:
        assert caught.value.line == line


def test_a_spec_that_is_not_toml_names_its_line(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('[sweep]\nscenario = "a.toml"\n[grid]\nradius = [1,\n', encoding="utf-8")
    with pytest.raises(InputFileError, match="not valid TOML"):
        load_sweep_spec(path)


def test_a_scenario_given_as_the_spec_is_told_so(tmp_path):
    """'ladartui sweep orbit.toml' said 'orbit.toml:1: files: unknown key; expected one of
    grid, random, sweep', as if the scenario were a spec with a typing mistake; the
    scenario reader tells the other way round ('a sweep spec ([sweep]), not a scenario')."""
    path = tmp_path / "orbit.toml"
    path.write_text('# an orbit\n[files]\nscene = "s.txt"\n[flight]\nspeed_mps = 30.0\n')
    with pytest.raises(InputFileError) as caught:
        load_sweep_spec(path)
    assert str(caught.value) == (
        f"{path}:2: a scenario ([files]), not a sweep spec: a spec's [sweep] names it "
        "(scenario = \"orbit.toml\"), see docs/sweeps.md; 'ladartui run FILE' runs it"
    )


def test_a_toml_mistake_in_a_spec_is_named_as_file_and_line_as_a_scenario_s_is(tmp_path):
    """It read 'spec.toml: not valid TOML: Expected '=' after a key in a key/value pair
    (at line 3, column 8)': the line inside the message, not where editors look for it."""
    path = tmp_path / "spec.toml"
    path.write_text('[sweep]\nscenario = "a.toml"\nradius 20\n', encoding="utf-8")
    with pytest.raises(InputFileError) as caught:
        load_sweep_spec(path)
    assert caught.value.line == 3
    assert str(caught.value) == f"{path}:3: not valid TOML: Expected '=' after a key in a key/value pair"
    path.write_text('[sweep]\nscenario = "a.toml"\nradius = [20,\n', encoding="utf-8")  # cut off
    with pytest.raises(InputFileError) as caught:
        load_sweep_spec(path)
    assert str(caught.value).startswith(f"{path}:3: not valid TOML: ")


# -- variant ids ---------------------------------------------------------------------


def test_variant_ids_ignore_order_and_number_spelling_but_not_values():
    a = variant_id({"radius": 100, "scans": 4, "preset": "orbit"})
    assert a == variant_id({"preset": "orbit", "scans": 4, "radius": 100.0})
    assert a != variant_id({"preset": "orbit", "scans": 4, "radius": 100.5})
    assert a != variant_id({"preset": "flypast", "scans": 4, "radius": 100.0})
    assert len(a) == 16 and int(a, 16) >= 0


def test_variant_ids_are_stable_across_processes():
    params = {"radius": 0.1 + 0.2, "scans": 7, "preset": "standoff"}
    code = f"from ladartui.sweep import variant_id; print(variant_id({params!r}))"
    # Another process with another string-hash seed computes the same id.
    seed = "2" if os.environ.get("PYTHONHASHSEED") == "1" else "1"
    env = dict(os.environ, PYTHONHASHSEED=seed)
    other = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    ).stdout.strip()
    assert other == variant_id(params)
