"""Heterogeneous volumes, compiled: media whose coefficients vary in space (a texture on a
Principled Volume's Density, say), as Cycles 5 renders them by default, by null
scattering (kernel/integrator/shade_volume.h, read for its meaning only).

A heterogeneous row of the volume table (volume.V_HET) has its absorption, scattering
and emission computed at a point by its material's shader program (the outputs
volume_absorption, volume_scattering and volume_emission; engine.nodes), run on a
"hit" at that point: N = Ng = I = the reversed ray direction, no UV, the row's object
(volume.V_OBJ) for Object and Generated coordinates, as Cycles' shader_setup_from_volume.
The medium at a point is the sum over the path's volume stack, homogeneous rows
included. `V_MAJ` holds a majorant mu of the row's extinction and emission (the
largest channel).

The estimators fill the medium with fictitious particles up to the majorant, so its
extinction is mu everywhere, and sample tentative collisions at rate mu:

- a path's segment (weighted delta tracking, Kutz et al. 2017's spectral tracking, as
  Cycles' volume_integrate_step_scattering): at each collision x the emission
  f sigma_e(x) / mu is gathered, then a real scattering is picked with probability
  P_s = sum_c |b_c f_c| sigma_s,c / sum_c |b_c f_c| (sigma_s,c + |sigma_n,c|) (sigma_n =
  mu - sigma_t; absorption, which adds nothing, is never picked) and the throughput
  factor f is multiplied by sigma_s / (mu P_s), or by sigma_n / (mu (1 - P_s)) for a
  null collision, after which tracking goes on. Passing the segment's end keeps f.
- a shadow ray's transmittance (ratio tracking): the product over the collisions of
  1 - sigma_t,c(x) / mu.

Both are unbiased for any mu > 0: where the density exceeds mu, sigma_n is negative and
so are the weights, which costs variance, never bias. The bound only decides the
noise and the number of program runs (about mu times the length). `bound_majorants`
takes it as 1.5 times the largest value of 4096 jittered samples of the program over
the row's meshes' bounds (Cycles takes 16 samples per octree voxel, and scales on-the-fly
estimates by 1.5), and at the centres of the largest voxels of the grids the program
reads (`grid_peaks`); a program that is zero everywhere sampled gets MU_FLOOR.

Paths through homogeneous media only never reach this module: `has_heterogeneous`
is checked once per kernel call, and each evaluation of a program here counts in the
`count` array the integrator keeps (tests check it stays 0 without such volumes)."""
from __future__ import annotations

import math

import numpy as np

from .. import visibility
from ..nodes.context import N_HIT, O_TO_WORLD, fill
from ..nodes.interpreter import run
from ..nodes.pack import GRIDS, NREGS, OPS, OUTS, PROG, VOXELS
from ..nodes.texture_nodes import TEX_GRID
from ..volume_grid import G_AFFINE, G_C, G_NX, G_NY, G_NZ, G_OFFSET
from ..nodes.shading import OUT_VOL_EM, OUT_VOL_SA, OUT_VOL_SS
from ..sampling.hashing import chain, unit_float
from .jit import kernel
from .volume import V_G, V_HET, V_MAJ, V_OBJ, medium

MAX_STEPS = 1024           # collisions per segment (Cycles' VOLUME_MAX_STEPS)
MU_FLOOR = 1e-2            # the majorant of a program found zero everywhere sampled
MAJORANT_SCALE = 1.5
BOUND_SAMPLES = 16         # per axis of the jittered grid over a row's bounds
PEAK_VOXELS = 4096         # largest voxels of each grid a row reads, also sampled
HET_DIM = 1 << 26          # the tracking's own random numbers (hashed: any count)
SHADOW = visibility.SHADOW


@kernel(allocates=False)
def has_heterogeneous(vol):
    for m in range(vol.shape[0]):
        if vol[m, V_HET] != 0.0:
            return True
    return False


@kernel(allocates=False)
def heterogeneous_in(vol, stacks, p):
    """Whether path (or shadow ray) p's medium has a heterogeneous entry."""
    for k in range(stacks.shape[1]):
        m = stacks[p, k]
        if m < 0:
            return False
        if vol[m, V_HET] != 0.0:
            return True
    return False


@kernel(allocates=False)
def row_coefficients(vol, m, T, objects, camera, px, py, pz, dx, dy, dz, ray, depth,
                     hit, regs, count):
    """Heterogeneous row m's (sigma_a RGB, sigma_s RGB, emission RGB) at point p, for a
    ray along d: its program's outputs, clamped at 0."""
    fill(hit, px, py, pz, -dx, -dy, -dz, -dx, -dy, -dz, dx, dy, dz, 0.0, 0.0, True, ray,
         depth, 0.0, objects, int(vol[m, V_OBJ]), camera, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
         0.0, 0.0)
    run(T, m, hit, regs)
    count[0] += 1
    outs = T[OUTS]
    sar = sag = sab = ssr = ssg = ssb = er = eg = eb = 0.0
    k = outs[m, OUT_VOL_SA]
    if k >= 0:
        sar, sag, sab = max(regs[k], 0.0), max(regs[k + 1], 0.0), max(regs[k + 2], 0.0)
    k = outs[m, OUT_VOL_SS]
    if k >= 0:
        ssr, ssg, ssb = max(regs[k], 0.0), max(regs[k + 1], 0.0), max(regs[k + 2], 0.0)
    k = outs[m, OUT_VOL_EM]
    if k >= 0:
        er, eg, eb = max(regs[k], 0.0), max(regs[k + 1], 0.0), max(regs[k + 2], 0.0)
    return sar, sag, sab, ssr, ssg, ssb, er, eg, eb


@kernel(allocates=False)
def point_medium(vol, stacks, p, T, objects, camera, px, py, pz, dx, dy, dz, ray, depth,
                 hit, regs, count):
    """The medium of p's stack at a point: (sigma_a RGB, sigma_s RGB, g, emission RGB),
    g the scattering-weighted mean: volume.medium's sum of the homogeneous rows (the
    heterogeneous rows' constants are zeros) plus the heterogeneous rows' programs."""
    sar, sag, sab, ssr, ssg, ssb, g, er, eg, eb = medium(vol, stacks, p)
    gs = ssr + ssg + ssb
    gw = g * gs
    for k in range(stacks.shape[1]):
        m = stacks[p, k]
        if m < 0:
            break
        if vol[m, V_HET] == 0.0:
            continue
        a0, a1, a2, s0, s1, s2, e0, e1, e2 = row_coefficients(
            vol, m, T, objects, camera, px, py, pz, dx, dy, dz, ray, depth, hit, regs, count)
        sar, sag, sab = sar + a0, sag + a1, sab + a2
        ssr, ssg, ssb = ssr + s0, ssg + s1, ssb + s2
        er, eg, eb = er + e0, eg + e1, eb + e2
        gw += (s0 + s1 + s2) * vol[m, V_G]
        gs += s0 + s1 + s2
    return sar, sag, sab, ssr, ssg, ssb, gw / gs if gs > 0.0 else 0.0, er, eg, eb


@kernel(allocates=False)
def majorant(vol, stacks, p):
    """The majorant of p's medium: the heterogeneous rows' V_MAJ plus the homogeneous
    rows' largest extinction or emission channel."""
    sar, sag, sab, ssr, ssg, ssb, _, er, eg, eb = medium(vol, stacks, p)
    mu = max(sar + ssr, sag + ssg, sab + ssb, er, eg, eb)
    for k in range(stacks.shape[1]):
        m = stacks[p, k]
        if m < 0:
            break
        if vol[m, V_HET] != 0.0:
            mu += vol[m, V_MAJ]
    return mu


@kernel
def _uniform(key, step, j):
    return unit_float(chain(chain(key, step), j))


@kernel
def path_key(pkey, index, depth):
    """The tracking's random stream of one path at one bounce."""
    return chain(chain(chain(pkey, index), HET_DIM), depth)


@kernel
def shadow_keys(pkey, index, sh_path, depth):
    """path_key of each shadow ray's path, salted apart from the path's own stream."""
    out = np.empty(sh_path.shape[0], np.uint64)
    for i in range(sh_path.shape[0]):
        p = sh_path[i]
        out[i] = chain(path_key(pkey[p], index[p], depth), 0x5AD0)
    return out


@kernel(allocates=False)
def tracked_segment(vol, stacks, p, T, objects, camera, ox, oy, oz, dx, dy, dz, t, t_mark,
                    br, bg, bb, ray, depth, key, hit, regs, count):
    """Path p (throughput b) travels distance t (inf: to infinity) from o along d through
    its heterogeneous medium (see the module's docstring).

    Returns (scattered, t_end, throughput factor f RGB, f at distance t_mark RGB (0 when
    the path scattered before it), emitted radiance RGB (times b), g at the
    scattering)."""
    mu = majorant(vol, stacks, p)
    fr = fg = fb = 1.0
    mr = mg = mb = 0.0
    marked = False
    Er = Eg = Eb = 0.0
    if not mu > 0.0:
        return False, t, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0
    s = 0.0
    for step in range(MAX_STEPS):
        s -= math.log(max(1.0 - _uniform(key, step, 0), 1e-300)) / mu
        if not marked and s >= t_mark:
            mr, mg, mb, marked = fr, fg, fb, True
        if s >= t:
            return False, t, fr, fg, fb, mr, mg, mb, Er, Eg, Eb, 0.0
        sar, sag, sab, ssr, ssg, ssb, g, er, eg, eb = point_medium(
            vol, stacks, p, T, objects, camera, ox + dx * s, oy + dy * s, oz + dz * s,
            dx, dy, dz, ray, depth, hit, regs, count)
        Er += br * fr * er / mu
        Eg += bg * fg * eg / mu
        Eb += bb * fb * eb / mu
        nr, ng, nb = mu - sar - ssr, mu - sag - ssg, mu - sab - ssb
        wr, wg, wb = abs(br * fr), abs(bg * fg), abs(bb * fb)
        num = wr * ssr + wg * ssg + wb * ssb
        den = num + wr * abs(nr) + wg * abs(ng) + wb * abs(nb)
        if not den > 0.0:
            break                        # nothing left to carry: absorbed
        ps = num / den
        if _uniform(key, step, 1) < ps:
            k = 1.0 / (mu * ps)
            return (True, s, fr * ssr * k, fg * ssg * k, fb * ssb * k, mr, mg, mb,
                    Er, Eg, Eb, g)
        k = 1.0 / (mu * (1.0 - ps))
        fr, fg, fb = fr * nr * k, fg * ng * k, fb * nb * k
    # absorbed (or past MAX_STEPS): nothing goes on
    return False, t, 0.0, 0.0, 0.0, mr, mg, mb, Er, Eg, Eb, 0.0


@kernel(allocates=False)
def tracked_transmittance(vol, stacks, r, T, objects, camera, ox, oy, oz, dx, dy, dz, t,
                          key, hit, regs, count):
    """Ratio tracking: an unbiased estimate of shadow ray r's transmittance (RGB) over
    distance t from o along d through its medium; Russian roulette once every channel
    is below 0.1."""
    mu = majorant(vol, stacks, r)
    tr = tg = tb = 1.0
    if not mu > 0.0 or not math.isfinite(t):
        return tr, tg, tb
    s = 0.0
    for step in range(MAX_STEPS):
        s -= math.log(max(1.0 - _uniform(key, step, 0), 1e-300)) / mu
        if s >= t:
            return tr, tg, tb
        sar, sag, sab, ssr, ssg, ssb, _, _, _, _ = point_medium(
            vol, stacks, r, T, objects, camera, ox + dx * s, oy + dy * s, oz + dz * s,
            dx, dy, dz, SHADOW, 0, hit, regs, count)
        tr *= 1.0 - (sar + ssr) / mu
        tg *= 1.0 - (sag + ssg) / mu
        tb *= 1.0 - (sab + ssb) / mu
        big = max(abs(tr), abs(tg), abs(tb))
        if big < 0.1:
            q = max(big * 5.0, 0.05)     # survive with probability q
            if _uniform(key, step, 1) >= q:
                return 0.0, 0.0, 0.0
            tr, tg, tb = tr / q, tg / q, tb / q
    return 0.0, 0.0, 0.0


@kernel(allocates=False)
def attenuate_tracked(vol, stacks, r, trans, T, objects, camera, ox, oy, oz, dx, dy, dz,
                      t, key, hit, regs, count):
    tr, tg, tb = tracked_transmittance(vol, stacks, r, T, objects, camera, ox, oy, oz,
                                       dx, dy, dz, t, key, hit, regs, count)
    trans[r, 0] *= tr
    trans[r, 1] *= tg
    trans[r, 2] *= tb


@kernel
def _sample_row(vol, m, T, objects, camera, lo, hi, n, seed):
    """The largest extinction or emission channel of row m over n^3 jittered points of
    the box [lo, hi]."""
    hit = np.zeros(N_HIT)
    regs = np.zeros(max(T[NREGS][0], 1))
    count = np.zeros(1, np.int64)
    top = 0.0
    key = chain(seed, m)
    i = 0
    for a in range(n):
        for b in range(n):
            for c in range(n):
                x = lo[0] + (hi[0] - lo[0]) * (a + _uniform(key, i, 0)) / n
                y = lo[1] + (hi[1] - lo[1]) * (b + _uniform(key, i, 1)) / n
                z = lo[2] + (hi[2] - lo[2]) * (c + _uniform(key, i, 2)) / n
                i += 1
                sar, sag, sab, ssr, ssg, ssb, er, eg, eb = row_coefficients(
                    vol, m, T, objects, camera, x, y, z, 0.0, 0.0, -1.0, 1, 0, hit, regs,
                    count)
                top = max(top, sar + ssr, sag + ssg, sab + ssb, er, eg, eb)
    return top


def bound_majorants(vol, T, tri_material, tri_object, objects, triangles, camera):
    """Fill V_OBJ and V_MAJ of the heterogeneous rows of `vol` (in place): the object of
    the first triangle of the row's material (-1 without object rows) and the majorant
    of the module's docstring, over the bounds of that material's triangles (triangles:
    (positions (V, 3), each triangle's corners as rows of them (T, 3))). Returns vol."""
    positions, corners = triangles
    for m in np.nonzero(vol[:, V_HET] != 0.0)[0]:
        tris = np.nonzero(tri_material == m)[0]
        if tris.size == 0:
            vol[m, V_MAJ] = MU_FLOOR
            continue
        vol[m, V_OBJ] = int(tri_object[tris[0]]) if len(tri_object) else -1
        pts = positions[corners[tris].ravel()]
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        top = _sample_row(vol, int(m), T, objects, camera, np.ascontiguousarray(lo),
                          np.ascontiguousarray(hi), BOUND_SAMPLES, np.uint64(0x5EED))
        peaks = grid_peaks(T, int(m), objects, int(vol[m, V_OBJ]))
        if len(peaks):
            top = max(top, _sample_points(vol, int(m), T, objects, camera, peaks))
        vol[m, V_MAJ] = max(MAJORANT_SCALE * top, MU_FLOOR)
    return vol


def grid_peaks(T, m, objects, obj) -> np.ndarray:
    """World-space centres (k, 3) of the PEAK_VOXELS largest voxels of each grid material
    m's program reads (a Volume object's density, temperature, ...): a trilinear grid
    peaks at a voxel centre, so a program that grows with its grids peaks there too,
    where the jittered samples of a sparse smoke would miss it."""
    prog = T[PROG]
    if not (0 <= m < prog.shape[0]) or prog[m, 1] == 0 or T[GRIDS].shape[0] == 0:
        return np.zeros((0, 3))
    ops = T[OPS][prog[m, 0]:prog[m, 0] + prog[m, 1]]
    found = []
    for g in np.unique(ops[ops[:, 0] == TEX_GRID, 7]):
        row = T[GRIDS][g]
        nx, ny, nz, nc = (int(row[G_NX]), int(row[G_NY]), int(row[G_NZ]), int(row[G_C]))
        start = int(row[G_OFFSET])
        block = T[VOXELS][start:start + nx * ny * nz * nc].reshape(nx * ny * nz, nc)
        mag = np.abs(block).max(axis=1)
        k = min(PEAK_VOXELS, mag.size)
        idx = np.argpartition(mag, mag.size - k)[mag.size - k:]
        ijk = np.stack(np.unravel_index(idx, (nx, ny, nz)), 1).astype(np.float64)
        affine = row[G_AFFINE:G_AFFINE + 12].reshape(3, 4)
        local = np.linalg.solve(affine[:, :3], (ijk - affine[:, 3]).T).T
        if 0 <= obj < objects.shape[0]:
            to_world = objects[obj, O_TO_WORLD:O_TO_WORLD + 12].reshape(3, 4)
            local = local @ to_world[:, :3].T + to_world[:, 3]
        found.append(local)
    return np.ascontiguousarray(np.concatenate(found)) if found else np.zeros((0, 3))


@kernel
def _sample_points(vol, m, T, objects, camera, pts):
    """The largest extinction or emission channel of row m at the points pts (k, 3)."""
    hit = np.zeros(N_HIT)
    regs = np.zeros(max(T[NREGS][0], 1))
    count = np.zeros(1, np.int64)
    top = 0.0
    for i in range(pts.shape[0]):
        sar, sag, sab, ssr, ssg, ssb, er, eg, eb = row_coefficients(
            vol, m, T, objects, camera, pts[i, 0], pts[i, 1], pts[i, 2], 0.0, 0.0, -1.0,
            1, 0, hit, regs, count)
        top = max(top, sar + ssr, sag + ssg, sab + ssb, er, eg, eb)
    return top
