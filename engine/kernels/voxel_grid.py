"""Voxel-grid lookups, scalar: the compiled twin of engine.volume_grid.VoxelGrid.lookup
(trilinear between voxel centres at integer block coordinates, every tap outside the
block reading 0), on the packed VOXELS and GRIDS arrays (engine.volume_grid.pack_grids)
that engine.nodes.pack appends to the shading tuple T.

`grid_sample(..., stochastic=True)` is Cycles 5's one-tap stochastic interpolation: on
each axis the upper neighbour is taken with probability equal to the trilinear weight
(Cycles' texture_3d.h interp_stochastic), so the value is one voxel's, and its
expectation is the trilinear value. A shader that is not linear in the grid (a
temperature raised to the fourth power by blackbody emission) then sees the voxels'
own values, as in Cycles, not their blend. The random numbers are a hash of the point
in voxel units (2^-24 of a voxel apart are different points): the points a path visits
are random, so the choices are too."""
from __future__ import annotations

import math

import numpy as np

from ..sampling.hashing import chain, unit_float
from ..volume_grid import G_AFFINE, G_C, G_NX, G_NY, G_NZ, G_OFFSET
from .jit import kernel


@kernel(allocates=False)
def _tap(voxels, base, nx, ny, nz, nc, i, j, k, c):
    if i < 0 or j < 0 or k < 0 or i >= nx or j >= ny or k >= nz:
        return 0.0
    return np.float64(voxels[base + ((i * ny + j) * nz + k) * nc + c])


STOCHASTIC_SALT = 0x564F58454C      # the stochastic choices' own hash chain


@kernel(allocates=False)
def _axis_pick(key, axis, t):
    """1 (the upper neighbour) with probability t."""
    return 1 if unit_float(chain(key, axis)) < t else 0


@kernel(allocates=False)
def grid_sample(voxels, grids, g, x, y, z, c, stochastic):
    """Channel c of grid g at object-space point (x, y, z), trilinear or (stochastic)
    one voxel picked with the trilinear weights; 0 for an unknown grid or a non-finite
    point."""
    if g < 0 or g >= grids.shape[0]:
        return 0.0
    row = grids[g]
    a = G_AFFINE
    qx = row[a] * x + row[a + 1] * y + row[a + 2] * z + row[a + 3]
    qy = row[a + 4] * x + row[a + 5] * y + row[a + 6] * z + row[a + 7]
    qz = row[a + 8] * x + row[a + 9] * y + row[a + 10] * z + row[a + 11]
    if not (math.isfinite(qx) and math.isfinite(qy) and math.isfinite(qz)):
        return 0.0
    nx, ny, nz = np.int64(row[G_NX]), np.int64(row[G_NY]), np.int64(row[G_NZ])
    if qx <= -1.0 or qy <= -1.0 or qz <= -1.0 or qx >= nx or qy >= ny or qz >= nz:
        return 0.0
    nc = np.int64(row[G_C])
    base = np.int64(row[G_OFFSET])
    fx, fy, fz = math.floor(qx), math.floor(qy), math.floor(qz)
    tx, ty, tz = qx - fx, qy - fy, qz - fz
    i, j, k = np.int64(fx), np.int64(fy), np.int64(fz)
    if stochastic:
        scale = 16777216.0                      # 2^24 per voxel
        key = chain(chain(chain(STOCHASTIC_SALT, np.int64((qx + 1.0) * scale)),
                          np.int64((qy + 1.0) * scale)), np.int64((qz + 1.0) * scale))
        return _tap(voxels, base, nx, ny, nz, nc, i + _axis_pick(key, 0, tx),
                    j + _axis_pick(key, 1, ty), k + _axis_pick(key, 2, tz), c)
    v = 0.0
    for corner in range(8):
        di, dj, dk = (corner >> 2) & 1, (corner >> 1) & 1, corner & 1
        w = ((tx if di else 1.0 - tx) * (ty if dj else 1.0 - ty)
             * (tz if dk else 1.0 - tz))
        if w != 0.0:
            v += w * _tap(voxels, base, nx, ny, nz, nc, i + di, j + dj, k + dk, c)
    return v


@kernel(allocates=False)
def grid_channels(grids, g):
    """Grid g's channel count (0 for an unknown grid)."""
    if g < 0 or g >= grids.shape[0]:
        return 0
    return np.int64(grids[g, G_C])
