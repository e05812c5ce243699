"""A unit voxel's rectangle of bins from its centre (object_order.voxel_bins) holds
every point of its grown cube, as the eight corners' rectangle (box_bins) does."""

import numpy as np
import pytest

from ladartui.tracing import object_order as oo


def random_frame(rng):
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    u = np.cross(axis, rng.normal(size=3))
    u /= np.linalg.norm(u)
    return axis, u, np.cross(axis, u)


@pytest.mark.parametrize("seed", range(4))
def test_the_rectangle_holds_every_point_of_the_grown_cube_and_near_is_below_them(seed):
    rng = np.random.default_rng(seed)
    nb = 64
    for _ in range(300):
        axis, u, v = random_frame(rng)
        grow = rng.choice([0.0, 1e-12, 0.3, 1.0]) * rng.random(3)
        centre = rng.uniform(-50, 50, 3)
        depth = rng.choice([3.0, 40.0, 2000.0])
        spot = centre + depth * axis + rng.normal(size=3) * depth * 0.05
        x0, y0, z0 = (float(c) for c in np.floor(spot))
        # bins 0.2 tangent units wide... down to 1e-4 (about the peer scan's), slack half a bin
        step = rng.choice([0.2, 0.01, 1e-4])
        grid = np.array([-nb / 2 * step, step, -nb / 2 * step, step, 0.5, 0.5])
        i0, i1, j0, j1, state, near = oo.voxel_bins(x0, y0, z0, centre, grow, axis, u, v, grid, nb)
        if state != 1:
            continue
        h = 0.5 + grow
        points = np.array([x0, y0, z0]) + 0.5 + rng.uniform(-1, 1, (200, 3)) * h
        corners = np.array([x0, y0, z0]) + 0.5 + np.array(np.meshgrid(*[[-1, 1]] * 3)).reshape(3, -1).T * h
        points = np.vstack([points, corners]) - centre
        w = points @ axis
        assert np.all(w > 0) and near <= w.min()
        p, q = (points @ u) / w, (points @ v) / w
        i = np.clip(np.floor((p - grid[0]) / step), -1, nb).astype(int)
        j = np.clip(np.floor((q - grid[2]) / step), -1, nb).astype(int)
        inside = (i >= 0) & (i < nb) & (j >= 0) & (j < nb)
        assert np.all((i0 <= i[inside]) & (i[inside] <= i1) & (j0 <= j[inside]) & (j[inside] <= j1))
        # It holds the corners' rectangle, and at airborne ranges (the bound is looser
        # by about the cube's depth over its range) is at most one bin wider a side.
        b = oo.box_bins(x0, y0, z0, 1, centre, grow, axis, u, v, grid, nb)
        assert b[4] == 1 and abs(near - b[5]) <= 1e-9 * (1 + abs(near))
        if b[0] <= b[1]:
            assert i0 <= b[0] and b[1] <= i1 and j0 <= b[2] and b[3] <= j1
            if depth >= 2000:
                assert b[0] <= i0 + 1 and i1 - 1 <= b[1] and b[2] <= j0 + 1 and j1 - 1 <= b[3]


def test_a_cube_reaching_the_centres_plane_is_left_to_box_bins():
    axis, u, v = np.array([0.0, 0.0, -1.0]), np.array([1.0, 0.0, 0.0]), np.array([0.0, -1.0, 0.0])
    grow, grid = np.zeros(3), np.array([-1.0, 0.1, -1.0, 0.1, 0.5, 0.5])
    # across the plane, behind it, and touching it with its top face
    for centre_z, z in ((10.3, 10.0), (10.3, 12.0), (10.0, 9.0)):
        centre = np.array([5.2, 5.2, centre_z])
        got = oo.voxel_bins(5.0, 5.0, z, centre, grow, axis, u, v, grid, 20)
        assert got == oo.box_bins(5.0, 5.0, z, 1, centre, grow, axis, u, v, grid, 20)
