"""Reading measures back: ``.cmf`` files and the JSON of ``Measures.to_dict``.

``Measures`` writes every section itself (``ladartui.measures``), but a reader
needs each section's parser, and the per-target sections hold ``Measures`` of
their own (``ladartui.target_measures``, which sits above ``measures``); so the
readers of whole files live here, above both.
"""

from __future__ import annotations

from dataclasses import replace

from ladartui.errors import InputFileError
from ladartui.fileprobe import path_field, read_utf8, text_lines
from ladartui.levels import level_result_from_dict
from ladartui.measures import CMF_HEADER, CMF_HEADERS, Measures, measures_from_lines
from ladartui.target_measures import PerTarget, is_target_section, read_target_lines


def read_cmf(path) -> Measures:
    """Read a ``.cmf`` file written by ``Measures.write_cmf``."""
    path = path_field("path", path, "a measures file's path (.cmf)")
    try:  # a pipe is refused unread; bytes that are not UTF-8 are named on their line
        text = read_utf8(path, "expected a measures file (.cmf)")
    except OSError as error:
        raise InputFileError(path, f"cannot read: {error.strerror or error}") from None
    lines = text_lines(text)
    version = CMF_HEADERS.get(lines[0].strip()) if lines else None
    if version is None:
        raise InputFileError(path, f"not a measures file: expected first line {CMF_HEADER!r}", line=1)
    numbered = list(enumerate(lines[1:], start=2))
    split = len(numbered)
    if version >= 2:
        split = next(
            (
                i
                for i, (_, raw) in enumerate(numbered)
                if raw.strip().startswith("[") and is_target_section(raw.strip()[1:-1].strip())
            ),
            split,
        )
    # nothing before the targets' sections: what it lacks is named at the first line
    measures = measures_from_lines(path, numbered[:split], end_line=None if split else 1)
    if split < len(numbered):
        measures = replace(measures, targets=read_target_lines(path, numbered[split:], measures))
    return measures


def measures_from_dict(data: dict) -> Measures:
    """The inverse of ``Measures.to_dict`` (JSON written by ``ladartui run --json``)."""
    measures = Measures.from_dict(data)
    if data.get("levels") is not None:
        measures = replace(measures, levels=level_result_from_dict(data["levels"]))
    if data.get("targets") is not None:
        measures = replace(measures, targets=PerTarget.from_dict(data["targets"]))
    return measures
