"""The ``[detection]`` scenario section: which detection model, and its numbers.

Absent, or ``model = "ideal"``: the report's ideal sensor, byte for byte.
``model = "geiger"``: Geiger-mode statistics after tracing (docs/detection.md)::

    [detection]
    model = "geiger"            # "ideal" (default) or "geiger"
    n_ref = 5.0                 # mean photoelectrons of a full-footprint return at range_ref_m
    range_ref_m = 85.0          # reference range, metres
    reflectance_ref = 0.5       # reflectance of that reference return
    reflectance_foliage = 0.5   # per class, 0..1
    reflectance_ground = 0.2
    reflectance_target = 0.3
    dark_rate_hz = 1e4          # detector dark counts
    solar_rate_hz = 1e6         # solar background counts
    bin_width_m = 0.5           # range bin; default: the sensor's depth resolution
    dead_time_m = 3.0           # range equivalent; default: longer than the gate
    pulses = 100                # pulses per look
    coincidence = 10            # k: a point is declared where >= k pulses fired
    seed = 0                    # the random stream; same seed, same answer

Every key may be left out (its default). Errors name the key, the value and
the allowed range (``FieldError``; the scenario reader adds file and line).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ladartui.checks import choice_field, integer_field, number_field
from ladartui.errors import FieldError
from ladartui.number_text import plural

MODELS = ("ideal", "geiger")
MAX_PULSES = 100_000
MAX_RATE_HZ = 1e10
MAX_PHOTOELECTRONS = 1e6
MAX_RANGE_M = 1e6
MAX_SEED = 2**63 - 1


@dataclass(frozen=True)
class DetectionSettings:
    """The detection model and its parameters (see the module docstring for units)."""

    model: str = "ideal"
    n_ref: float = 5.0
    range_ref_m: float = 85.0
    reflectance_ref: float = 0.5
    reflectance_foliage: float = 0.5
    reflectance_ground: float = 0.2
    reflectance_target: float = 0.3
    dark_rate_hz: float = 1e4
    solar_rate_hz: float = 1e6
    bin_width_m: float | None = None
    dead_time_m: float | None = None
    pulses: int = 100
    coincidence: int = 10
    seed: int = 0

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "model", choice_field("detection.model", self.model, MODELS))
        set_(
            self, "n_ref", number_field("detection.n_ref", self.n_ref, 0.0, MAX_PHOTOELECTRONS, low_open=True)
        )
        set_(
            self,
            "range_ref_m",
            number_field("detection.range_ref_m", self.range_ref_m, 0.0, MAX_RANGE_M, low_open=True),
        )
        set_(
            self,
            "reflectance_ref",
            number_field("detection.reflectance_ref", self.reflectance_ref, 0.0, 1.0, low_open=True),
        )
        for name in ("reflectance_foliage", "reflectance_ground", "reflectance_target"):
            set_(self, name, number_field(f"detection.{name}", getattr(self, name), 0.0, 1.0))
        for name in ("dark_rate_hz", "solar_rate_hz"):
            set_(self, name, number_field(f"detection.{name}", getattr(self, name), 0.0, MAX_RATE_HZ))
        if self.bin_width_m is not None:
            set_(
                self,
                "bin_width_m",
                number_field("detection.bin_width_m", self.bin_width_m, 0.0, 1000.0, low_open=True),
            )
        if self.dead_time_m is not None:
            set_(
                self,
                "dead_time_m",
                number_field("detection.dead_time_m", self.dead_time_m, 0.0, MAX_RANGE_M, low_open=True),
            )
        set_(self, "pulses", integer_field("detection.pulses", self.pulses, 1, MAX_PULSES))
        set_(self, "coincidence", integer_field("detection.coincidence", self.coincidence, 1, self.pulses))
        set_(self, "seed", integer_field("detection.seed", self.seed, 0, MAX_SEED))

    @property
    def geiger(self) -> bool:
        return self.model == "geiger"

    @property
    def noise_rate_hz(self) -> float:
        return self.dark_rate_hz + self.solar_rate_hz

    def bin_width(self, depth_resolution: float) -> float:
        """Range bin width in metres: the set one, else the sensor's depth resolution."""
        width = depth_resolution if self.bin_width_m is None else self.bin_width_m
        if not width > 0:
            raise FieldError(
                "detection.bin_width_m",
                self.bin_width_m,
                "a number > 0 (needed when sensor.depth_resolution_m is 0)",
            )
        return width

    def dead_bins(self, bin_width: float) -> int:
        """Bins the detector stays blind after firing (a huge number: one fire per pulse)."""
        if self.dead_time_m is None:
            return 1_000_000
        return max(1, min(1_000_000, math.ceil(self.dead_time_m / bin_width - 1e-9)))

    def threshold(self, pulses: int) -> int:
        """Coincidence k for ``pulses`` pulses: ``coincidence`` scaled from ``self.pulses``.

        At ``self.pulses`` it is ``coincidence`` itself; a sweep over pulse
        counts keeps the share k / M (at least 1).
        """
        if pulses == self.pulses:
            return self.coincidence
        return max(1, math.ceil(self.coincidence * pulses / self.pulses - 1e-12))

    def to_dict(self) -> dict:
        """The TOML section (keys left unset, None, are not written)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) is not None}

    def describe(self) -> str:
        """One line for scenario summaries."""
        if not self.geiger:
            return "ideal (every return that survives the depth rule)"
        dead = "one fire per pulse" if self.dead_time_m is None else f"dead time {self.dead_time_m:g} m"
        width = "depth resolution" if self.bin_width_m is None else f"{self.bin_width_m:g} m"
        return (
            f"geiger, {plural(self.pulses, 'pulse')}, k = {self.coincidence}, N_ref {self.n_ref:g} "
            f"at {self.range_ref_m:g} m, noise {self.noise_rate_hz:g} Hz, bins {width}, "
            f"{dead}, seed {self.seed}"
        )


DETECTION_KEYS = tuple(f.name for f in fields(DetectionSettings))


def detection_from_table(table: dict) -> DetectionSettings:
    """A ``[detection]`` table (keys already checked against DETECTION_KEYS) as settings.
    Errors name a key the table holds: ``pulses = 4`` alone, under the default
    coincidence of 10, is the pulses' error, not the coincidence's, which it lacks."""
    try:
        return DetectionSettings(**table)
    except FieldError as error:
        if error.field != "detection.coincidence" or "coincidence" in table or "pulses" not in table:
            raise
        raise FieldError(
            "detection.pulses",
            table["pulses"],
            f"at least detection.coincidence ({error.value}, its default: set it too; "
            "k of the pulses must fire to declare a point)",
        ) from None
