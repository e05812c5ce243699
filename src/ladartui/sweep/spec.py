"""Sweep specs: which base scenario, which parameters to vary, how to rank.

A spec is a TOML file::

    [sweep]
    scenario = "orbit.toml"          # base scenario, relative to this file;
                                     # "default", "convoy": a bundled scenario
    objective = "coverage-per-km"    # see ladartui.sweep.ranking.OBJECTIVES
    cost = "flight-time"             # Pareto cost: "flight-time" or "distance"
    budget = 300.0                   # flight-time budget, seconds

    [grid]                           # every combination of these
    preset = ["orbit", "flypast"]
    radius = [100.0, 150.0]
    altitude = { start = 100, stop = 300, step = 100 }   # inclusive range

    [random]                         # and/or random draws of these
    samples = 8
    seed = 7
    heading_offset = { min = 0, max = 360 }             # uniform float
    scans = { min = 4, max = 16, integer = true }       # uniform integer
    fov = [5.0, 10.0]                                   # one of the list

The variants are the product of the grid points and the random draws. Each
variant is identified by a stable hash of its parameter values
(``variant_id``), so an interrupted sweep knows which variants are done.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
import tomllib
from dataclasses import dataclass, field
from itertools import product
from pathlib import Path
from typing import NoReturn

import numpy as np

from ladartui.errors import InputFileError
from ladartui.fileprobe import no_such_file, path_field, read_utf8, text_lines
from ladartui.scenario_file import SECTIONS as SCENARIO_SECTIONS
from ladartui.sweep.ranking import BUDGET_OBJECTIVES, OBJECTIVES
from ladartui.sweep.variant import applicable
from ladartui.toml_lines import toml_mistake
from ladartui.user_data import bundled_scenario_name

PRESETS = ("orbit", "flypast", "standoff")
# ``scenario = "default"`` (or another bundled name, e.g. "convoy") names a bundled
# scenario, made in the user data folder on first use; held as ``<name>``.


def bundled_base(name: str) -> Path:
    return Path(f"<{name}>")


def bundled_name(scenario_path: Path) -> str | None:
    """The bundled scenario a spec's ``scenario_path`` names, or None for a file."""
    text = str(scenario_path)
    return text[1:-1] if text.startswith("<") and text.endswith(">") else None


@dataclass(frozen=True)
class Parameter:
    """One parameter a sweep may vary: its value type, unit and meaning."""

    name: str
    kind: str  # "float", "int" or "choice"
    unit: str
    help: str
    choices: tuple = ()


PARAMETERS = {
    p.name: p
    for p in (
        Parameter("preset", "choice", "", "flight path preset", PRESETS),
        Parameter("radius", "float", "m", "orbit radius"),
        Parameter("standoff", "float", "m", "horizontal standoff of a fly-past or standoff sweep"),
        Parameter("altitude", "float", "m", "aircraft altitude"),
        Parameter("scans", "int", "", "number of scans along the path"),
        Parameter("heading_offset", "float", "deg", "rotation of the path about the target"),
        Parameter("arc", "float", "deg", "orbit arc flown"),
        Parameter("speed", "float", "m/s", "aircraft speed"),
        Parameter("sensor_grid", "int", "", "detectors per side (n)"),
        Parameter("ray_grid", "int", "", "rays per detector side (m)"),
        Parameter("fov", "float", "deg", "sensor field of view"),
        Parameter("depth_resolution", "float", "m", "sensor depth resolution"),
    )
}

OBJECTIVE_NAMES = tuple(OBJECTIVES)
BUDGET_OBJECTIVE_NAMES = tuple(sorted(BUDGET_OBJECTIVES))
COST_NAMES = ("flight-time", "distance")


@dataclass(frozen=True)
class Variant:
    """One point of a sweep: parameter values (in spec order) and their stable id."""

    params: dict
    id: str

    @classmethod
    def of(cls, params: dict) -> Variant:
        return cls(dict(params), variant_id(params))


@dataclass
class SweepSpec:
    """A parsed sweep spec. ``variants`` is the expanded, de-duplicated list."""

    path: Path
    scenario_path: Path
    grid: dict = field(default_factory=dict)
    random: dict = field(default_factory=dict)
    samples: int = 0
    seed: int = 0
    objective: str = "obscured-coverage"
    cost: str = "flight-time"
    budget: float | None = None
    name: str = ""

    @property
    def parameter_names(self) -> list[str]:
        return [*self.grid, *self.random]

    @property
    def variants(self) -> list[Variant]:
        return expand_variants(self)


def canonical_value(name: str, value):
    """The value as stored and hashed: floats as float, ints as int, presets as str."""
    kind = PARAMETERS[name].kind
    if kind == "float":
        return float(value)
    if kind == "int":
        return int(value)
    return str(value)


def variant_id(params: dict) -> str:
    """A stable 16-hex-digit hash of parameter values (order and int/float spelling ignored)."""
    canonical = {name: canonical_value(name, value) for name, value in params.items()}
    # repr of a float round-trips exactly, so equal values always give equal text.
    text = json.dumps(
        {k: (repr(v) if isinstance(v, float) else v) for k, v in canonical.items()},
        sort_keys=True,
        separators=(",", ":"),
    )
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def expand_variants(spec: SweepSpec) -> list[Variant]:
    """All variants: the grid product times the random draws, duplicates dropped."""
    grid_names = list(spec.grid)
    grid_points = [dict(zip(grid_names, combo)) for combo in product(*spec.grid.values())]
    random_points = _random_draws(spec) if spec.random else [{}]
    seen, variants = set(), []
    for grid_point in grid_points:
        for drawn in random_points:
            variant = Variant.of(applicable({**grid_point, **drawn}))
            if variant.id not in seen:
                seen.add(variant.id)
                variants.append(variant)
    return variants


def _random_draws(spec: SweepSpec) -> list[dict]:
    # One generator drawn in a fixed order (sample by sample, parameters in
    # spec order) so the same seed always gives the same variants.
    rng = np.random.default_rng(spec.seed)
    draws = []
    for _ in range(spec.samples):
        point = {}
        for name, rule in spec.random.items():
            if isinstance(rule, list):
                point[name] = rule[int(rng.integers(len(rule)))]
            elif rule.get("integer"):
                point[name] = int(rng.integers(int(rule["min"]), int(rule["max"]) + 1))
            else:
                point[name] = float(rng.uniform(rule["min"], rule["max"]))
        draws.append(point)
    return draws


# Variants a sweep may expand to; each is a whole run (and a row of the results table).
MAX_VARIANTS = 100_000
MAX_RANGE_VALUES = 100_000  # in one { start, stop, step } range
# Random bounds beyond this overflow the draws (floats: max - min; integers: int64).
RANDOM_BOUND = 1e15


def _check_variant_count(checker, grid, samples):
    from ladartui.errors import ResourceLimitError

    count = math.prod(len(values) for values in grid.values()) * max(samples, 1)
    if count > MAX_VARIANTS:
        sizes = " x ".join(f"{len(v):,} {k}" for k, v in grid.items())
        draws = f"{samples:,} random draws" if samples else ""
        tables = [name for name, used in (("grid", grid), ("random", samples)) if used]
        line = checker.line("", tables[0])
        where = f"{checker.path}:{line}" if line else str(checker.path)
        made = " and ".join(f"[{name}]" for name in tables) + (" make" if len(tables) > 1 else " makes")
        raise ResourceLimitError(
            f"{where}: {made} {count:,} variants ({' x '.join(filter(None, (sizes, draws)))}), "
            f"more than the limit of {MAX_VARIANTS:,}; use fewer values or samples"
        )


def load_sweep_spec(path) -> SweepSpec:
    """Read and check a sweep spec; mistakes raise InputFileError naming the key."""
    path = path_field("path", path, "a sweep spec file's path")
    try:
        text = read_utf8(path, "expected a sweep spec (.toml)")
        data = tomllib.loads(text)
    except FileNotFoundError:
        raise InputFileError(path, f"{no_such_file(path)}; expected a sweep spec (.toml)") from None
    except RecursionError:
        raise InputFileError(path, "not valid TOML: arrays or tables nested too deep to read") from None
    except OSError as error:
        raise InputFileError(path, f"cannot read: {error.strerror or error}") from None
    except tomllib.TOMLDecodeError as error:
        message, line = toml_mistake(error, text)
        raise InputFileError(path, f"not valid TOML: {message}", line=line) from None
    return parse_sweep_spec(data, path, text)


def parse_sweep_spec(data: dict, path, text: str = "") -> SweepSpec:
    """Check a spec already read from TOML (``path`` names it in errors; ``text`` finds lines)."""
    path = Path(path)
    checker = _Checker(path, text)
    scenario_table = next((key for key in data if key in SCENARIO_SECTIONS), None)
    if "sweep" not in data and scenario_table is not None:  # a scenario given where a spec goes
        raise InputFileError(
            path,
            f"a scenario ([{scenario_table}]), not a sweep spec: a spec's [sweep] names it "
            f"(scenario = \"{path.name}\"), see docs/sweeps.md; 'ladartui run FILE' runs it",
            line=checker.line("", scenario_table),
        )
    checker.known_keys(data, "", {"sweep", "grid", "random"})
    head = data.get("sweep")
    if not isinstance(head, dict):
        checker.fail("sweep", 'a [sweep] table with scenario = "BASE.toml"')
    checker.known_keys(head, "sweep.", {"scenario", "name", "objective", "cost", "budget"})
    scenario = head.get("scenario")
    if not isinstance(scenario, str) or not scenario:
        checker.fail("sweep.scenario", "the base scenario file, a path relative to the spec", scenario)
    objective = checker.choice(head, "sweep.objective", "objective", OBJECTIVE_NAMES, "obscured-coverage")
    cost = checker.choice(head, "sweep.cost", "cost", COST_NAMES, "flight-time")
    budget = head.get("budget")
    if budget is not None and not (_is_number(budget) and budget > 0):
        checker.fail("sweep.budget", "a flight-time budget in seconds, > 0", budget)
    if objective in BUDGET_OBJECTIVE_NAMES and budget is None:
        checker.fail("sweep.budget", f"a flight-time budget in seconds for objective '{objective}'", None)
    name = head.get("name", path.stem)
    stem_rule = "a file-name stem of letters, digits, '.', '_' or '-'"
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]*", name):
        if "name" not in head:  # the spec's own file name, which the user never wrote as a name
            checker.fail(
                "sweep.name",
                f"{stem_rule} to name the best-path scenario file: the spec's file name "
                f"{path.stem!r} is not one, so set sweep.name",
            )
        checker.fail("sweep.name", f"{stem_rule} (it names the best-path scenario file)", name)

    grid = {}
    table = data.get("grid", {})
    if not isinstance(table, dict):
        checker.fail("grid", "a [grid] table of parameter = [values]", table)
    for key, value in table.items():
        checker.parameter_name(f"grid.{key}", key)
        grid[key] = checker.grid_values(f"grid.{key}", key, value)

    random, samples, seed = {}, 0, 0
    table = data.get("random")
    if table is not None:
        if not isinstance(table, dict):
            checker.fail("random", "a [random] table with samples, seed and parameter rules", table)
        drawn = table.get("samples")
        if not (isinstance(drawn, int) and not isinstance(drawn, bool) and drawn >= 1):
            checker.fail("random.samples", "the number of random draws, an integer >= 1", drawn)
        samples = drawn
        seed = table.get("seed", 0)
        if not (isinstance(seed, int) and not isinstance(seed, bool) and seed >= 0):
            checker.fail("random.seed", "an integer >= 0", seed)
        for key, value in table.items():
            if key in ("samples", "seed"):
                continue
            checker.parameter_name(f"random.{key}", key)
            if key in grid:
                checker.fail(f"random.{key}", "each parameter in [grid] or [random], not both", value)
            random[key] = checker.random_rule(f"random.{key}", key, value)
        if not random:
            checker.fail("random", "at least one parameter rule besides samples and seed", None)
    if not grid and not random:
        checker.fail(
            "grid",
            "at least one parameter to vary in [grid] or [random]; known: " + ", ".join(PARAMETERS),
            None,
        )
    _check_variant_count(checker, grid, samples)
    scenario_path = path.parent / scenario
    bundled = bundled_scenario_name(scenario)  # "convoy" or "convoy.toml" with no such file here
    if bundled is not None and not scenario_path.exists():
        scenario_path = bundled_base(bundled)
    return SweepSpec(
        path=path,
        scenario_path=scenario_path,
        grid=grid,
        random=random,
        samples=samples,
        seed=seed,
        objective=objective,
        cost=cost,
        budget=float(budget) if budget is not None else None,
        name=name,
    )


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def spec_line(path, table: str, key: str) -> int | None:
    """1-based line of ``key`` in ``[table]`` of the spec file at ``path`` (None if unreadable)."""
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError):
        return None
    return _Checker(Path(path), text).line(table, key)


class _Checker:
    """Raises InputFileError naming the spec file, the key and what was expected."""

    def __init__(self, path: Path, text: str = ""):
        self.path = path
        self.lines = text_lines(text)

    def fail(self, key: str, expected: str, value: object = ...) -> NoReturn:
        shown = "" if value is ... else " (not set)" if value is None else f" (got {value!r})"
        table, _, name = key.rpartition(".")
        raise InputFileError(self.path, f"{key}: expected {expected}{shown}", line=self.line(table, name))

    def line(self, table, key):
        """1-based line of ``key`` in ``[table]`` (or of the table header), None if not found."""
        table = table.strip(".")
        current, header_line = "", None
        name = rf"(?:{re.escape(key)}|\"{re.escape(key)}\"|'{re.escape(key)}')"  # bare or quoted
        pattern = re.compile(rf"^\s*{name}\s*=")
        dotted = re.compile(rf"^\s*{re.escape(table)}\s*\.\s*{name}\s*=") if table else None
        for number, text in enumerate(self.lines, start=1):
            stripped = text.strip()
            if stripped.startswith("["):
                current = stripped.strip("[] \t").split("#")[0].strip().strip("[]")
                if current == (table or key):
                    header_line = number
                continue
            if current == table and pattern.match(text):
                return number
            if current == "" and dotted is not None and dotted.match(text):  # grid.radius = ...
                return number
        return header_line

    def known_keys(self, table, prefix, allowed):
        for key in table:
            if key not in allowed:
                raise InputFileError(
                    self.path,
                    f"{prefix}{key}: unknown key; expected one of " + ", ".join(sorted(allowed)),
                    line=self.line(prefix, key),
                )

    def choice(self, table, key, short, allowed, default):
        value = table.get(short, default)
        normal = value.replace("_", "-") if isinstance(value, str) else value
        if normal not in allowed:
            self.fail(key, "one of " + ", ".join(allowed), value)
        return normal

    def parameter_name(self, key, name):
        if name not in PARAMETERS:
            raise InputFileError(
                self.path,
                f"{key}: unknown parameter; expected one of " + ", ".join(PARAMETERS),
                line=self.line(*key.rsplit(".", 1)),
            )

    def scalar(self, key, name, value):
        parameter = PARAMETERS[name]
        if parameter.kind == "choice":
            if value not in parameter.choices:
                self.fail(key, "one of " + ", ".join(parameter.choices), value)
            return value
        if parameter.kind == "int":
            if not (isinstance(value, int) and not isinstance(value, bool)):
                self.fail(key, f"integer values ({parameter.help})", value)
            return value
        if not _is_number(value):
            self.fail(key, f"numbers ({parameter.help}, {parameter.unit})", value)
        return float(value)

    def grid_values(self, key, name, value):
        if isinstance(value, dict):
            return self.grid_range(key, name, value)
        values = value if isinstance(value, list) else [value]
        if not values:
            self.fail(key, "a non-empty list of values", value)
        out = []
        for item in values:
            item = self.scalar(key, name, item)
            if item not in out:
                out.append(item)
        return out

    def grid_range(self, key, name, table):
        if set(table) != {"start", "stop", "step"} or PARAMETERS[name].kind == "choice":
            self.fail(key, "a list of values or { start = A, stop = B, step = S }", table)
        start, stop, step = (self.scalar(key, name, table[k]) for k in ("start", "stop", "step"))
        if not step > 0 or stop < start:
            self.fail(key, "step > 0 and stop >= start", table)
        span = (stop - start) / step  # inf past float range: never made an int
        if not span < MAX_RANGE_VALUES:
            self.fail(key, f"at most {MAX_RANGE_VALUES} values in a range", table)
        count = int(math.floor(span + 1e-9)) + 1
        if count > MAX_RANGE_VALUES:
            self.fail(key, f"at most {MAX_RANGE_VALUES} values in a range", table)
        values = [start + i * step for i in range(count)]
        if PARAMETERS[name].kind == "float":
            # Round away float noise (0.1 * 3) so ids and file names stay readable.
            values = [float(round(v, 9)) for v in values]
        return values

    def random_rule(self, key, name, value):
        if isinstance(value, list):
            return self.grid_values(key, name, value)
        if not isinstance(value, dict):
            self.fail(key, "a list to choose from or { min = A, max = B }", value)
        parameter = PARAMETERS[name]
        if parameter.kind == "choice":
            self.fail(key, "a list of presets to choose from", value)
        allowed = {"min", "max", "integer"}
        if not {"min", "max"} <= set(value) or not set(value) <= allowed:
            self.fail(key, "{ min = A, max = B } (and integer = true for whole numbers)", value)
        low, high = value["min"], value["max"]
        if not (
            _is_number(low)
            and _is_number(high)
            and low <= high
            and -RANDOM_BOUND <= low
            and high <= RANDOM_BOUND
        ):
            self.fail(key, f"numbers with min <= max, within +-{RANDOM_BOUND:g}", value)
        integer = value.get("integer", parameter.kind == "int")
        if not isinstance(integer, bool):
            self.fail(f"{key}.integer", "true or false", integer)
        if parameter.kind == "int" and not integer:
            self.fail(f"{key}.integer", f"true ({name} is an integer parameter)", integer)
        if integer and (low != int(low) or high != int(high)):
            self.fail(key, "whole-number min and max for integer draws", value)
        return {"min": low, "max": high, "integer": integer}
