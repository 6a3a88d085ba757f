"""Voxel grids (engine.volume_grid, engine.kernels.voxel_grid): the compiled lookup
against the NumPy twin and against the grid's own voxels, Cycles 5's stochastic
interpolation, the TEX_GRID program operation, and the majorant's peak voxels.

- The kernel's trilinear lookup equals VoxelGrid.lookup (float64 on the same float32
  voxels, the same products: within 1e-12 of the values' scale) at points inside,
  at the edges and outside a rotated, sheared, offset grid, at scales 1e-3 and 1e4.
- At a voxel's centre (its index through the grid's transform) the lookup returns the
  voxel's value (OpenVDB's convention, which Cycles 5 keeps); outside the block's
  support, or at a non-finite point, 0.
- Stochastic: every lookup returns one of the eight surrounding voxels' values, and the
  mean over many points equals the trilinear mean within 4 standard errors; the
  control (always the lower corner) does not.
- A program reading a grid through TEX_GRID gives the grid's value (a vector grid's
  average for Fac, its channels for Color), and a shading tuple without grids packs
  no voxels (the cost of the feature to every other scene: two empty arrays).
- grid_peaks finds the world-space centre of a grid's one hot voxel, which jittered
  samples of its box miss.
"""
from __future__ import annotations

import numpy as np
import pytest

from engine.kernels.voxel_grid import grid_sample
from engine.nodes.context import H_OBJECT, hit_rows
from engine.nodes.program import ProgramBuilder
from engine.nodes.interpreter import evaluate_registers
from engine.nodes.texture_nodes import TEX_GRID
from engine.volume_grid import VoxelGrid, pack_grids


def _rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def _grid(rng, scale=1.0, shape=(7, 5, 9), channels=1):
    values = rng.uniform(0.0, 2.0, size=shape + ((3,) if channels == 3 else ()))
    index_to_object = np.eye(4)
    shear = np.eye(3)
    shear[0, 1] = 0.3
    index_to_object[:3, :3] = _rotation(rng) @ shear * (0.1 * scale)
    index_to_object[:3, 3] = rng.normal(size=3) * scale
    return VoxelGrid("density", values.astype(np.float32), (3, -2, 5),
                     np.linalg.inv(index_to_object)), index_to_object


def _kernel_lookup(grid, pts, stochastic=False, channel=0):
    voxels, rows = pack_grids([grid])
    return np.array([grid_sample(voxels, rows, 0, p[0], p[1], p[2], channel, stochastic)
                     for p in pts])


def _object_points(index_to_object, ijk):
    return ijk @ index_to_object[:3, :3].T + index_to_object[:3, 3]


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e4])
def test_kernel_equals_numpy_twin_inside_and_outside(scale):
    rng = np.random.default_rng(7)
    grid, i2o = _grid(rng, scale)
    n = np.array(grid.values.shape[:3])
    ijk = rng.uniform(-2.0, n + 1.0, size=(2000, 3)) + np.array(grid.origin)
    pts = _object_points(i2o, ijk)
    want = grid.lookup(pts)[:, 0]
    got = _kernel_lookup(grid, pts)
    assert np.abs(got - want).max() <= 1e-12 * 2.0 * 8
    inside = ((ijk - grid.origin > 0) & (ijk - grid.origin < n - 1)).all(axis=1)
    assert (want[inside] > 0).all() and (want[~inside] >= 0).all()
    assert (got[((ijk - grid.origin) <= -1).any(axis=1)] == 0).all()


def test_voxel_centres_read_their_own_values_and_nothing_is_read_outside():
    rng = np.random.default_rng(3)
    grid, i2o = _grid(rng)
    n = grid.values.shape[:3]
    ijk = np.stack(np.meshgrid(*(np.arange(k) for k in n), indexing="ij"), -1).reshape(-1, 3)
    pts = _object_points(i2o, ijk + np.array(grid.origin, np.float64))
    got = _kernel_lookup(grid, pts)
    np.testing.assert_allclose(got, grid.values[..., 0].reshape(-1), rtol=1e-9, atol=1e-9)
    # a voxel's centre shifted by half a voxel (Cycles 4's cell-centred convention) is
    # not its value: the control
    shifted = _kernel_lookup(grid, _object_points(i2o, ijk + np.array(grid.origin) + 0.5))
    assert np.abs(shifted - grid.values[..., 0].reshape(-1)).max() > 0.1
    far = _object_points(i2o, np.array([[-1.001, 0, 0], [0, 0, n[2] + 0.001]]) + grid.origin)
    assert (_kernel_lookup(grid, far) == 0).all()
    assert _kernel_lookup(grid, np.array([[np.nan, 0.0, 0.0], [np.inf, 1.0, 1.0]])).tolist() \
        == [0.0, 0.0]
    lo, hi = grid.bounds()
    inside = rng.uniform(lo, hi, size=(500, 3))
    outside = inside + (hi - lo) * 1.01
    assert (_kernel_lookup(grid, outside) == 0).all()


def test_stochastic_lookup_is_one_voxel_and_trilinear_on_average():
    rng = np.random.default_rng(11)
    grid, i2o = _grid(rng, shape=(4, 4, 4))
    ijk = rng.uniform(0.0, 3.0, size=(20000, 3)) + np.array(grid.origin)
    pts = _object_points(i2o, ijk)
    got = _kernel_lookup(grid, pts, stochastic=True)
    base = np.floor(ijk - grid.origin).astype(int)
    corners = np.stack([grid.values[base[:, 0] + (c >> 2 & 1), base[:, 1] + (c >> 1 & 1),
                                    base[:, 2] + (c & 1), 0] for c in range(8)], 1)
    assert np.isclose(got[:, None], corners, rtol=0, atol=1e-6).any(axis=1).all()
    trilinear = grid.lookup(pts)[:, 0]
    err = 4.0 * np.std(got - trilinear) / np.sqrt(len(got))
    assert abs(got.mean() - trilinear.mean()) < err
    lower = corners[:, 0]                   # the control: always the lower corner
    assert abs(lower.mean() - trilinear.mean()) > err


def test_vector_grids_and_the_program_operation():
    rng = np.random.default_rng(5)
    grid, i2o = _grid(rng, channels=3)
    pts = _object_points(i2o, rng.uniform(0.5, 3.5, size=(50, 3)) + grid.origin)
    b = ProgramBuilder()
    from engine.nodes.input_nodes import IN_HIT3
    co = b.emit(IN_HIT3, "vector", [H_OBJECT], varying=True)
    fac = b.emit(TEX_GRID, "float", [co, 0, 0], grid=grid)
    color = b.emit(TEX_GRID, "color", [co, 1, 0], grid=grid)
    program = b.build()
    hits = hit_rows(pts, np.tile([0.0, 0.0, 1.0], (len(pts), 1)))
    hits[:, H_OBJECT:H_OBJECT + 3] = pts         # the identity object
    regs = evaluate_registers(program, hits)
    want = grid.lookup(pts)
    np.testing.assert_allclose(regs[:, color.reg:color.reg + 3], want, atol=1e-12)
    np.testing.assert_allclose(regs[:, fac.reg], want.mean(axis=1), atol=1e-12)


def test_scenes_without_grids_pack_no_voxels():
    from engine.bsdf.material_table import MaterialTable
    from engine.nodes.pack import GRIDS, VOXELS
    from engine.scene import Material
    T = MaterialTable([Material("plain")]).shading()
    assert T[VOXELS].size == 0 and T[GRIDS].shape[0] == 0


def test_grid_peaks_find_the_one_hot_voxel():
    from engine.kernels.majorant_bounds import grid_peaks
    from engine.nodes.context import O_TO_WORLD, N_OBJ
    from engine.nodes.pack import pack_programs
    values = np.zeros((40, 40, 40), np.float32)
    values[31, 7, 22] = 50.0
    i2o = np.diag([0.05, 0.05, 0.05, 1.0])
    grid = VoxelGrid("density", values, (0, 0, 0), np.linalg.inv(i2o))
    b = ProgramBuilder()
    from engine.nodes.input_nodes import IN_HIT3
    co = b.emit(IN_HIT3, "vector", [H_OBJECT], varying=True)
    b.emit(TEX_GRID, "float", [co, 0, 0], grid=grid)

    class Table:
        metallic = np.zeros(1)
        programs = [b.build()]
        texture_index = {}
    T = (None,) * 5 + pack_programs(Table())
    objects = np.zeros((1, N_OBJ))
    to_world = np.array([[1.0, 0, 0, 10.0], [0, 1.0, 0, -3.0], [0, 0, 1.0, 2.0]])
    objects[0, O_TO_WORLD:O_TO_WORLD + 12] = to_world.ravel()
    peaks = grid_peaks(T, 0, objects, 0)
    hot = np.array([31, 7, 22]) * 0.05 + to_world[:, 3]
    assert np.isclose(peaks, hot, atol=1e-9).all(axis=1).any()
