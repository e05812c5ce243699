"""Speed against accuracy: every backend x method x setting, timed and scored.

``run_study`` traces a scenario's scans with each setting, times the traces
(median after warm-up), compares each ray's first hit with exact float64 numba,
scores the obscured target coverage against a converged reference (exact,
ray grid 8), and marks the Pareto front. ``draw_chart``/``chart_text``/
``chart_svg`` draw the chart; ``StudyResult.verdict`` names the settings never
worth using; ``StudyResult.write`` writes CSV and JSON atomically.
"""

from ladartui.pareto import dominates, pareto_front
from ladartui.study.chart import chart_svg, chart_text, draw_chart, table_rows
from ladartui.study.misses import CLASSES, MissSummary, summarise, voxel_geometry
from ladartui.study.results import StudyResult, StudyRow
from ladartui.study.settings import Setting, full_settings, quick_settings, reference_setting
from ladartui.study.timing import Timing, measure

__all__ = [
    "CLASSES",
    "MissSummary",
    "Setting",
    "StudyResult",
    "StudyRow",
    "Timing",
    "chart_svg",
    "chart_text",
    "dominates",
    "draw_chart",
    "full_settings",
    "measure",
    "pareto_front",
    "quick_settings",
    "reference_setting",
    "run_study",
    "StudyInputs",
    "StudyProgress",
    "summarise",
    "table_rows",
    "voxel_geometry",
    "write_outputs",
]


def __getattr__(name):
    # The runner pulls in the tracing stack; load it only when asked for.
    if name in ("run_study", "StudyInputs", "StudyProgress", "write_outputs"):
        from ladartui.study import run

        return getattr(run, name)
    raise AttributeError(f"module 'ladartui.study' has no attribute {name!r}")
