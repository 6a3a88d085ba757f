"""The majorants of heterogeneous volumes, computed once per render before any path is
traced: each heterogeneous row's global majorant V_MAJ and its majorant grid
(engine.kernels.majorant_grid), from its program run at sample points.

A row's program is run at 2 x 2 x 2 jittered points in each of the grid's cells over
the bounds of the row's meshes (Cycles takes 16 samples per octree voxel and scales its
estimates by 1.5, as DRT does here: MAJORANT_SCALE), and, when it reads voxel grids (a
Volume object's), at the centre of the largest voxel of each grid whose trilinear
support reaches into each cell: a program that grows with its grids peaks at such a
centre, which jittered points of a sparse smoke miss. V_MAJ is the largest of them all
(MU_FLOOR when every sample is zero); a cell's majorant is MAJORANT_SCALE times the
largest in the cell and its 26 neighbours, and at least majorant_grid.FLOOR of V_MAJ.

The neighbours count because samples miss peaks: a thresholded noise (a Color Ramp
with a narrow step on Density) has peaks between one cell's 8 points that a
neighbour's points find. Where the density exceeds a cell's majorant the trackers'
weights turn negative (unbiased, but fireflies and black pixels): in a public file of
textured fog lit by lamps inside it (docs/public_files.md, space.blend) the cells alone
left DRT's image 20 to 40 % above Cycles' at 128 samples, speckled; with their
neighbours, within 1.2 % and clean (2026-12-03)."""
from __future__ import annotations

import numpy as np

from ..nodes.context import N_HIT, O_TO_WORLD
from ..nodes.pack import GRIDS, MAJORANTS, NREGS, OPS, PROG, VOXELS
from ..nodes.texture_nodes import TEX_GRID
from ..volume_grid import G_AFFINE, G_C, G_NX, G_NY, G_NZ, G_OFFSET
from .jit import kernel
from .majorant_grid import FLOOR, MG_CELLS, MG_HI, MG_LO, MG_RES, RES, cell_centres, cells_of
from .medium_density import row_coefficients
from .volume import V_HET, V_MAJ, V_OBJ

MU_FLOOR = 1e-2            # the majorant of a program found zero everywhere sampled
MAJORANT_SCALE = 1.5
SEED = 0x5EED


@kernel
def point_values(vol, m, T, objects, camera, pts):
    """The largest extinction or emission channel of row m at each point (k, 3)."""
    hit = np.zeros(N_HIT)
    regs = np.zeros(max(T[NREGS][0], 1))
    count = np.zeros(1, np.int64)
    out = np.zeros(pts.shape[0])
    for i in range(pts.shape[0]):
        sar, sag, sab, ssr, ssg, ssb, er, eg, eb = row_coefficients(
            vol, m, T, objects, camera, pts[i, 0], pts[i, 1], pts[i, 2], 0.0, 0.0, -1.0,
            1, 0, hit, regs, count)
        out[i] = max(sar + ssr, sag + ssg, sab + ssb, er, eg, eb)
    return out


def _grids_read(T, m) -> np.ndarray:
    prog = T[PROG]
    if not (0 <= m < prog.shape[0]) or prog[m, 1] == 0 or T[GRIDS].shape[0] == 0:
        return np.zeros(0, np.int64)
    ops = T[OPS][prog[m, 0]:prog[m, 0] + prog[m, 1]]
    return np.unique(ops[ops[:, 0] == TEX_GRID, 7]).astype(np.int64)


def _voxels_to_world(T, g, objects, obj):
    """(magnitudes (n,), 4 x 4 block index -> world) of grid g placed by object obj."""
    row = T[GRIDS][g]
    nx, ny, nz, nc = (int(row[G_NX]), int(row[G_NY]), int(row[G_NZ]), int(row[G_C]))
    start = int(row[G_OFFSET])
    block = T[VOXELS][start:start + nx * ny * nz * nc].reshape(nx * ny * nz, nc)
    to_block = np.eye(4)
    to_block[:3] = row[G_AFFINE:G_AFFINE + 12].reshape(3, 4)
    to_world = np.eye(4)
    if 0 <= obj < objects.shape[0]:
        to_world[:3] = objects[obj, O_TO_WORLD:O_TO_WORLD + 12].reshape(3, 4)
    return np.abs(block).max(axis=1), to_world @ np.linalg.inv(to_block), (nx, ny, nz)


def grid_peaks(T, m, objects, obj, count=4096) -> np.ndarray:
    """World-space centres (k, 3) of the `count` largest voxels of each grid material
    m's program reads."""
    found = []
    for g in _grids_read(T, m):
        mag, to_world, shape = _voxels_to_world(T, g, objects, obj)
        k = min(count, mag.size)
        idx = np.argpartition(mag, mag.size - k)[mag.size - k:]
        ijk = np.stack(np.unravel_index(idx, shape), 1).astype(np.float64)
        found.append(ijk @ to_world[:3, :3].T + to_world[:3, 3])
    return np.ascontiguousarray(np.concatenate(found)) if found else np.zeros((0, 3))


def cell_peaks(T, m, objects, obj, lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """(points (k, 3), their cells (k,)): for each grid m's program reads and each cell of
    the majorant grid over [lo, hi], the world centre of the largest nonzero voxel whose
    trilinear support (one voxel either side) reaches into the cell."""
    points, cells = [], []
    for g in _grids_read(T, m):
        mag, to_world, shape = _voxels_to_world(T, g, objects, obj)
        idx = np.nonzero(mag > 0.0)[0]
        if idx.size == 0:
            continue
        ijk = np.stack(np.unravel_index(idx, shape), 1).astype(np.float64)
        centres = ijk @ to_world[:3, :3].T + to_world[:3, 3]
        reach = np.abs(to_world[:3, :3]).sum(axis=1)          # one voxel, every axis
        touched = cells_of(centres, lo, hi, np.broadcast_to(reach, centres.shape))
        cell = np.concatenate(touched)
        voxel = np.tile(np.arange(idx.size), 8)
        order = np.lexsort((mag[idx][voxel], cell))
        last = np.append(cell[order][1:] != cell[order][:-1], True)
        points.append(centres[voxel[order][last]])
        cells.append(cell[order][last])
    if not points:
        return np.zeros((0, 3)), np.zeros(0, np.int64)
    return np.concatenate(points), np.concatenate(cells)


def with_neighbours(cell_top):
    """Each cell's value (RES^3, the grid's order) raised to the largest of its 3 x 3 x 3
    neighbourhood: the largest of each cell and its two neighbours along each axis in
    turn."""
    top = cell_top.reshape(RES, RES, RES)
    for axis in range(3):
        a = np.moveaxis(top, axis, 0)
        b = a.copy()
        b[:-1] = np.maximum(b[:-1], a[1:])
        b[1:] = np.maximum(b[1:], a[:-1])
        top = np.moveaxis(b, 0, axis)
    return np.ascontiguousarray(top).ravel()


def bound_majorants(vol, T, tri_material, tri_object, objects, triangles, camera,
                    grids=True):
    """Fill V_OBJ and V_MAJ of the heterogeneous rows of `vol` and their majorant grids
    in T[MAJORANTS] (in place): V_OBJ is the object of the first triangle of the row's
    material (-1 without object rows); the majorants are the module docstring's, over
    the bounds of that material's triangles (triangles: (positions (V, 3), each
    triangle's corners as rows of them (T, 3))). grids=False leaves every row without a
    majorant grid (V_MAJ everywhere). Returns vol."""
    positions, corners = triangles
    maj = T[MAJORANTS]
    rng = np.random.default_rng(SEED)
    for m in np.nonzero(vol[:, V_HET] != 0.0)[0]:
        m = int(m)
        tris = np.nonzero(tri_material == m)[0]
        if tris.size == 0:
            vol[m, V_MAJ] = MU_FLOOR
            continue
        obj = int(tri_object[tris[0]]) if len(tri_object) else -1
        vol[m, V_OBJ] = obj
        pts = positions[corners[tris].ravel()]
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        span = np.maximum(hi - lo, 1e-9 * max(float(np.abs(hi).max()), 1.0))
        hi = lo + span
        samples = cell_centres(lo, hi, rng.random((RES ** 3 * 8, 3)))
        cell_top = point_values(vol, m, T, objects, camera, samples).reshape(-1, 8).max(axis=1)
        peaks, peak_cells = cell_peaks(T, m, objects, obj, lo, hi)
        if len(peaks):
            np.maximum.at(cell_top, peak_cells,
                          point_values(vol, m, T, objects, camera, peaks))
        cell_top = with_neighbours(cell_top)
        top = float(cell_top.max())
        vol[m, V_MAJ] = max(MAJORANT_SCALE * top, MU_FLOOR)
        if grids and m < maj.shape[0]:
            maj[m, MG_LO:MG_LO + 3] = lo
            maj[m, MG_HI:MG_HI + 3] = hi
            maj[m, MG_RES] = RES
            maj[m, MG_CELLS:] = np.maximum(MAJORANT_SCALE * cell_top, FLOOR * vol[m, V_MAJ])
    return vol
