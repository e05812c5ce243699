"""A sweep's base scenario: where it is, the hash its rows carry, and the rows made from it.

A results table may hold rows of several bases (the scenario or a model edited
between runs) and of other specs' variants (another seed): a sweep, and
anything that shows its ranking, takes only the spec's variants made from the
base as it is now.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from ladartui.errors import InputFileError
from ladartui.sweep.spec import SweepSpec, bundled_name, spec_line


def base_scenario_path(spec: SweepSpec) -> Path:
    """The base scenario file (a bundled one is made on first use)."""
    bundled = bundled_name(spec.scenario_path)
    if bundled is not None:
        from ladartui.user_data import bundled_scenario_path

        return bundled_scenario_path(bundled)
    if not spec.scenario_path.is_file():
        found = "is a folder" if spec.scenario_path.is_dir() else "does not exist"
        raise InputFileError(
            spec.path,
            f"sweep.scenario: expected an existing scenario file; {str(spec.scenario_path)!r} {found}",
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


def spec_rows(table_rows: list[dict], spec: SweepSpec) -> list[dict]:
    """The rows of ``spec``'s variants made from its base as it is now."""
    from ladartui.scenario import load_scenario

    path = base_scenario_path(spec)
    return own_rows(table_rows, spec.variants, base_digest(path, load_scenario(path, check_files=False)))


def check_some_variant_runs(spec: SweepSpec, base, scene_loader) -> None:
    """Refuse a spec none of whose variants the base can take (flight parameters over a
    base with no orbit, fly-past or standoff, a preset the base cannot complete): that
    is a mistake in the spec, named on its key's line, not one error row per variant.
    Stops at the first variant that can be built, so a good spec costs one build."""
    from ladartui.errors import FieldError
    from ladartui.sweep.variant import apply_parameters

    first = None
    for variant in spec.variants:
        try:
            apply_parameters(base, variant.params, scene_loader)
            return
        except FieldError as error:
            first = first or error
    if first is None:
        return  # a spec of no variants
    # The key to blame: the one in error, else the preset that needs what is missing.
    name = first.field if first.field in spec.parameter_names else "preset"
    table = "grid" if name in spec.grid else "random" if name in spec.random else "sweep"
    if table == "sweep":
        name = "scenario"
    raise InputFileError(
        spec.path,
        f"{table}.{name}: no variant can run on base {spec.scenario_path.name}: {first}",
        line=spec_line(spec.path, table, name),
    )
