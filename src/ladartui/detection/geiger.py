"""Geiger-mode detection: per detector, per pulse, bins fire in range order.

Model (Fouche, Applied Optics 42(27), 2003; O'Brien and Fouche, Lincoln
Laboratory Journal 15(1), 2005):

- Each range bin ``b`` of a detector has a mean primary count ``N_b`` (signal
  photoelectrons of the surfaces in it plus noise). Counts are Poisson, so the
  bin fires, if the detector is armed, with probability ``1 - exp(-N_b)``.
- After firing the detector is blind for its dead time (``dead_bins`` bins,
  the firing bin included). ``dead_bins >= bins`` is the classic one-fire
  per pulse regime: an early strong return blocks everything behind it, and
  the far surface of two fires with ``exp(-N_1) (1 - exp(-N_2))``. A shorter
  dead time re-arms the detector inside the gate (Gatt, Johnson and Nichols,
  Applied Optics 48(17), 2009).
- Noise: dark count rate plus solar background rate ``r`` (Hz) gives
  ``r * 2 * bin_width / c`` mean counts per bin.
- Coincidence processing over ``M`` pulses: a point is declared in a bin that
  fired at least ``k`` times; per bin that count is binomial, so
  ``P = sum_{j>=k} C(M, j) p^j (1 - p)^(M - j)`` (``binomial_at_least``).

Random numbers: a counter-based hash (SplitMix64 finaliser) of (seed, scan,
detector, pulse, bin), so results do not depend on threads, chunks or backend.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ladartui.checks import integer_field, number_field
from ladartui.detection.settings import MAX_PULSES
from ladartui.errors import Described, FieldError, check_cancelled

SPEED_OF_LIGHT = 299_792_458.0
_MASK = (1 << 64) - 1
# The longest dead time in bins (an int32 in the kernel's arithmetic).
MAX_DEAD_BINS = 2**31 - 1


@numba.njit(cache=True, nogil=True)
def _mix(z):
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@numba.njit(cache=True, nogil=True)
def _uniform(seed, scan, detector, pulse, bin_):
    golden = np.uint64(0x9E3779B97F4A7C15)
    z = _mix(np.uint64(seed) + golden)
    z = _mix(z ^ (np.uint64(scan) + golden))
    z = _mix(z ^ (np.uint64(detector) + golden))
    z = _mix(z ^ (np.uint64(pulse) + golden))
    z = _mix(z ^ (np.uint64(bin_) + golden))
    return float(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


def uniform(seed: int, scan: int, detector: int, pulse: int, bin_: int) -> float:
    """The generator's uniform in [0, 1) for one (seed, scan, detector, pulse, bin)."""
    return float(
        _uniform(
            np.uint64(seed & _MASK), np.uint64(scan), np.uint64(detector), np.uint64(pulse), np.uint64(bin_)
        )
    )


@numba.njit(cache=True, nogil=True, parallel=True)
def _fire_kernel(fire_prob, detectors, first_pulse, end_pulse, dead_bins, seed, scan, counts):
    """Add the fires of pulses ``first_pulse`` to ``end_pulse`` (exclusive) to ``counts``."""
    n_det, n_bins = fire_prob.shape
    for d in numba.prange(n_det):
        det_id = detectors[d]
        for p in range(first_pulse, end_pulse):
            armed_at = 0
            for b in range(n_bins):
                if b < armed_at:
                    continue
                q = fire_prob[d, b]
                if q <= 0.0:
                    continue
                if _uniform(seed, scan, det_id, p, b) < q:
                    counts[d, b] += 1
                    armed_at = b + dead_bins


# Bin visits (detectors x bins x pulses) between two cancel checks: well under a
# second of firing, so a cancel is answered promptly whatever the pulse count.
FIRE_BLOCK_VISITS = 1 << 25


def fire_counts(
    mean_counts, pulses: int, dead_bins: int, seed: int, scan: int = 0, detectors=None, cancel=None
) -> np.ndarray:
    """Times each bin fired over ``pulses`` pulses.

    ``mean_counts``: (D, B) mean primary counts per detector and range bin
    (signal plus noise), bins in range order. ``detectors``: (D,) detector ids
    keying the generator (default 0..D-1), so a subset of detectors gives the
    same answers as the whole array. Returns (D, B) int32. The pulses are fired
    in blocks, ``cancel`` (a threading.Event) checked between them: each pulse
    has its own random numbers, so blocks never change an answer.
    """
    mean = np.ascontiguousarray(mean_counts, dtype=np.float64)
    if mean.ndim != 2:
        raise FieldError("mean_counts", Described(f"a {mean.shape} array"), "a (detectors, bins) array")
    pulses = integer_field("pulses", pulses, 1, MAX_PULSES)
    dead_bins = integer_field("dead_bins", dead_bins, 1, MAX_DEAD_BINS)
    bad = ~np.isfinite(mean) | (mean < 0)
    if bad.any():
        raise FieldError(
            "mean_counts",
            Described(f"a {mean.shape} array holding {float(mean[bad][0])!r}"),
            "finite mean counts >= 0",
        )
    ids = (
        np.arange(mean.shape[0], dtype=np.uint64)
        if detectors is None
        else np.ascontiguousarray(detectors, dtype=np.uint64)
    )
    counts = np.zeros(mean.shape, dtype=np.int32)
    fire_prob = -np.expm1(-mean)
    block = max(1, FIRE_BLOCK_VISITS // max(mean.size, 1))
    for first in range(0, pulses, block):
        check_cancelled(cancel, "cancelled while firing pulses")
        end = min(pulses, first + block)
        _fire_kernel(fire_prob, ids, first, end, dead_bins, np.uint64(seed & _MASK), np.uint64(scan), counts)
    return counts


def declare_points(counts, threshold: int) -> np.ndarray:
    """Coincidence processing: True where a bin fired at least ``threshold`` times."""
    threshold = integer_field("threshold", threshold, 1, MAX_PULSES)
    return np.asarray(counts) >= threshold


def noise_per_bin(rate_hz: float, bin_width_m: float) -> float:
    """Mean noise counts in one range bin: rate times the bin's round-trip time."""
    rate_hz = number_field("rate_hz", rate_hz, 0.0)
    bin_width_m = number_field("bin_width_m", bin_width_m, 0.0, low_open=True)
    return rate_hz * 2.0 * bin_width_m / SPEED_OF_LIGHT


def binomial_at_least(pulses: int, threshold: int, p: float) -> float:
    """P(at least ``threshold`` of ``pulses`` Bernoulli(p) trials succeed).

    Each term ``C(M, j) p^j (1 - p)^(M - j)`` is taken through its logarithm:
    past about 1,030 pulses ``C(M, j)`` alone is beyond the largest float. A
    value outside its meaning (``p`` not a probability, a count not a whole number
    of at most ``MAX_PULSES``) is a ``FieldError`` naming it.
    """
    pulses = integer_field("pulses", pulses, 0, MAX_PULSES)
    threshold = integer_field("threshold", threshold, 0, MAX_PULSES + 1)
    p = number_field("p", p, 0.0, 1.0)
    if threshold <= 0:
        return 1.0
    if threshold > pulses or p <= 0.0:
        return 0.0
    if p >= 1.0:
        return 1.0
    log_p, log_q = math.log(p), math.log1p(-p)
    log_whole = math.lgamma(pulses + 1)
    terms = [
        math.exp(
            log_whole - math.lgamma(j + 1) - math.lgamma(pulses - j + 1) + j * log_p + (pulses - j) * log_q
        )
        for j in range(threshold, pulses + 1)
    ]
    return min(1.0, math.fsum(terms))


def optimal_energy_scale(n_target: float, n_foliage: float) -> float:
    """Energy scale ``a`` maximising ``exp(-a N_f) (1 - exp(-a N_t))``.

    Setting the derivative to zero gives ``a* = ln(1 + N_t / N_f) / N_t``. Both
    counts must be above 0: without foliage no finite scale is best, and a target
    that never fires has no optimum (``FieldError`` naming the count).
    """
    n_target = number_field("n_target", n_target, 0.0, low_open=True)
    n_foliage = number_field("n_foliage", n_foliage, 0.0, low_open=True)
    return math.log1p(n_target / n_foliage) / n_target
