"""Optional detection models applied after tracing (off by default).

``geiger``: Geiger-mode avalanche photodiode statistics per detector and pulse
(see docs/detection.md). The numba kernels load on first use, so that reading
a scenario's ``[detection]`` section (``detection.settings``) stays quick.
"""

_GEIGER = (
    "binomial_at_least",
    "declare_points",
    "fire_counts",
    "noise_per_bin",
    "optimal_energy_scale",
    "uniform",
)

__all__ = list(_GEIGER)


def __getattr__(name):
    if name in _GEIGER:
        from ladartui.detection import geiger

        return getattr(geiger, name)
    raise AttributeError(f"module 'ladartui.detection' has no attribute {name!r}")
