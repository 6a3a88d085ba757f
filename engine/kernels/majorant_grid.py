"""Majorant grids: a coarse grid of majorants over a heterogeneous volume's bounds, so that
null-scattering tracking (engine.kernels.medium_density) takes tentative collisions at the
rate the density needs where it is, not at the rate of its densest part everywhere (a
smoke cache fills a fraction of its box; Cycles keeps an octree of majorants for the same
reason, kernel/integrator/volume_*).

Table MAJ (the shading tuple's field MAJORANTS, engine.nodes.pack): one row per material,
zeros (no grid) for a material without a heterogeneous volume:

  MG_LO (3), MG_HI (3)   the world-space box of the row's meshes
  MG_RES                 RES cells per axis (0: the row has no grid)
  MG_CELLS + ((i RES) + j) RES + k   cell (i, j, k)'s majorant

A cell's majorant is MAJORANT_SCALE times the largest extinction or emission channel of
the row's program found in it or in its 26 neighbours (majorant_bounds): at 2 x 2 x 2
jittered points of each cell, and at the centre of the largest voxel of each grid the
program reads whose trilinear support reaches into the cell (a program that grows with
its grids peaks at such a centre); never below FLOOR of the row's global majorant. The estimators stay unbiased for any
majorant above 0 (medium_density's docstring): the grid only moves where the
collisions are taken.

`cell_majorant` is the query the trackers advance by: the majorant of the cell a ray is
in at distance s and the distance at which it leaves that cell (the box's entry when
the ray is outside it, where the row's medium is empty)."""
from __future__ import annotations

import math

import numpy as np

from .jit import kernel

MG_LO, MG_HI, MG_RES, MG_CELLS = 0, 3, 6, 7
RES = 16
WIDTH = MG_CELLS + RES ** 3
FLOOR = 1.0 / 64.0                 # of the row's global majorant, the least a cell has
_NUDGE = 1e-6                      # of a cell, past a boundary before a cell is looked up


def empty_table(n_rows: int) -> np.ndarray:
    """MAJ with no grid (n_rows may be 0: a scene without heterogeneous volumes)."""
    return np.zeros((n_rows, WIDTH if n_rows else MG_CELLS))


@kernel(allocates=False)
def has_grid(maj, m):
    return 0 <= m < maj.shape[0] and maj[m, MG_RES] > 0.0


@kernel(allocates=False)
def _slab(o, d, lo, hi):
    """The distances (t0, t1) at which o + t d is within [lo, hi] on one axis."""
    if d != 0.0:
        a, b = (lo - o) / d, (hi - o) / d
        return min(a, b), max(a, b)
    if lo <= o <= hi:
        return -math.inf, math.inf
    return math.inf, -math.inf


@kernel(allocates=False)
def cell_majorant(maj, m, ox, oy, oz, dx, dy, dz, s):
    """(majorant of row m's grid at distance s along the ray, distance at which it
    changes); outside the box 0 until the box's entry (inf: never)."""
    row = maj[m]
    res = np.int64(row[MG_RES])
    sx = (row[MG_HI] - row[MG_LO]) / res
    sy = (row[MG_HI + 1] - row[MG_LO + 1]) / res
    sz = (row[MG_HI + 2] - row[MG_LO + 2]) / res
    nudge = _NUDGE * min(sx, sy, sz)
    s1 = s + nudge
    px, py, pz = ox + dx * s1, oy + dy * s1, oz + dz * s1
    cx = (px - row[MG_LO]) / sx
    cy = (py - row[MG_LO + 1]) / sy
    cz = (pz - row[MG_LO + 2]) / sz
    if not (0.0 <= cx < res and 0.0 <= cy < res and 0.0 <= cz < res):
        # outside: empty until the box's entry ahead
        a0, a1 = _slab(ox, dx, row[MG_LO], row[MG_HI])
        b0, b1 = _slab(oy, dy, row[MG_LO + 1], row[MG_HI + 1])
        c0, c1 = _slab(oz, dz, row[MG_LO + 2], row[MG_HI + 2])
        t0, t1 = max(a0, b0, c0), min(a1, b1, c1)
        if t0 <= t1 and t0 > s:
            return 0.0, t0
        return 0.0, math.inf
    i, j, k = np.int64(cx), np.int64(cy), np.int64(cz)
    mu = row[MG_CELLS + (i * res + j) * res + k]
    # where the ray leaves the cell
    end = math.inf
    if dx > 0.0:
        end = min(end, (row[MG_LO] + (i + 1) * sx - ox) / dx)
    elif dx < 0.0:
        end = min(end, (row[MG_LO] + i * sx - ox) / dx)
    if dy > 0.0:
        end = min(end, (row[MG_LO + 1] + (j + 1) * sy - oy) / dy)
    elif dy < 0.0:
        end = min(end, (row[MG_LO + 1] + j * sy - oy) / dy)
    if dz > 0.0:
        end = min(end, (row[MG_LO + 2] + (k + 1) * sz - oz) / dz)
    elif dz < 0.0:
        end = min(end, (row[MG_LO + 2] + k * sz - oz) / dz)
    return mu, max(end, s1)


def cell_centres(lo, hi, jitter) -> np.ndarray:
    """Points (RES^3 x 8, 3): 2 x 2 x 2 jittered points in each cell, cell by cell (the
    row-major order of MG_CELLS); jitter (RES^3 x 8, 3) uniform in [0, 1)."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    size = (hi - lo) / RES
    ijk = np.stack(np.meshgrid(*(np.arange(RES),) * 3, indexing="ij"), -1).reshape(-1, 1, 3)
    sub = np.stack(np.meshgrid(*(np.arange(2),) * 3, indexing="ij"), -1).reshape(1, 8, 3)
    frac = (ijk * 2 + sub + jitter.reshape(-1, 8, 3)) / 2.0
    return (lo + frac * size).reshape(-1, 3)


def cells_of(points, lo, hi, reach) -> list:
    """For each point (n, 3) with a reach (n, 3) either side, the flat cell indices of the
    up to 8 cells its box [p - reach, p + reach] touches (a list of 8 (n,) arrays; the
    same cell may repeat)."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    size = (hi - lo) / RES
    out = []
    for corner in range(8):
        sign = np.array([(corner >> 2) & 1, (corner >> 1) & 1, corner & 1]) * 2 - 1
        c = np.floor((points + sign * reach - lo) / size).astype(np.int64)
        c = np.clip(c, 0, RES - 1)
        out.append((c[:, 0] * RES + c[:, 1]) * RES + c[:, 2])
    return out
