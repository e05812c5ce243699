"""Measures a Geiger-mode run adds (only when ``[detection] model = "geiger"``).

Per run of the full scene (the obscured view):

- ``declared_points``: declared range bins over all looks, returns and noise
  (``declared_per_look`` its mean per look);
- ``false_alarms``: declared bins that hold no return (``false_alarms_per_look``;
  ``false_alarm_probability`` per noise-only bin: false alarms / such bins);
- ``target_detection``: probability of detection of target voxels: of the
  distinct target voxels the ideal sensor returns in each look, summed over
  looks, the share the Geiger model declares;
- ``ideal_obscured_coverage`` and ``ideal_unobscured_coverage``: the ideal
  model's coverages on the same rays, for comparison with the measures'
  coverages, which count declared points only.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ladartui.scene.keys import voxel_keys

# (.cmf key, attribute, kind) in the [geiger detection] section.
CMF_SECTION = "geiger detection"
CMF_ENTRIES = [
    ("pulses_per_look", "pulses", "int"),
    ("coincidence_k", "coincidence", "int"),
    ("seed", "seed", "int"),
    ("declared_points", "declared_points", "int"),
    ("declared_per_look", "declared_per_look", "float"),
    ("false_alarms", "false_alarms", "int"),
    ("false_alarms_per_look", "false_alarms_per_look", "float"),
    ("false_alarm_probability_per_bin", "false_alarm_probability", "float"),
    ("target_detection_probability", "target_detection", "float"),
    ("ideal_obscured_coverage", "ideal_obscured_coverage", "float"),
    ("ideal_unobscured_coverage", "ideal_unobscured_coverage", "float"),
]


@dataclass(frozen=True)
class DetectionMeasures:
    pulses: int | None = None
    coincidence: int | None = None
    seed: int | None = None
    declared_points: int | None = None
    declared_per_look: float | None = None
    false_alarms: int | None = None
    false_alarms_per_look: float | None = None
    false_alarm_probability: float | None = None
    target_detection: float | None = None
    ideal_obscured_coverage: float | None = None
    ideal_unobscured_coverage: float | None = None

    def to_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}


class DetectionTally:
    """Adds up the looks of one run (``LookOutcome``s, in any order)."""

    def __init__(self):
        self.looks = 0
        self.declared = 0
        self.false_alarms = 0
        self.noise_bins = 0
        self.target_ideal = 0
        self.target_declared = 0

    def add(self, outcome) -> None:
        self.looks += 1
        self.declared += outcome.declared_points
        self.false_alarms += outcome.false_alarms
        self.noise_bins += outcome.noise_bins
        self.target_ideal += outcome.target_ideal
        self.target_declared += outcome.target_declared

    def measures(self, settings, ideal_obscured, ideal_unobscured) -> DetectionMeasures:
        looks = self.looks or None
        return DetectionMeasures(
            pulses=settings.pulses,
            coincidence=settings.coincidence,
            seed=settings.seed,
            declared_points=self.declared,
            declared_per_look=self.declared / looks if looks else None,
            false_alarms=self.false_alarms,
            false_alarms_per_look=self.false_alarms / looks if looks else None,
            false_alarm_probability=(self.false_alarms / self.noise_bins if self.noise_bins else None),
            target_detection=(self.target_declared / self.target_ideal if self.target_ideal else None),
            ideal_obscured_coverage=ideal_obscured,
            ideal_unobscured_coverage=ideal_unobscured,
        )


def coverage(target_model, voxels) -> float | None:
    """Share of the distinct target-model voxels among ``voxels``."""
    target = np.unique(voxel_keys(np.asarray(target_model).reshape(-1, 3)))
    if not target.size:
        return None
    seen = voxel_keys(np.asarray(voxels).reshape(-1, 3))
    return float(np.isin(target, seen).sum() / target.size)
