"""Statistics of the Geiger-mode model against closed forms (fixed seeds, 3 sigma)."""

import math

import numpy as np
import pytest

from ladartui.detection import (
    binomial_at_least,
    declare_points,
    fire_counts,
    noise_per_bin,
    optimal_energy_scale,
    uniform,
)

PULSES = 4000


def _within_3_sigma(observed_share, p, trials):
    sigma = math.sqrt(p * (1 - p) / trials)
    assert abs(observed_share - p) <= 3 * sigma, (observed_share, p, sigma)


def test_single_surface_fires_with_one_minus_exp():
    n = 0.7
    mean = np.array([[0.0, n, 0.0]])
    counts = fire_counts(mean, PULSES, dead_bins=3, seed=11)
    _within_3_sigma(counts[0, 1] / PULSES, 1 - math.exp(-n), PULSES)
    assert counts[0, 0] == counts[0, 2] == 0


def test_near_surface_blocks_far_one():
    n1, n2 = 0.8, 1.5
    mean = np.array([[n1, 0.0, n2]])
    counts = fire_counts(mean, PULSES, dead_bins=3, seed=5)
    _within_3_sigma(counts[0, 2] / PULSES, math.exp(-n1) * (1 - math.exp(-n2)), PULSES)
    # With a dead time of one bin the detector re-arms: no blocking.
    rearmed = fire_counts(mean, PULSES, dead_bins=1, seed=5)
    _within_3_sigma(rearmed[0, 2] / PULSES, 1 - math.exp(-n2), PULSES)


def test_noise_only_gate_matches_poisson_expectation():
    bins = 200
    per_bin = noise_per_bin(1e5, 0.5)
    assert per_bin == pytest.approx(1e5 * 2 * 0.5 / 299_792_458.0)
    mean = np.full((50, bins), per_bin)
    counts = fire_counts(mean, 200, dead_bins=1, seed=3)
    # Re-arming after each bin: each bin fires independently, 1 - exp(-N) each.
    p = 1 - math.exp(-per_bin)
    trials = 50 * bins * 200
    _within_3_sigma(counts.sum() / trials, p, trials)


def test_coincidence_matches_binomial_sum():
    n, pulses, k = 0.3, 10, 4
    p = 1 - math.exp(-n)
    detectors = 5000
    counts = fire_counts(np.full((detectors, 1), n), pulses, dead_bins=1, seed=9)
    declared = declare_points(counts, k)[:, 0]
    expected = binomial_at_least(pulses, k, p)
    assert expected == pytest.approx(
        1 - sum(math.comb(pulses, j) * p**j * (1 - p) ** (pulses - j) for j in range(k))
    )
    _within_3_sigma(declared.mean(), expected, detectors)


def test_same_seed_same_result_and_detector_subsets_agree():
    rng = np.random.default_rng(0)
    mean = rng.uniform(0, 1, size=(64, 20))
    a = fire_counts(mean, 50, dead_bins=4, seed=42, scan=3)
    b = fire_counts(mean, 50, dead_bins=4, seed=42, scan=3)
    assert np.array_equal(a, b)
    # Chunking: half the detectors, keyed by their ids, give the same rows.
    ids = np.arange(32, 64)
    part = fire_counts(mean[32:], 50, dead_bins=4, seed=42, scan=3, detectors=ids)
    assert np.array_equal(part, a[32:])
    assert not np.array_equal(fire_counts(mean, 50, dead_bins=4, seed=43, scan=3), a)
    assert uniform(1, 2, 3, 4, 5) == uniform(1, 2, 3, 4, 5)
    assert 0 <= uniform(1, 2, 3, 4, 5) < 1


def test_pulses_fired_in_blocks_give_the_same_counts_and_a_cancel_stops_between_them(monkeypatch):
    """All pulses were fired in one kernel call: a Ctrl-C waited out 100,000 pulses of a
    look (20 s and more). Each pulse has its own random numbers, so blocks change nothing."""
    import threading

    from ladartui.detection import geiger
    from ladartui.errors import Cancelled

    mean = np.random.default_rng(2).uniform(0, 1, size=(16, 10))
    whole = fire_counts(mean, 37, dead_bins=3, seed=9, scan=1)
    monkeypatch.setattr(geiger, "FIRE_BLOCK_VISITS", 160 * 5)  # 5 pulses a block: 8 blocks
    calls = []
    real = geiger._fire_kernel
    monkeypatch.setattr(geiger, "_fire_kernel", lambda *a: calls.append(a[2:4]) or real(*a))
    assert np.array_equal(fire_counts(mean, 37, dead_bins=3, seed=9, scan=1), whole)
    assert calls == [(0, 5), (5, 10), (10, 15), (15, 20), (20, 25), (25, 30), (30, 35), (35, 37)]
    cancel = threading.Event()
    cancel.set()
    with pytest.raises(Cancelled):
        fire_counts(mean, 37, dead_bins=3, seed=9, scan=1, cancel=cancel)


def test_same_seed_identical_with_one_and_two_threads():
    import numba

    mean = np.random.default_rng(1).uniform(0, 1, size=(128, 16))
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = fire_counts(mean, 30, dead_bins=2, seed=7)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = fire_counts(mean, 30, dead_bins=2, seed=7)
    finally:
        numba.set_num_threads(before)
    assert np.array_equal(one, two)


@pytest.mark.parametrize("ratio", [0.1, 0.5, 1.0, 3.0])
def test_energy_sweep_finds_published_optimum(ratio):
    n_f = 1.0
    n_t = ratio * n_f
    scales = np.linspace(0.05, 4.0, 80)
    pulses = 3000
    mean = np.stack([np.array([a * n_f, a * n_t]) for a in scales])
    counts = fire_counts(mean, pulses, dead_bins=2, seed=21)
    target_share = counts[:, 1] / pulses
    a_star = optimal_energy_scale(n_t, n_f)
    assert a_star == pytest.approx(math.log(1 + n_t / n_f) / n_t)
    # The analytic curve is flat near its peak: the sampled best scale's
    # expected share must be within 3 sigma of the optimum's.
    best = scales[int(np.argmax(target_share))]
    peak = math.exp(-a_star * n_f) * (1 - math.exp(-a_star * n_t))
    at_best = math.exp(-best * n_f) * (1 - math.exp(-best * n_t))
    assert peak - at_best <= 3 * math.sqrt(peak * (1 - peak) / pulses) + 1e-12
    # Overall detection probability (anything fires) at the optimum: 65-84 %
    # in whole percent (64.95 % at N_t/N_f = 0.1, 84.25 % at 3).
    overall = 1 - math.exp(-a_star * (n_f + n_t))
    assert 65 <= round(overall * 100) <= 84
    i = int(np.argmin(abs(scales - a_star)))
    _within_3_sigma(counts[i].sum() / pulses, 1 - math.exp(-scales[i] * (n_f + n_t)), pulses)


def test_look_sums_ray_signal_into_bins_and_counts_false_alarms():
    from ladartui.detection.look import geiger_look

    # Detector 0: two rays on foliage at 100 m, two on the target at 103 m.
    # Detector 1: nothing but noise beyond its one ground ray.
    detector = np.array([0, 0, 0, 0, 1, 1, 1, 1])
    kind = np.array([1, 1, 1, 1, 2, 0, 0, 0])
    ranges = np.array([100.0, 100.2, 103.0, 103.4, 105.0, np.inf, np.inf, np.inf])
    refl = np.array([0.5, 0.5, 0.3, 0.3, 0.2, 0, 0, 0])
    look = geiger_look(
        detector,
        kind,
        ranges,
        refl,
        np.ones(8),
        rays_per_detector=4,
        n_ref=2.0,
        range_ref=100.0,
        reflectance_ref=0.5,
        noise=0.0,
        bin_width=1.0,
        pulses=200,
        threshold=1,
        dead_bins=6,
        seed=1,
        scan=0,
    )
    assert look.gate_start == 100.0 and look.mean_counts.shape == (2, 6)
    assert look.mean_counts[0, 0] == pytest.approx(2 * 0.5 * 1.0 * (100 / 100.2) ** 2 / 2 + 0.5)
    assert look.mean_counts[0, 3] == pytest.approx(2 * 0.25 * 0.6 * ((100 / 103) ** 2 + (100 / 103.4) ** 2))
    assert look.false_alarms == 0  # no noise, so only surfaces fire
    assert look.ray_declared[:5].all() and not look.ray_declared[5:].any()
    noisy = geiger_look(
        detector,
        kind,
        ranges,
        refl,
        np.ones(8),
        rays_per_detector=4,
        n_ref=2.0,
        range_ref=100.0,
        reflectance_ref=0.5,
        noise=0.05,
        bin_width=1.0,
        pulses=200,
        threshold=1,
        dead_bins=1,
        seed=1,
        scan=0,
    )
    assert noisy.false_alarms > 0
    strict = geiger_look(
        detector,
        kind,
        ranges,
        refl,
        np.ones(8),
        rays_per_detector=4,
        n_ref=2.0,
        range_ref=100.0,
        reflectance_ref=0.5,
        noise=0.05,
        bin_width=1.0,
        pulses=200,
        threshold=60,
        dead_bins=1,
        seed=1,
        scan=0,
    )
    assert strict.false_alarms == 0


def test_incidence_cosine_of_nadir_and_slanted_rays():
    from ladartui.detection.look import incidence_cosines

    d = np.array([[0, 0, -1.0], [np.sin(0.5), 0, -np.cos(0.5)]])
    o = np.array([[2.0, 2.0, 10.0], [2.0, 2.0, 10.0]])
    # Ray 0 (cell z 10.5) meets voxel (2, 2, 3)'s top face (cell z = 4) after 6.5 cells.
    cos = incidence_cosines(
        o, d, np.array([1, 2]), np.array([[2, 2, 3], [0, 0, 0]]), np.array([6.5, 10.5 / np.cos(0.5)]), 1.0
    )
    assert cos[0] == pytest.approx(1.0) and cos[1] == pytest.approx(np.cos(0.5))


def test_settings_and_cli_reject_bad_values(capsys):
    from ladartui.cli import main
    from ladartui.detection.settings import DetectionSettings
    from ladartui.errors import FieldError

    with pytest.raises(
        FieldError, match=r"detection.reflectance_target = 1.5: expected a number from 0 to 1"
    ):
        DetectionSettings(reflectance_target=1.5)
    # k keeps the share coincidence / pulses (10 of 100 by default), at least 1.
    settings = DetectionSettings()
    assert [settings.threshold(m) for m in (1, 10, 25, 100, 1000)] == [1, 1, 3, 10, 100]
    assert main(["pulses", "--pulses", "1,x"]) == 2
    assert "--pulses = '1,x': expected comma-separated whole numbers" in capsys.readouterr().err


@pytest.mark.parametrize(
    "pulses, k, a, b",
    [(10, 4, 3, 10), (40, 1, 1, 10**6), (2000, 1000, 1, 2), (3000, 40, 1, 100), (3000, 2, 1, 10**5)],
)
def test_binomial_tail_matches_exact_sums_past_a_thousand_pulses(pulses, k, a, b):
    """Above about 1,030 pulses C(M, j) no longer fits a float and the sum raised
    OverflowError, though [detection] pulses may be up to 100,000."""
    tail = sum(math.comb(pulses, j) * a**j * (b - a) ** (pulses - j) for j in range(k, pulses + 1))
    exact = tail / b**pulses  # int / int: correctly rounded
    assert binomial_at_least(pulses, k, a / b) == pytest.approx(exact, rel=1e-9)


def test_binomial_tail_at_the_largest_pulse_count_and_its_ends():
    # k at the mean M p: about a half (a normal tail, 0.5 within 0.2 %).
    assert binomial_at_least(100_000, 10_000, 0.1) == pytest.approx(0.5, abs=0.003)
    assert binomial_at_least(100_000, 1, 1e-9) == pytest.approx(-math.expm1(100_000 * math.log1p(-1e-9)))
    assert binomial_at_least(100_000, 50_000, 0.1) == 0.0  # below the smallest float
    assert binomial_at_least(2000, 1, 0.0) == 0.0
    assert binomial_at_least(2000, 2000, 1.0) == 1.0
    assert binomial_at_least(2000, 0, 0.3) == 1.0
    assert binomial_at_least(2000, 2001, 0.3) == 0.0


def test_incidence_cosine_takes_a_face_the_ray_can_enter():
    """The face was the plane nearest the hit point, so a range a float32 rounding long
    (1e-6 m) put a hit on the top face, close to its far x edge, on the x face the ray
    leaves by: cos |d_x| 0.29 for |d_z| 0.96."""
    from ladartui.detection.look import incidence_cosines

    d = np.array([0.3, 0.0, -1.0]) / np.hypot(0.3, 1.0)
    hit = np.array([1.0 - 1e-9, 0.5, 1.0])  # cell space: voxel (0, 0, 0)'s top face, at its +x edge
    origin = hit - 9.0 * d - 0.5  # metres (voxel size 1), 9 m before the hit
    for error in (0.0, 1e-6, -1e-6):
        cos = incidence_cosines(
            origin[None], d[None], np.array([1]), np.array([[0, 0, 0]]), np.array([9.0 + error]), 1.0
        )
        assert cos[0] == pytest.approx(abs(d[2])), error


@pytest.mark.parametrize(
    "call, message",
    [
        # no foliage: the optimum is no finite scale (was ZeroDivisionError)
        (lambda: optimal_energy_scale(5.0, 0.0), "n_foliage = 0.0: expected a number > 0"),
        # a target that never fires has no optimum (was ZeroDivisionError)
        (lambda: optimal_energy_scale(0.0, 5.0), "n_target = 0.0: expected a number > 0"),
        # was 0.223, a scale for a negative signal
        (lambda: optimal_energy_scale(-1.0, 5.0), "n_target = -1.0: expected a number > 0"),
        # was 1.0: a certain declaration from a probability that is not one
        (lambda: binomial_at_least(100, 10, math.nan), "p = nan: expected a number from 0 to 1"),
        (lambda: binomial_at_least(10, 3, 1.5), "p = 1.5: expected a number from 0 to 1"),
        # was a TypeError from range()
        (lambda: binomial_at_least(10.5, 3, 0.5), "pulses = 10.5: expected an integer from 0 to 100000"),
        # was -3.3e-09 mean counts
        (lambda: noise_per_bin(-1.0, 0.5), "rate_hz = -1.0: expected a number >= 0"),
        (lambda: noise_per_bin(1e6, 0.0), "bin_width_m = 0.0: expected a number > 0"),
    ],
)
def test_closed_forms_refuse_values_outside_their_meaning(call, message):
    from ladartui.errors import FieldError

    with pytest.raises(FieldError) as caught:
        call()
    assert str(caught.value).startswith(message)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: fire_counts(np.ones((1, 3)), 0, 1, 0), "pulses = 0: expected an integer from 1 to 100000"),
        (lambda: fire_counts(np.ones((1, 3)), 2.5, 1, 0), "pulses = 2.5: expected an integer from 1 to"),
        (lambda: fire_counts(np.ones((1, 3)), 1, 0, 0), "dead_bins = 0: expected an integer from 1 to"),
        (
            lambda: fire_counts(-np.ones((1, 3)), 1, 1, 0),
            "mean_counts is a (1, 3) array holding -1.0: expected finite mean counts >= 0",
        ),
        (
            lambda: fire_counts(np.ones(3), 1, 1, 0),
            "mean_counts is a (3,) array: expected a (detectors, bins) array",
        ),
        (lambda: declare_points(np.ones((1, 3)), 0), "threshold = 0: expected an integer from 1 to"),
    ],
)
def test_firing_refuses_bad_arguments_with_one_line_naming_them(call, message):
    """They raised ValueError ("pulses and dead_bins must be at least 1", naming neither),
    where the README says bad values given to the API raise a LadarError naming them."""
    from ladartui.errors import FieldError

    with pytest.raises(FieldError) as caught:
        call()
    assert str(caught.value).startswith(message)
