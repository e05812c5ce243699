"""A sweep's base scenario: where it is, the hash its rows carry, and the rows made from it.

A results table may hold rows of several bases (the scenario or a model edited
between runs) and of other specs' variants (another seed): a sweep, and
anything that shows its ranking, takes only the spec's variants made from the
base as it is now.
"""

from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ladartui.errors import InputFileError
from ladartui.fileprobe import SPECIAL_FILE
from ladartui.sweep.spec import SweepSpec, bundled_name, spec_line

if TYPE_CHECKING:
    from ladartui.scenario import Scenario


def base_scenario_path(spec: SweepSpec) -> Path:
    """The base scenario file (a bundled one is made on first use)."""
    bundled = bundled_name(spec.scenario_path)
    if bundled is not None:
        from ladartui.user_data import bundled_scenario_path

        return bundled_scenario_path(bundled)
    if not spec.scenario_path.is_file():
        found = "is a folder" if spec.scenario_path.is_dir() else "does not exist"
        if spec.scenario_path.exists() and not spec.scenario_path.is_dir():
            found = SPECIAL_FILE
        raise InputFileError(
            spec.path,
            f"sweep.scenario: expected an existing scenario file; {str(spec.scenario_path)!r} {found}",
            line=spec_line(spec.path, "sweep", "scenario"),
        )
    if spec.scenario_path.resolve() == Path(spec.path).resolve():
        raise InputFileError(
            spec.path,
            f"sweep.scenario: expected the base scenario's file; {spec.scenario_path.name!r} "
            "is this sweep spec",
            line=spec_line(spec.path, "sweep", "scenario"),
        )
    return spec.scenario_path


def base_digest(scenario_path, scenario) -> str:
    """Short hash of the base scenario file and of its scene and target models' bytes.

    Stored in every row: a resumed sweep reuses only rows made from the same
    base, so editing the base scenario or either model re-runs every variant.
    """
    digest = hashlib.sha256(Path(scenario_path).read_bytes())
    for role in ("scene_file", "target_file"):
        model = getattr(scenario, role, None)
        if model is None:
            continue
        digest.update(f"\0{role}\0".encode())
        try:
            with open(model, "rb") as handle:
                for chunk in iter(lambda: handle.read(1 << 20), b""):
                    digest.update(chunk)
        except OSError:  # the run of each variant reports the file
            pass
    return digest.hexdigest()[:12]


def own_rows(table_rows: list[dict], variants, digest: str) -> list[dict]:
    """The rows of ``variants`` (in their order) made from the base whose hash is ``digest``."""
    by_key = {(row.get("variant"), row.get("base")): row for row in table_rows}
    return [row for variant in variants if (row := by_key.get((variant.id, digest))) is not None]


def load_base(spec: SweepSpec, check_files: bool = True) -> Scenario:
    """The spec's base scenario. Each variant is held to the ray limit as it runs, the
    base never: a base too large for the limit can be swept down (fewer scans, a
    smaller sensor)."""
    from ladartui.scenario import load_scenario

    return load_scenario(base_scenario_path(spec), check_files)


def spec_rows(table_rows: list[dict], spec: SweepSpec) -> list[dict]:
    """The rows of ``spec``'s variants made from its base as it is now."""
    return own_rows(table_rows, spec.variants, spec_digest(spec))


def spec_digest(spec: SweepSpec) -> str:
    """The hash of ``spec``'s base as it is now, which its rows carry."""
    base = load_base(spec, check_files=False)
    return base_digest(base.path, base)


def earlier_base_rows(table_rows: list[dict], digest: str) -> int:
    """How many rows were made from a base other than the one whose hash is ``digest``."""
    return sum(row.get("base") != digest for row in table_rows)


@dataclass(frozen=True)
class CheckedBase:
    """A spec's base scenario, read and found to take some variant of the spec: made
    once by ``checked_base`` for the caller's early refusal and the run alike."""

    spec: SweepSpec
    path: Path
    scenario: Scenario

    @functools.cached_property
    def digest(self) -> str:
        """``base_digest`` of the base: hashed once however many ask (the TUI's stored
        rows, then the run)."""
        return base_digest(self.path, self.scenario)


def checked_base(spec: SweepSpec) -> CheckedBase:
    """Read the spec's base scenario (``InputFileError`` for a missing or bad one) and
    refuse the spec when none of its variants can run on it."""
    from ladartui.resources import max_bin_visits, max_rays

    max_rays(), max_bin_visits()  # a limit mistyped is its own error, not every variant's
    scenario = load_base(spec)
    check_some_variant_runs(spec, scenario)
    return CheckedBase(spec, scenario.path, scenario)


def check_some_variant_runs(spec: SweepSpec, base) -> None:
    """Refuse a spec none of whose variants can be built from the base (flight parameters
    over a base with no orbit, fly-past or standoff, a preset the base cannot complete,
    every value out of range): a mistake in the spec, named on its key's line, not
    one error row per variant. Stops at the first variant that builds; a preset's
    aim point comes from the target model alone, never the whole scene. A variant
    refused by this machine's limits is named before an impossible one: it is what
    stops the variants that have possible values."""
    from ladartui.errors import LadarError, ResourceLimitError
    from ladartui.scenario import check_work
    from ladartui.sweep.variant import apply_parameters

    target = _TargetCentre(base)
    first = limit = None
    for variant in spec.variants:
        try:
            check_work(apply_parameters(base, variant.params, lambda: target))
            return
        except ResourceLimitError as error:
            limit = limit or error
        except LadarError as error:
            first = first or error
    first = limit or first
    if first is None:
        return  # a spec of no variants
    from ladartui.resources import sweep_advice

    if limit is not None:  # the rays: what makes them, of what the spec varies
        field = next((name for name in RAY_PARAMETERS if name in spec.parameter_names), "")
    else:
        field = getattr(first, "field", "")
    key = _blamed_key(spec, field)
    said = f"{key}: no variant can run: {sweep_advice(first)}"
    raise InputFileError(spec.path, said, line=spec_line(spec.path, *key.split(".")))


# The parameters a variant's rays grow with: a refusal for the ray limit is theirs.
RAY_PARAMETERS = ("sensor_grid", "ray_grid", "scans", "preset", "arc")


def _blamed_key(spec: SweepSpec, field: str) -> str:
    """``table.key`` of the spec to blame for ``field``'s error: that parameter, else
    the preset (it needs what is missing), else the first parameter varied."""
    names = spec.parameter_names
    if field in names:
        name = field
    elif "preset" in names:
        name = "preset"
    elif names:
        name = names[0]
    else:
        return "sweep.scenario"
    return f"{'grid' if name in spec.grid else 'random'}.{name}"


class _TargetCentre:
    """The scene as a preset without an aim point needs it: its target's centre, read
    from the target model file once (a scene file can run to gigabytes)."""

    def __init__(self, base):
        self.base, self.centre = base, None

    def target_centre_m(self):
        if self.centre is None:
            from ladartui.scene.model import Scene
            from ladartui.scene.target_model import load_target

            voxels, _ = load_target(self.base.target_file)
            # the scene's path names it and its target model in an error, as a loaded scene's does
            empty = Scene(np.zeros((0, 3), np.int32), voxels, self.base.voxel_size, path=self.base.scene_file)
            self.centre = empty.target_centre_m()
        return self.centre
