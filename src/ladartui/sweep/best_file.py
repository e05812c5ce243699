"""The best flight path of a sweep as a scenario file the analyst can open, edit and run.

A sweep (and the sweep screen's F8) writes ``NAME-best.toml`` beside its results.
The analyst may open that file, change it and save it: a later sweep must not
write over those edits. So the file's second line carries a fingerprint of what
the sweep wrote below it: a file whose text still matches its fingerprint is
the sweep's own and may be replaced; any other file (edited, or the analyst's
own) is kept, and the best path goes to the first ``NAME-best-2.toml``,
``NAME-best-3.toml``, ... that is free or the sweep's own.
"""

from __future__ import annotations

import hashlib
import itertools
import re
from dataclasses import dataclass
from pathlib import Path

from ladartui.atomic import numbered_paths
from ladartui.errors import OutputFileError
from ladartui.fileprobe import SPECIAL_FILE, file_problem
from ladartui.textsafe import one_line

HEADER = "# The best flight path of a sweep"
_FINGERPRINT = re.compile(r"\(fingerprint ([0-9a-f]{16})\)")
_NUMBERED = re.compile(r"-best(-\d+)?$")
_MOST_NUMBERS = 1000  # NAME-best-2 ... NAME-best-999, then refuse


@dataclass(frozen=True)
class BestScenario:
    """Where the best path was written, and the edited file it was written beside (if any)."""

    path: Path
    kept: Path | None = None  # NAME-best.toml left as the analyst saved it
    kept_why: str = ""  # why it was not replaced, in words


def _fingerprint(body: str) -> str:
    return hashlib.sha256(body.encode("utf-8")).hexdigest()[:16]


def _state(path: Path) -> str:
    """ "own" (a best path as a sweep wrote it), "edited" (its fingerprint no longer
    matches), "unmarked" (a sweep's header without a fingerprint: an earlier version's,
    which may hold edits), "special" (a pipe or device: not read, a pipe would wait for
    ever) or "other" (not a sweep's best path)."""
    if file_problem(path) == SPECIAL_FILE:
        return "special"
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError):
        return "other"
    lines = text.split("\n", 2)
    if not lines[0].startswith(HEADER):
        return "other"
    found = _FINGERPRINT.search(lines[1]) if len(lines) > 1 else None
    if found is None:
        return "unmarked"
    return "own" if len(lines) == 3 and found.group(1) == _fingerprint(lines[2]) else "edited"


_KEPT_WHY = {
    "edited": "edited since a sweep wrote it",
    "unmarked": "written before sweeps marked their own files; it may hold edits",
    "other": "not a best path a sweep wrote",
    "special": SPECIAL_FILE,
}


def best_target(path) -> BestScenario:
    """Where a best path meant for ``path`` goes: ``path`` itself when free or the
    sweep's own, else the first numbered name beside it that is."""
    path = Path(path)
    state = _state(path) if path.exists() else "own"
    if state == "own":
        return BestScenario(path)
    for beside in itertools.islice(numbered_paths(path, _MOST_NUMBERS - 1), 1, None):
        if not beside.exists() or _state(beside) == "own":
            return BestScenario(beside, kept=path, kept_why=_KEPT_WHY[state])
    raise OutputFileError(path, f"and {_MOST_NUMBERS - 2} numbered files beside it are edited: keep fewer")


def best_files(folder, name: str | None = None) -> list[Path]:
    """The best-path files sweeps wrote in ``folder`` (``name``'s only, if given: NAME-best
    and NAME-best-N), edited or not, newest first."""
    found = [
        path
        for path in Path(folder).glob(f"{name or '*'}-best*.toml")
        if _NUMBERED.search(path.stem)
        and (name is None or _NUMBERED.sub("", path.stem) == name)
        and _state(path) not in ("other", "special")
    ]
    return sorted(found, key=lambda path: path.stat().st_mtime_ns, reverse=True)


def write_best_scenario(path, base, row: dict, parameter_names, scene_loader) -> BestScenario:
    """Save the scenario of ``row`` (the base with its parameters) as a ready-to-open file,
    at ``path`` or beside it (``best_target``)."""
    from ladartui.atomic import write_errors_named, write_text_atomic

    target, text = best_scenario_text(path, base, row, parameter_names, scene_loader)
    with write_errors_named(target.path):
        write_text_atomic(target.path, text)
    return target  # relative scene path and outputs follow the file


def best_scenario_text(path, base, row: dict, parameter_names, scene_loader) -> tuple[BestScenario, str]:
    """Where the scenario of ``row`` goes (``best_target`` of ``path``) and its text there.

    Made afresh, not from the base file's text: the base's comments describe its own
    values (an orbit's looks, an altitude's depression), which a variant may change."""
    from ladartui.sweep.table import display_cell
    from ladartui.sweep.variant import apply_parameters

    target = best_target(path)
    params = {name: row[name] for name in parameter_names if row.get(name) is not None}
    scenario = apply_parameters(base, params, scene_loader).with_changes(path=target.path)
    settings = ", ".join(f"{name} = {display_cell(value)}" for name, value in params.items())
    header = one_line(
        f"{HEADER} (variant {row.get('variant', '?')}): "
        f"{base.path.name}" + (f" with {settings}" if settings else "")
    )
    body = scenario.to_toml()  # its scene path relative to its own folder
    mark = f"# A later sweep replaces this file until it is edited (fingerprint {_fingerprint(body)})."
    return target, f"{header}\n{mark}\n{body}"
