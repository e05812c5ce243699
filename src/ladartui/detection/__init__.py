"""Optional detection models applied after tracing (off by default).

``geiger``: Geiger-mode avalanche photodiode statistics per detector and pulse
(see docs/detection.md).
"""

from ladartui.detection.geiger import (
    binomial_at_least,
    declare_points,
    fire_counts,
    noise_per_bin,
    optimal_energy_scale,
    uniform,
)

__all__ = ["binomial_at_least", "declare_points", "fire_counts", "noise_per_bin",
           "optimal_energy_scale", "uniform"]
