"""Voxel grids: the values of a Volume object's OpenVDB grid (density, temperature,
flame, colour, ...) as a dense block over its active voxels, which shader programs read
where a Cycles material reads the grid through an Attribute node or the Principled
Volume's Density, Color and Temperature Attributes (engine.nodes.texture_nodes.TEX_GRID).

A `VoxelGrid` holds
  values     float32 (nx, ny, nz, C): C = 1 for a scalar grid, 3 for a vector grid;
             values[i, j, k] is the voxel at index (i, j, k) + origin
  origin     the index coordinates of values[0, 0, 0] (the active voxels' lowest corner)
  to_index   4 x 4 object -> index space (the inverse of the grid's transform)

OpenVDB's convention, which Cycles keeps: voxel (i, j, k) is centred at index-space point
(i, j, k). Between centres the grid is trilinear; outside the block every tap reads 0
(the grid's background, and what inactive voxels hold). `lookup` is the NumPy twin of
the compiled engine.kernels.voxel_grid.grid_sample, used by tests and by the exporter.

`pack_grids` lays every grid out for the kernels: VOXELS, one float32 array of all their
values, and GRIDS, a float64 row per grid (G_* columns) with its offset, size, channel
count and the object -> block-index affine map (origin folded in)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# GRIDS columns
G_OFFSET, G_NX, G_NY, G_NZ, G_C, G_AFFINE = 0, 1, 2, 3, 4, 5
N_GRID = G_AFFINE + 12


@dataclass(eq=False)
class VoxelGrid:
    name: str
    values: np.ndarray
    origin: tuple = (0, 0, 0)
    to_index: np.ndarray = field(default_factory=lambda: np.eye(4))

    def __post_init__(self):
        v = np.asarray(self.values, np.float32)
        if v.ndim == 3:
            v = v[..., None]
        if v.ndim != 4 or v.shape[3] not in (1, 3):
            raise ValueError(f"grid {self.name!r}: values of shape {v.shape} are not "
                             f"(nx, ny, nz) or (nx, ny, nz, 3)")
        # a non-finite voxel (a broken cache) reads as empty space, never NaN light
        self.values = np.ascontiguousarray(np.where(np.isfinite(v), v, 0.0), np.float32)
        self.to_index = np.asarray(self.to_index, np.float64).reshape(4, 4)
        if not np.isfinite(self.to_index).all():
            raise ValueError(f"grid {self.name!r}: its transform is not finite")

    @property
    def channels(self) -> int:
        return int(self.values.shape[3])

    def block_affine(self) -> np.ndarray:
        """3 x 4: object point -> coordinates in the block (voxel centres at integers)."""
        a = self.to_index[:3].copy()
        a[:, 3] -= np.asarray(self.origin, np.float64)
        return a

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The object-space box (lo, hi) outside which every lookup is 0: the block's
        voxel centres widened by one voxel (where the outermost taps fade out)."""
        n = np.array(self.values.shape[:3], np.float64)
        corners = np.array([[x, y, z] for x in (-1.0, n[0]) for y in (-1.0, n[1])
                            for z in (-1.0, n[2])]) + np.asarray(self.origin, np.float64)
        to_object = np.linalg.inv(self.to_index)
        pts = corners @ to_object[:3, :3].T + to_object[:3, 3]
        return pts.min(axis=0), pts.max(axis=0)

    def lookup(self, points) -> np.ndarray:
        """Trilinear values (n, C) at object-space points (n, 3)."""
        p = np.asarray(points, np.float64).reshape(-1, 3)
        a = self.block_affine()
        q = p @ a[:, :3].T + a[:, 3]
        q = np.where(np.isfinite(q), q, -2.0)
        base = np.floor(q)
        f = q - base
        i0 = base.astype(np.int64)
        n = np.array(self.values.shape[:3])
        out = np.zeros((len(p), self.channels))
        for corner in range(8):
            d = np.array([(corner >> 2) & 1, (corner >> 1) & 1, corner & 1])
            idx = i0 + d
            inside = ((idx >= 0) & (idx < n)).all(axis=1)
            w = np.prod(np.where(d == 1, f, 1.0 - f), axis=1) * inside
            c = np.clip(idx, 0, n - 1)
            out += w[:, None] * self.values[c[:, 0], c[:, 1], c[:, 2]].astype(np.float64)
        return out


def pack_grids(grids) -> tuple[np.ndarray, np.ndarray]:
    """(VOXELS float32, GRIDS float64 (n, N_GRID)) of a list of VoxelGrids."""
    rows = np.zeros((len(grids), N_GRID))
    blocks, pos = [], 0
    for g, grid in enumerate(grids):
        nx, ny, nz, c = grid.values.shape
        rows[g, G_OFFSET] = pos
        rows[g, G_NX:G_C + 1] = (nx, ny, nz, c)
        rows[g, G_AFFINE:] = grid.block_affine().ravel()
        blocks.append(grid.values.ravel())
        pos += grid.values.size
    voxels = np.concatenate(blocks) if blocks else np.zeros(0, np.float32)
    return voxels, rows
