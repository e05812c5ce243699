import math

import numpy as np
import pytest

from ladartui.attitude import attitude_matrix, body_fixed_directions, coordinated_turn_roll
from ladartui.errors import FieldError


def test_coordinated_turn_roll():
    # 30 m/s on a 60 m radius: tan(roll) = 900 / (9.80665 * 60).
    assert coordinated_turn_roll(30.0, 60.0) == pytest.approx(math.degrees(math.atan(900 / 588.399)))
    assert coordinated_turn_roll(0.0, 60.0) == 0.0


@pytest.mark.parametrize("heading", [0.0, 90.0, 217.0])
def test_body_fixed_roll_moves_nadir_footprint_by_h_tan_roll(heading):
    h = 100.0
    d = body_fixed_directions(np.array([[0.0, 0.0, -1.0]]), heading, roll=30.0)[0]
    ground = np.array([0.0, 0.0, h]) + d * (h / -d[2])
    shift = ground[:2]
    assert np.linalg.norm(shift) == pytest.approx(h * math.tan(math.radians(30)))
    # Right wing down turns the belly to the left of the track.
    hr = math.radians(heading)
    right = np.array([math.cos(hr), -math.sin(hr)])
    assert shift @ right == pytest.approx(-h * math.tan(math.radians(30)))


def test_zero_attitude_is_identity_and_rotation_is_orthonormal():
    d = np.random.default_rng(0).normal(size=(20, 3))
    assert np.allclose(body_fixed_directions(d, 123.0), d)
    m = attitude_matrix(10, -5, 20)
    assert np.allclose(m @ m.T, np.eye(3)) and np.linalg.det(m) == pytest.approx(1.0)
    # Pitch nose up: the belly, and a nadir ray, turn forward (along the heading).
    ahead = body_fixed_directions(np.array([[0.0, 0.0, -1.0]]), 0.0, pitch=10.0)[0]
    assert ahead[1] == pytest.approx(math.sin(math.radians(10))) and ahead[0] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize(
    "speed, radius, said",
    [
        # NaN came back as the bank; 0 and -60 raised a ValueError naming neither value.
        (float("nan"), 60.0, "speed = nan: expected a number >= 0"),
        (30.0, 0.0, "radius = 0.0: expected a number > 0"),
        (30.0, -60.0, "radius = -60.0: expected a number > 0"),
        ("30", 60.0, "speed = '30': expected a number >= 0"),
    ],
)
def test_a_coordinated_turn_s_speed_and_radius_are_checked_and_named(speed, radius, said):
    with pytest.raises(FieldError) as caught:
        coordinated_turn_roll(speed, radius)
    assert str(caught.value).startswith(said)


@pytest.mark.parametrize(
    "directions, angles, said",
    [
        # numpy's matmul complained of its gufunc signature.
        (
            np.array([1.0, 2.0]),
            {},
            "directions is an array of shape (2,): expected an (N, 3) array of numbers",
        ),
        (None, {}, "directions is not set: expected an (N, 3) array of numbers"),
        # NaN directions came back for a NaN angle.
        (np.array([[0.0, 0.0, -1.0]]), {"roll": float("nan")}, "roll = nan: expected a finite number"),
        (np.array([[0.0, 0.0, -1.0]]), {"heading": None}, "heading is not set: expected a finite number"),
    ],
)
def test_body_fixed_directions_name_a_bad_argument(directions, angles, said):
    arguments = {"heading": 0.0, **angles}
    with pytest.raises(FieldError) as caught:
        body_fixed_directions(directions, **arguments)
    assert str(caught.value).startswith(said)
