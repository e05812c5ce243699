"""ladartui: plan airborne foliage-penetrating LADAR collections.

The public API is importable from here; submodules load on first use so that
``import ladartui`` stays fast and never pulls in the terminal UI. Function
names never equal module names (``trace`` lives in ``ladartui.tracing``,
``simulate`` in ``ladartui.simulation``) so a submodule import cannot shadow
an exported function.
"""

from ladartui import threads
from ladartui.kernel_cache import clear_stale_kernels
from ladartui.lazy import lazy_getattr

# Before numba loads: its TBB layer where installed, else a short OpenMP spin.
threads.configure()
# Before a kernel loads from the cache: none compiled from sources since changed.
clear_stale_kernels(__path__[0])

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
    "load_scenario": "ladartui.user_data",  # also takes a bundled name
    "trace": "ladartui.tracing",
    "simulate": "ladartui.simulation",
    "compute_measures": "ladartui.measures",
    "TraceResult": "ladartui.tracing",
    "SimulationResult": "ladartui.simulation",
}

__all__ = sorted(_EXPORTS) + ["__version__"]


__getattr__ = lazy_getattr("ladartui", _EXPORTS, globals())
