"""Flight-path sweeps: vary a base scenario, simulate every variant on Dask, rank the paths.

``run_sweep(spec, client=None, progress=None, cancel=None) -> SweepResult`` runs
a spec (see ``ladartui.sweep.spec`` for the TOML format), resuming from its
result table; ``load_sweep_results(path)`` reads a finished or partial one.
"""

from ladartui.sweep.execute import (
    SweepProgress,
    SweepResult,
    connect,
    default_out_dir,
    load_sweep_results,
    local_client,
    run_sweep,
)
from ladartui.sweep.ranking import OBJECTIVES, Ranked, objective_value, pareto_front, rank_rows
from ladartui.sweep.spec import (
    PARAMETERS,
    SweepSpec,
    Variant,
    expand_variants,
    load_sweep_spec,
    parse_sweep_spec,
    variant_id,
)
from ladartui.sweep.table import read_table, write_table
from ladartui.sweep.variant import apply_parameters, run_variant

__all__ = [
    "OBJECTIVES",
    "PARAMETERS",
    "Ranked",
    "SweepProgress",
    "SweepResult",
    "SweepSpec",
    "Variant",
    "apply_parameters",
    "connect",
    "default_out_dir",
    "expand_variants",
    "load_sweep_results",
    "load_sweep_spec",
    "local_client",
    "objective_value",
    "pareto_front",
    "parse_sweep_spec",
    "rank_rows",
    "read_table",
    "run_sweep",
    "run_variant",
    "variant_id",
    "write_table",
]
