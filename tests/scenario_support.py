"""The scenario text and model files the scenario tests start from."""

import textwrap

BASE = textwrap.dedent("""\
    [files]
    scene = "models/forest.txt"
    voxel_size = 0.5

    [sensor]
    grid = 32
    ray_grid = 2
    fov_deg = 12.0
    depth_resolution_m = 1.5
    pixel_pitch_um = 100.0

    [flight]
    speed_mps = 25.0

    [flight.start]
    x = 0.0
    y = -100.0
    z = 80.0
    heading = 0.0
    azimuth = 0.0
    depression = 45.0

    [[flight.segments]]
    kind = "straight"
    distance = 50.0
    scans = 2

    [[flight.segments]]
    kind = "orbit"
    centre = [10.0, 10.0, 1.0]
    radius = 60.0
    altitude = 60.0
    scans = 8

    [simulation]
    backend = "auto"
    method = "march"
    step = 0.25
    precision = "f32"
    fast_mode = true
    """)


def write_models(folder, stem="forest", target=((1, 1, 0), (2, 1, 0), (1, 2, 1))):
    folder.mkdir(parents=True, exist_ok=True)
    scene = folder / f"{stem}.txt"
    scene.write_text("".join(f"{x},{y},{z}\n" for x, y, z in [(5, 5, 3), *target]))
    (folder / f"{stem}_Target.txt").write_text("".join(f"{x},{y},{z}\n" for x, y, z in target))
    return scene


def write_scenario(tmp_path, text=BASE, name="case.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def edited(key_line, new_line, text=BASE):
    assert key_line in text, key_line
    return text.replace(key_line, new_line, 1)


def line_of(text, fragment):
    return next(i for i, line in enumerate(text.splitlines(), start=1) if fragment in line)


# A small valid scenario over s.txt: the parser fuzzers' seed, the model-file tests' plan.
VALID_SCENARIO = """[files]
scene = "s.txt"
voxel_size = 1.0

[sensor]
grid = 16
ray_grid = 2
fov_deg = 20.0

[flight]
speed_mps = 30.0

[[flight.segments]]
kind = "orbit"
centre = [0.5, 0.5, 0.5]
radius = 20.0
altitude = 30.0
scans = 4
"""
