"""Study results: one row per setting, the Pareto front, the verdict, CSV and JSON files."""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

from ladartui.atomic import write_text_atomic
from ladartui.pareto import Sense, dominator, pareto_front
from ladartui.study.misses import CLASSES, MissSummary
from ladartui.study.settings import Setting
from ladartui.study.timing import Timing

OK, SKIPPED, FAILED = "ok", "skipped", "failed"
OBJECTIVES = ("seconds per scan", "|obscured coverage error|", "share of first hits that differ")

# The study's objectives (StudyRow.objectives): less of each is better.
OBJECTIVE_SENSE: tuple[Sense, ...] = ("min", "min", "min")


@dataclass
class StudyRow:
    """What one setting measured. Shares are fractions 0..1; coverage error is signed."""

    setting: Setting
    status: str = OK
    reason: str | None = None
    rays_per_scan: int | None = None
    scans: int = 0
    timing: Timing = field(default_factory=Timing)
    misses: MissSummary = field(default_factory=MissSummary)
    coverage: float | None = None
    coverage_error: float | None = None
    front: bool = False
    dominated_by: str | None = None

    @property
    def label(self) -> str:
        return self.setting.label

    @property
    def seconds_per_scan(self) -> float | None:
        return self.timing.median

    @property
    def rays_per_second(self) -> float | None:
        seconds = self.seconds_per_scan
        if not seconds or not self.rays_per_scan:
            return None
        return self.rays_per_scan / seconds

    @property
    def hit_differs(self) -> float | None:
        return self.misses.share

    def objectives(self) -> tuple | None:
        """(seconds per scan, |coverage error|, share differing): OBJECTIVE_SENSE, all minimised."""
        if self.status != OK:
            return None
        values = (self.seconds_per_scan, _abs(self.coverage_error), self.hit_differs)
        if any(v is None or (isinstance(v, float) and math.isnan(v)) for v in values):
            return None
        return values

    def to_dict(self) -> dict:
        return {
            "label": self.label,
            **self.setting.to_dict(),
            "status": self.status,
            "reason": self.reason,
            "rays_per_scan": self.rays_per_scan,
            "scans": self.scans,
            "runs": self.timing.runs,
            "seconds": list(self.timing.seconds),
            "seconds_per_scan": self.seconds_per_scan,
            "rays_per_second": self.rays_per_second,
            "hit_differs": self.hit_differs,
            "misses": self.misses.to_dict(),
            "coverage": self.coverage,
            "coverage_error": self.coverage_error,
            "front": self.front,
            "dominated_by": self.dominated_by,
        }


def _abs(value):
    return None if value is None else abs(value)


CSV_COLUMNS = (
    "label",
    "backend",
    "method",
    "precision",
    "step",
    "ray_grid",
    "status",
    "reason",
    "rays_per_scan",
    "scans",
    "runs",
    "seconds_per_scan",
    "rays_per_second",
    "hit_differs",
    "differing_rays",
    "later",
    "earlier",
    *(f"{name}_share" for name in CLASSES),
    *(f"{name}_all_rays_share" for name in CLASSES),
    "coverage",
    "coverage_error",
    "front",
    "dominated_by",
)


@dataclass
class StudyResult:
    """All rows of a study and what they were measured on."""

    rows: list[StudyRow]
    context: dict = field(default_factory=dict)
    reference_label: str | None = None
    reference_coverage: float | None = None
    notes: list[str] = field(default_factory=list)

    def finish(self) -> None:
        """Coverage errors against the converged reference, then the Pareto front."""
        for row in self.rows:
            if row.coverage is not None and self.reference_coverage is not None:
                row.coverage_error = row.coverage - self.reference_coverage
        points = [row.objectives() for row in self.rows]
        front = pareto_front(points, OBJECTIVE_SENSE)
        for i, row in enumerate(self.rows):
            row.front = front[i]
            j = dominator(points, i, OBJECTIVE_SENSE)
            row.dominated_by = self.rows[j].label if j is not None else None

    def front_rows(self) -> list[StudyRow]:
        return sorted((r for r in self.rows if r.front), key=_seconds_or_inf)

    def dominated_rows(self) -> list[StudyRow]:
        return [r for r in self.rows if r.dominated_by is not None]

    def verdict(self) -> str:
        """A short text: the front, the settings never worth using, what was skipped."""
        lines = []
        front = self.front_rows()
        if front:
            lines.append(
                "Pareto front (fastest first; none of these is beaten on speed, "
                "coverage error and first-hit agreement at once):"
            )
            lines += [f"  {describe_row(r)}" for r in front]
        else:
            lines.append("No setting produced a complete measurement.")
        dominated = self.dominated_rows()
        if dominated:
            lines.append(
                "Never worth using (dominated: another setting is at least as fast and at least as accurate):"
            )
            lines += [f"  {r.label}: beaten by {r.dominated_by}" for r in dominated]
            everywhere = _tracers_dominated_everywhere(self.rows)
            if everywhere:
                lines.append("Dominated at every ray grid measured: " + ", ".join(everywhere) + ".")
        skipped = [r for r in self.rows if r.status != OK]
        reasons: dict[str, list[str]] = {}
        for r in skipped:
            reasons.setdefault(r.reason or r.status, []).append(r.label)
        for reason, labels in reasons.items():
            lines.append(f"Not measured ({len(labels)} settings): {reason}")
        lines += self.notes
        return "\n".join(lines)

    def to_dict(self) -> dict:
        return {
            "context": self.context,
            "objectives": list(OBJECTIVES),
            "reference": {"label": self.reference_label, "coverage": self.reference_coverage},
            "notes": list(self.notes),
            "rows": [row.to_dict() for row in self.rows],
            "verdict": self.verdict(),
        }

    @classmethod
    def from_dict(cls, data: dict) -> StudyResult:
        """Read back what ``to_dict`` wrote (to redraw a chart without measuring again)."""
        rows = []
        for item in data["rows"]:
            setting = Setting(
                item["backend"], item["method"], item["precision"], item["step"], item["ray_grid"]
            )
            misses = item.get("misses") or {}
            row = StudyRow(
                setting,
                status=item["status"],
                reason=item.get("reason"),
                rays_per_scan=item.get("rays_per_scan"),
                scans=item.get("scans", 0),
                timing=Timing(_durations(item.get("seconds") or [])),
                misses=MissSummary(
                    rays=misses.get("rays", 0),
                    voxel_rays=misses.get("voxel_rays", 0),
                    differing=misses.get("differing", 0),
                    later=misses.get("later", 0),
                    earlier=misses.get("earlier", 0),
                    no_voxel=misses.get("no_voxel", 0),
                    classes=dict(misses.get("classes") or {n: 0 for n in CLASSES}),
                    base=dict(misses.get("base") or {n: 0 for n in CLASSES}),
                ),
                coverage=item.get("coverage"),
            )
            rows.append(row)
        reference = data.get("reference") or {}
        result = cls(
            rows,
            context=data.get("context") or {},
            reference_label=reference.get("label"),
            reference_coverage=reference.get("coverage"),
            notes=list(data.get("notes") or []),
        )
        result.finish()
        return result

    def to_csv(self) -> str:
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(CSV_COLUMNS)
        for row in self.rows:
            writer.writerow([_csv_value(v) for v in _csv_record(row)])
        return buffer.getvalue()

    def write(self, out_dir, stem="study") -> dict[str, Path]:
        """Write ``stem.csv`` and ``stem.json`` atomically into ``out_dir``; their paths."""
        out_dir = Path(out_dir)
        paths = {"csv": out_dir / f"{stem}.csv", "json": out_dir / f"{stem}.json"}
        write_text_atomic(paths["csv"], self.to_csv())
        write_text_atomic(paths["json"], self.to_json())
        return paths

    def to_json(self) -> str:
        """The study as ``study.json`` holds it."""
        return json.dumps(self.to_dict(), indent=1, allow_nan=False) + "\n"


def _csv_record(row: StudyRow) -> list:
    s = row.setting
    m = row.misses
    shares = [m.class_share(name) for name in CLASSES]
    base_shares = [m.base_share(name) for name in CLASSES]
    return [
        row.label,
        s.backend,
        s.method,
        s.precision,
        s.step,
        s.ray_grid,
        row.status,
        row.reason,
        row.rays_per_scan,
        row.scans,
        row.timing.runs,
        row.seconds_per_scan,
        row.rays_per_second,
        row.hit_differs,
        m.differing,
        m.later,
        m.earlier,
        *shares,
        *base_shares,
        row.coverage,
        row.coverage_error,
        row.front,
        row.dominated_by,
    ]


def _csv_value(value):
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    return value


def _tracers_dominated_everywhere(rows) -> list[str]:
    by_tracer: dict[str, list[StudyRow]] = {}
    for row in rows:
        if row.status == OK:
            by_tracer.setdefault(row.setting.tracer_label, []).append(row)
    return [
        label
        for label, group in by_tracer.items()
        if group and all(r.dominated_by is not None for r in group)
    ]


def describe_row(row: StudyRow) -> str:
    """One line: label, speed and both accuracy figures."""
    if row.status != OK:
        return f"{row.label}: {row.status} ({row.reason})"
    return (
        f"{row.label}: {format_seconds(row.seconds_per_scan)}/scan, "
        f"{format_rate(row.rays_per_second)} rays/s, "
        f"coverage error {format_points(row.coverage_error)}, "
        f"{format_share(row.hit_differs)} of first hits differ"
    )


def format_seconds(value) -> str:
    if value is None:
        return "-"
    if value < 1e-3:
        return f"{value * 1e6:.0f} us"
    if value < 1:
        return f"{value * 1e3:.1f} ms"
    return f"{value:.2f} s"


def format_rate(value) -> str:
    if value is None:
        return "-"
    for scale, unit in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if value >= scale:
            return f"{value / scale:.2f} {unit}"
    return f"{value:.0f}"


def format_points(value) -> str:
    """A signed coverage difference in percentage points."""
    return "-" if value is None else f"{value * 100:+.2f} pts"


def format_share(value) -> str:
    if value is None:
        return "-"
    if value and value < 1e-4:
        return f"{value * 100:.4f}%"
    return f"{value * 100:.2f}%"


STUDY_JSON = "expected a study.json written by 'ladartui study'"


def _durations(seconds) -> list[float]:
    """A row's timed runs as read: durations, each a finite number of seconds >= 0."""
    for value in seconds:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value < math.inf:
            raise ValueError(f"a time of {value!r} s, where a duration is expected")
    return [float(value) for value in seconds]


def _no_constant(name: str):
    raise ValueError(f"{name}, which a study never writes")


def read_study(path) -> StudyResult:
    """A ``study.json`` written by a study (the CLI's or the terminal UI's), read back."""
    from ladartui.errors import InputFileError
    from ladartui.fileprobe import no_such_file, refuse_special_file

    refuse_special_file(path, STUDY_JSON)
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"), parse_constant=_no_constant)
        if not isinstance(data, dict):
            raise InputFileError(path, f"a JSON {type(data).__name__}, not an object; {STUDY_JSON}")
        return StudyResult.from_dict(data)
    except FileNotFoundError:
        raise InputFileError(path, f"{no_such_file(path)}; {STUDY_JSON}") from None
    except IsADirectoryError:
        raise InputFileError(path, f"is a folder; {STUDY_JSON}") from None
    except OSError as error:
        raise InputFileError(path, f"cannot be read ({error.strerror or error})") from None
    except UnicodeDecodeError:
        raise InputFileError(path, f"not UTF-8 text; {STUDY_JSON}") from None
    except json.JSONDecodeError as error:
        raise InputFileError(path, f"not JSON ({error.msg}); {STUDY_JSON}", error.lineno) from None
    except RecursionError:
        raise InputFileError(path, f"nested too deep to read; {STUDY_JSON}") from None
    except KeyError as error:
        raise InputFileError(path, f"no {error.args[0]!r} entry; {STUDY_JSON}") from None
    except (ValueError, TypeError, AttributeError, IndexError) as error:
        raise InputFileError(path, f"a value of the wrong kind ({error}); {STUDY_JSON}") from None


def study_folder(scenario_path=None) -> Path:
    """Where the terminal UI keeps a scenario's last study: ``S-study`` beside ``S.toml``;
    for the generated scenes, ``study`` in the user data folder."""
    if scenario_path is None:
        from ladartui.user_data import data_home

        return data_home() / "study"
    path = Path(scenario_path)
    return path.with_name(f"{path.stem}-study")


def _seconds_or_inf(row: StudyRow) -> float:
    # front rows have every objective measured; an unmeasured time would sort last
    seconds = row.seconds_per_scan
    return math.inf if seconds is None else seconds
