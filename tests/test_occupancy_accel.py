"""Optional accelerations of the occupancy: empty cubes per octant and 2x2x2 block masks,
checked against brute force on random scenes."""

import numpy as np
import pytest

from ladartui.scene.occupancy import CUBE_CAP, Occupancy


def brute_force_cubes(vox, origin, dims):
    """Per brick cell and downward octant: the largest k such that the k-brick cube from the
    cell along the octant holds no voxel, from the nearest full brick ahead."""
    full = np.unique(vox >> 3, axis=0) - origin
    dx, dy, dz = (int(v) for v in dims)
    out = np.zeros((dz, dy, dx, 4), np.int64)
    for z in range(dz):
        for y in range(dy):
            for x in range(dx):
                for o in range(4):
                    s = np.array([-1 if o & 1 else 1, -1 if o & 2 else 1, -1])
                    rel = (full - [x, y, z]) * s  # >= 0 on every axis: ahead of the cell
                    ahead = rel[np.all(rel >= 0, axis=1)]
                    k = ahead.max(axis=1).min() if len(ahead) else CUBE_CAP
                    out[z, y, x, o] = min(k, CUBE_CAP)
    return out.reshape(-1)


@pytest.mark.parametrize("seed", range(4))
def test_empty_cubes_equal_brute_force_on_random_scenes(seed):
    rng = np.random.default_rng(seed)
    shape = tuple(int(v) for v in rng.integers(40, 100, size=3))
    vox = rng.integers(0, shape, size=(int(rng.integers(1, 40)), 3))
    occ = Occupancy.build(vox, shape)
    origin = occ.bbox_lo >> 3
    dims = ((occ.bbox_hi - 1) >> 3) - origin + 1
    assert occ.cube_origin.tolist() == origin.tolist()
    assert occ.cube_dims.tolist() == dims.tolist()
    assert occ.cubes.dtype == np.uint8
    assert np.array_equal(occ.cubes.astype(np.int64), brute_force_cubes(vox, origin, dims))


def test_empty_cubes_are_capped_far_from_everything():
    # Full bricks at x = 0 and x = 511 only (a 512 x 1 x 1 brick box).
    occ = Occupancy.build(np.array([[0, 0, 0], [4095, 0, 0]]), (4096, 1, 1))
    cubes = occ.cubes.reshape(-1, 4).astype(int)
    assert cubes[1, 0] == CUBE_CAP  # 510 empty bricks ahead along +x: capped
    assert cubes[1, 1] == 1  # along -x the full brick 0 is next
    assert cubes[510, 0] == 1 and cubes[300, 1] == CUBE_CAP
    assert cubes[0].max() == 0 and cubes[511].max() == 0


def test_empty_scene_has_no_cubes():
    occ = Occupancy.build(np.zeros((0, 3), int), (10, 10, 10))
    assert len(occ.cubes) == 0 and occ.cube_dims.tolist() == [0, 0, 0]


def test_block_masks_mark_exactly_the_2x2x2_blocks_holding_voxels():
    rng = np.random.default_rng(31)
    shape = (90, 70, 60)
    vox = np.unique(rng.integers(0, shape, size=(2500, 3)), axis=0)
    occ = Occupancy.build(vox, shape)
    assert occ.blocks.dtype == np.uint64 and len(occ.blocks) == occ.n_bricks
    # Brick number of every voxel, by walking the documented hierarchy.
    rel = vox - occ.root_origin
    r = rel >> 9
    g = occ.root[r[:, 0] + occ.root_dims[0] * (r[:, 1] + occ.root_dims[1] * r[:, 2])].astype(int)

    def slot(shift):
        c = (rel >> shift) & 7
        return c[:, 0] + 8 * c[:, 1] + 64 * c[:, 2]

    tile = occ.regions[(g - 1) * 512 + slot(6)].astype(int)
    brick = occ.tiles[(tile - 1) * 512 + slot(3)].astype(int) - 1
    b = (rel & 7) >> 1
    expected = np.zeros(occ.n_bricks, np.uint64)
    for k, bit in zip(brick, b[:, 0] + 4 * b[:, 1] + 16 * b[:, 2]):
        expected[k] |= np.uint64(1) << np.uint64(bit)
    assert np.array_equal(occ.blocks, expected)
