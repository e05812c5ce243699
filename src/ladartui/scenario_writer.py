"""The scenario file's writer: a Scenario as its TOML document (``scenario_document``)
and that document as text (``toml_text``), paths written relative to the file's folder
(``relative_path``, which run records use too). ``ladartui.scenario_file`` reads it back.
"""

from __future__ import annotations

import dataclasses
import os
import re
from pathlib import Path

import tomli_w

from ladartui.trajectory import LogSegment


def relative_path(file: Path, folder: Path) -> str:
    """``file`` relative to ``folder`` unless they share nothing but the root."""
    try:
        common = os.path.commonpath([file, folder])
    except ValueError:  # different drives
        return str(file)
    if common == file.anchor:
        return str(file)
    return os.path.relpath(file, folder)


def scenario_document(scenario) -> dict:
    """``scenario``'s TOML document as plain data (paths relative to its folder)."""
    s = scenario.sensor
    flight: dict[str, object] = {"speed_mps": scenario.speed}
    if scenario.flight.start is not None:
        flight["start"] = scenario.flight.start.to_dict()
    flight["segments"] = [_segment_to_dict(seg, scenario.path.parent) for seg in scenario.flight.segments]
    sensor: dict[str, object] = {
        "grid": s.grid,
        "ray_grid": s.ray_grid,
        "fov_deg": s.fov,
        "depth_resolution_m": s.depth_resolution,
        "pixel_pitch_um": _to_micrometres(s.pixel_pitch),
    }
    if s.mount != "stabilised":  # written only when chosen: older files stay as they were
        sensor["mount"] = s.mount
    data = {
        "files": {
            "scene": relative_path(scenario.scene_file, scenario.path.parent),
            "voxel_size": scenario.voxel_size,
        },
        "sensor": sensor,
        "flight": flight,
        "simulation": {
            "backend": scenario.backend,
            "method": scenario.method,
            "step": scenario.step,
            "precision": scenario.precision,
            "fast_mode": scenario.fast_mode,
        },
    }
    if scenario.detection is not None:
        data["detection"] = scenario.detection.to_dict()
    if scenario.levels is not None:
        data["levels"] = scenario.levels.to_dict()
    if scenario.target_names:
        data["targets"] = {"names": {str(i): name for i, name in scenario.target_names}}
    return data


def toml_text(data: dict) -> str:
    """``data`` as TOML, short numeric arrays on one line."""
    return _compact_arrays(tomli_w.dumps(data))


def _segment_to_dict(segment, folder: Path) -> dict:
    data = {"kind": segment.kind}
    for f in dataclasses.fields(segment):
        value = getattr(segment, f.name)
        if value is None:
            continue
        if f.name == "poses":
            value = [p.to_dict() for p in value]
        elif isinstance(segment, LogSegment) and f.name == "file":
            value = relative_path(Path(value), folder)
        elif isinstance(value, tuple):
            value = list(value)
        data[f.name] = value
    return data


def _to_micrometres(metres: float) -> float:
    # Shortest decimal, so 100e-6 m is written as 100.0 and reads back identically.
    micrometres = float(f"{metres * 1e6:.12g}")
    return micrometres if micrometres / 1e6 == metres else metres * 1e6


def _compact_arrays(text: str) -> str:
    """Put short numeric arrays on one line: ``centre = [32.0, 32.0, 1.0]``."""
    number = r"[-+]?(?:\d[\d_]*(?:\.\d+)?(?:[eE][-+]?\d+)?|inf|nan)"

    def join(match):
        items = re.findall(number, match.group(1))
        return "[" + ", ".join(items) + "]"

    return re.sub(r"\[\n((?:[ \t]+" + number + r",\n)+)[ \t]*\]", join, text)
