"""ladartui: plan airborne foliage-penetrating LADAR collections.

The public API is importable from here; submodules load on first use so that
``import ladartui`` stays fast and never pulls in the terminal UI. Function
names never equal module names (``trace`` lives in ``ladartui.tracing``,
``simulate`` in ``ladartui.simulation``) so a submodule import cannot shadow
an exported function.
"""

import os

from ladartui.lazy import lazy_getattr

# numba's OpenMP threads spin for milliseconds after each parallel pass by default
# (libgomp: 300,000 spins), each holding a core: on a 2-core machine that starved
# lavapipe's threads (the wgpu backend ran up to 30 % slower), Dask's workers and
# the terminal UI. 30,000 spins still bridge the short gaps between a trace's
# passes (numba's own trace times did not change). Set before numba loads the
# library; a user's own setting stands.
if "OMP_WAIT_POLICY" not in os.environ:
    os.environ.setdefault("GOMP_SPINCOUNT", "30000")

__version__ = "0.1.0"

_EXPORTS = {
    "LadarError": "ladartui.errors",
    "Cancelled": "ladartui.errors",
    "load_voxels": "ladartui.scene.voxels",
    "save_voxels": "ladartui.scene.voxels",
    "generate_scene": "ladartui.scene.generate",
    "Scene": "ladartui.scene.model",
    "Occupancy": "ladartui.scene.occupancy",
    "ScanPose": "ladartui.flight",
    "FlightPlan": "ladartui.flight",
    "straight": "ladartui.flight",
    "turn": "ladartui.flight",
    "orbit": "ladartui.flight",
    "flypast": "ladartui.flight",
    "standoff_sweep": "ladartui.flight",
    "aim_at": "ladartui.flight",
    "path_length": "ladartui.flight",
    "Sensor": "ladartui.sensor",
    "Scenario": "ladartui.scenario",
    "load_scenario": "ladartui.scenario",
    "trace": "ladartui.tracing",
    "simulate": "ladartui.simulation",
    "compute_measures": "ladartui.measures",
    "TraceResult": "ladartui.tracing",
    "SimulationResult": "ladartui.simulation",
}

__all__ = sorted(_EXPORTS) + ["__version__"]


__getattr__ = lazy_getattr("ladartui", _EXPORTS, globals())
