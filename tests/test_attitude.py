import math

import numpy as np
import pytest

from ladartui.attitude import attitude_matrix, body_fixed_directions, coordinated_turn_roll


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
