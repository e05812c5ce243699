"""The shared Pareto front: the sorted two-objective path against a pairwise check."""

import math
import random

import pytest

from ladartui.pareto import dominator, pareto_front


def _brute_force(points):
    def ok(p):
        return p is not None and all(v is not None and not math.isnan(v) for v in p)

    def beats(q, p):
        return all(a <= b for a, b in zip(q, p)) and q != p

    return [ok(p) and not any(ok(q) and beats(q, p) for q in points) for p in points]


def test_two_and_three_objective_fronts_match_a_pairwise_check_with_ties_and_gaps():
    rng = random.Random(11)
    gaps = [None, (float("nan"), 1.0), (1.0, None)]
    for k in (2, 3):
        for _ in range(300):
            points = [tuple(float(rng.randint(0, 4)) for _ in range(k)) for _ in range(rng.randint(0, 15))]
            points += rng.sample(gaps, rng.randint(0, 3))
            rng.shuffle(points)
            assert pareto_front(points, ("min",) * k) == _brute_force(points)


def test_identical_points_share_the_front_under_both_orientations():
    assert pareto_front([(2, 2), (2, 2), (3, 3)], ("min", "min")) == [True, True, False]
    # Sweeps maximise coverage: (cost 1, coverage 0.5) twice, both beat (1, 0.4).
    front = pareto_front([(1, 0.5), (1, 0.5), (1, 0.4), (1, float("nan"))], ("min", "max"))
    assert front == [True, True, False, False]


def test_the_sense_decides_the_front_and_must_be_stated():
    points = [(1, 1), (2, 2)]
    assert pareto_front(points, ("min", "min")) == [True, False]
    assert pareto_front(points, ("max", "max")) == [False, True]
    assert pareto_front(points, ("min", "max")) == [True, True]
    with pytest.raises(ValueError, match="'min' or 'max'"):
        pareto_front(points, ("least", "most"))
    with pytest.raises(ValueError, match="2 objectives against 3 senses"):
        pareto_front(points, ("min", "min", "min"))
    with pytest.raises(TypeError):
        pareto_front(points)  # type: ignore[call-arg]


def test_dominator_is_the_cheapest_front_point_that_dominates():
    points = [(1, 5), (2, 1), (3, 0.5), (4, 6), None]
    assert dominator(points, 3, ("min", "min")) == 0
    assert dominator(points, 4, ("min", "min")) is None and dominator(points, 1, ("min", "min")) is None
