"""Flight-path sweeps: vary a base scenario, simulate every variant on Dask, rank the paths.

``run_sweep(spec, client=None, progress=None, cancel=None) -> SweepResult`` runs
a spec (see ``ladartui.sweep.spec`` for the TOML format), resuming from its
result table; ``load_sweep_results(path)`` reads a finished or partial one.
Submodules load on first use: the CLI reads a name without starting Dask or numba.
"""

from ladartui.lazy import lazy_getattr

_EXPORTS = {
    "SweepProgress": "ladartui.sweep.execute",
    "SweepResult": "ladartui.sweep.execute",
    "connect": "ladartui.sweep.cluster",
    "default_out_dir": "ladartui.sweep.execute",
    "load_sweep_results": "ladartui.sweep.execute",
    "local_client": "ladartui.sweep.cluster",
    "run_sweep": "ladartui.sweep.execute",
    "OBJECTIVES": "ladartui.sweep.ranking",
    "Ranked": "ladartui.sweep.ranking",
    "objective_value": "ladartui.sweep.ranking",
    "pareto_front": "ladartui.sweep.ranking",
    "rank_rows": "ladartui.sweep.ranking",
    "PARAMETERS": "ladartui.sweep.spec",
    "SweepSpec": "ladartui.sweep.spec",
    "Variant": "ladartui.sweep.spec",
    "expand_variants": "ladartui.sweep.spec",
    "load_sweep_spec": "ladartui.sweep.spec",
    "parse_sweep_spec": "ladartui.sweep.spec",
    "variant_id": "ladartui.sweep.spec",
    "read_table": "ladartui.sweep.table",
    "write_table": "ladartui.sweep.table",
    "apply_parameters": "ladartui.sweep.variant",
    "run_variant": "ladartui.sweep.variant",
}

__all__ = sorted(_EXPORTS)


__getattr__ = lazy_getattr("ladartui.sweep", _EXPORTS, globals())
