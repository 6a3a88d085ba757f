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
- a point sampled on the segment by another strategy (equiangularly towards a lamp):
  ratio tracking's transmittance to it, and the density with which tracking would have
  scattered there, for the MIS weights of the two (`equiangular_point`).

All are unbiased for any mu > 0: where the density exceeds mu, sigma_n is negative and
so are the weights, which costs variance, never bias. The bound only decides the
noise and the number of program runs (about mu times the length). The majorant is a
row's V_MAJ, or where the row has one, its majorant grid's cell along the ray
(engine.kernels.majorant_grid): free flights are sampled through the cells by their
optical depth (`advance`). engine.kernels.majorant_bounds computes both.

Paths through homogeneous media only never reach this module: `has_heterogeneous`
is checked once per kernel call, and each evaluation of a program here counts in the
`count` array the integrator keeps (tests check it stays 0 without such volumes)."""
from __future__ import annotations

import math

import numpy as np

from .. import visibility
from ..nodes.context import fill
from ..nodes.interpreter import run
from ..nodes.pack import MAJORANTS, OUTS
from ..nodes.shading import OUT_VOL_EM, OUT_VOL_SA, OUT_VOL_SS
from ..sampling.hashing import chain, stream_key, stream_uniform
from .jit import kernel
from .majorant_grid import RES, cell_majorant, has_grid
from .volume import V_G, V_HET, V_MAJ, V_OBJ, V_SS, medium

MAX_STEPS = 1024           # collisions per segment (Cycles' VOLUME_MAX_STEPS)
ADVANCE_LIMIT = 4 * RES + 8  # cells one free flight may cross
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
def scatters_in(vol, stacks, p, T):
    """Whether path p's medium can scatter: a homogeneous row with a scattering
    coefficient, or a heterogeneous row whose program has a scattering output."""
    outs = T[OUTS]
    for k in range(stacks.shape[1]):
        m = stacks[p, k]
        if m < 0:
            return False
        if vol[m, V_HET] != 0.0:
            if outs[m, OUT_VOL_SS] >= 0:
                return True
        elif vol[m, V_SS] + vol[m, V_SS + 1] + vol[m, V_SS + 2] > 0.0:
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
def majorant_parts(vol, stacks, p, maj):
    """(mu_fixed, row): the part of p's majorant that is the same everywhere (the
    homogeneous rows and the heterogeneous rows without a majorant grid), and the first
    heterogeneous row with a grid (-1: none), whose cells add to it."""
    sar, sag, sab, ssr, ssg, ssb, _, er, eg, eb = medium(vol, stacks, p)
    mu = max(sar + ssr, sag + ssg, sab + ssb, er, eg, eb)
    row = -1
    for k in range(stacks.shape[1]):
        m = stacks[p, k]
        if m < 0:
            break
        if vol[m, V_HET] != 0.0:
            if row < 0 and has_grid(maj, m):
                row = m
            else:
                mu += vol[m, V_MAJ]
    return mu, row


@kernel(allocates=False)
def advance(maj, row, mu_fixed, ox, oy, oz, dx, dy, dz, s, t, tau):
    """From distance s, the distance at which the ray has crossed optical depth tau of
    the majorant (mu_fixed plus row's cells), with the majorant there; (t, mu, True)
    when it reaches t first."""
    mu = mu_fixed
    for _ in range(ADVANCE_LIMIT):
        end = math.inf
        mu = mu_fixed
        if row >= 0:
            mc, end = cell_majorant(maj, row, ox, oy, oz, dx, dy, dz, s)
            mu = mu_fixed + mc
        lim = min(end, t)
        if mu > 0.0 and tau < mu * (lim - s):
            return s + tau / mu, mu, False
        if lim >= t:
            return t, mu, True
        tau -= mu * (lim - s)
        s = lim
    return t, mu, True


@kernel(allocates=False)
def path_key(pkey, index, depth):
    """The tracking's random stream of one path at one bounce."""
    return stream_key(pkey, index, HET_DIM, depth)


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
                    t_eq, br, bg, bb, ray, depth, key, hit, regs, count):
    """Path p (throughput b) travels distance t (inf: to infinity) from o along d through
    its heterogeneous medium (see the module's docstring).

    Returns (scattered, t_end, throughput factor f RGB, f at distance t_mark RGB (0 when
    the path scattered before it), emitted radiance RGB (times b), g at the
    scattering, the scattering's density for MIS (0: none), `eq`).

    `eq` serves a point sampled at t_eq in [0, t] by equiangular sampling (t_eq < 0:
    none): (f RGB, prod(1 - P_s), mu(t_eq)) of a tracking that took every collision
    before t_eq as null, or zeros when tracking ended before. Where the path scatters
    before t_eq, tracking goes on to t_eq as ratio tracking (the collisions' places do
    not depend on what was decided at them), as Cycles does. `equiangular_point` takes
    it from there."""
    maj = T[MAJORANTS]
    mu_fixed, row = majorant_parts(vol, stacks, p, maj)
    fr = fg = fb = 1.0
    mr = mg = mb = 0.0
    marked = False
    Er = Eg = Eb = 0.0
    p_null = 1.0                         # the product of the null collisions' 1 - P_s
    eq = (0.0, 0.0, 0.0, 0.0, 0.0)
    eq_due = t_eq >= 0.0
    if not (mu_fixed > 0.0 or row >= 0):
        return (False, t, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                (1.0, 1.0, 1.0, 1.0, 0.0))
    # the scattering, once sampled: (t_end, f RGB, g, density)
    scattered = passed = False
    out = (t, 0.0, 0.0, 0.0, 0.0, 0.0)
    s = 0.0
    for step in range(MAX_STEPS):
        tau = -math.log(max(1.0 - stream_uniform(key, step, 0), 1e-300))
        s, mu, passed = advance(maj, row, mu_fixed, ox, oy, oz, dx, dy, dz, s, t, tau)
        if not marked and s >= t_mark and not scattered:
            mr, mg, mb, marked = fr, fg, fb, True
        if eq_due and s >= t_eq:
            eq = (fr, fg, fb, p_null, majorant_at(maj, row, mu_fixed, ox, oy, oz, dx, dy,
                                                  dz, t_eq))
            eq_due = False
        if passed or (scattered and not eq_due):
            break
        sar, sag, sab, ssr, ssg, ssb, g, er, eg, eb = point_medium(
            vol, stacks, p, T, objects, camera, ox + dx * s, oy + dy * s, oz + dz * s,
            dx, dy, dz, ray, depth, hit, regs, count)
        if not scattered:
            Er += br * fr * er / mu
            Eg += bg * fg * eg / mu
            Eb += bb * fb * eb / mu
        nr, ng, nb = mu - sar - ssr, mu - sag - ssg, mu - sab - ssb
        ps = scatter_probability(br * fr, bg * fg, bb * fb, ssr, ssg, ssb, nr, ng, nb)
        if not ps >= 0.0:
            break                        # nothing left to carry: absorbed
        if not scattered and stream_uniform(key, step, 1) < ps:
            k = 1.0 / (mu * ps)
            scattered = True
            out = (s, fr * ssr * k, fg * ssg * k, fb * ssb * k, g, p_null * mu * ps)
        # a null collision (after the path scattered: for the equiangular point only)
        k = 1.0 / (mu * (1.0 - ps))
        fr, fg, fb = fr * nr * k, fg * ng * k, fb * nb * k
        p_null *= 1.0 - ps
    if scattered:
        t_end, sfr, sfg, sfb, g, density = out
        return True, t_end, sfr, sfg, sfb, mr, mg, mb, Er, Eg, Eb, g, density, eq
    if passed:
        return False, t, fr, fg, fb, mr, mg, mb, Er, Eg, Eb, 0.0, 0.0, eq
    # absorbed (or past MAX_STEPS): nothing goes on
    return False, t, 0.0, 0.0, 0.0, mr, mg, mb, Er, Eg, Eb, 0.0, 0.0, eq


@kernel(allocates=False)
def majorant_at(maj, row, mu_fixed, ox, oy, oz, dx, dy, dz, s):
    """The majorant at distance s along the ray."""
    if row < 0:
        return mu_fixed
    return mu_fixed + cell_majorant(maj, row, ox, oy, oz, dx, dy, dz, s)[0]


@kernel(allocates=False)
def scatter_probability(wr, wg, wb, ssr, ssg, ssb, nr, ng, nb):
    """P_s of a collision (the module's docstring), the channels weighted by the
    throughput w; -1 when nothing is left to carry (every weighted channel absorbed)."""
    wr, wg, wb = abs(wr), abs(wg), abs(wb)
    num = wr * ssr + wg * ssg + wb * ssb
    den = num + wr * abs(nr) + wg * abs(ng) + wb * abs(nb)
    return num / den if den > 0.0 else -1.0


@kernel(allocates=False)
def equiangular_point(vol, stacks, p, T, objects, camera, ox, oy, oz, dx, dy, dz, t, br,
                      bg, bb, eq, ray, depth, hit, regs, count):
    """The medium at a point sampled equiangularly at distance t along path p's ray
    (throughput b at its origin), from `tracked_segment`'s `eq`: the ratio-tracking
    estimate of the transmittance to t (RGB: f prod(1 - P_s) = prod sigma_n / mu), the
    scattering coefficient (RGB) and anisotropy there, and the density with which the
    tracking would have scattered the path at t after the same null collisions (0:
    never), for the MIS weights of the two strategies.

    That density is the path-space density of null-scattering tracking (Miller et al.
    2019, "A null-scattering path integral formulation of light transport", as Cycles
    weighs its equiangular samples in heterogeneous volumes): prod(1 - P_s) over the
    null collisions before t, times mu(t) P_s(t). The factors the two strategies share
    (the exponential steps between collisions) cancel in the weights and are left out."""
    fr, fg, fb, p_null, mu = eq
    if not mu > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    sar, sag, sab, ssr, ssg, ssb, g, _, _, _ = point_medium(
        vol, stacks, p, T, objects, camera, ox + dx * t, oy + dy * t, oz + dz * t,
        dx, dy, dz, ray, depth, hit, regs, count)
    ps = scatter_probability(br * fr, bg * fg, bb * fb, ssr, ssg, ssb, mu - sar - ssr,
                             mu - sag - ssg, mu - sab - ssb)
    return (fr * p_null, fg * p_null, fb * p_null, ssr, ssg, ssb, g,
            p_null * mu * ps if ps > 0.0 else 0.0)


@kernel(allocates=False)
def tracked_transmittance(vol, stacks, r, T, objects, camera, ox, oy, oz, dx, dy, dz, t,
                          key, hit, regs, count):
    """Ratio tracking: an unbiased estimate of shadow ray r's transmittance (RGB) over
    distance t from o along d through its medium; Russian roulette once every channel
    is below 0.1."""
    maj = T[MAJORANTS]
    mu_fixed, row = majorant_parts(vol, stacks, r, maj)
    tr = tg = tb = 1.0
    if not (mu_fixed > 0.0 or row >= 0) or not math.isfinite(t):
        return tr, tg, tb
    s = 0.0
    for step in range(MAX_STEPS):
        tau = -math.log(max(1.0 - stream_uniform(key, step, 0), 1e-300))
        s, mu, passed = advance(maj, row, mu_fixed, ox, oy, oz, dx, dy, dz, s, t, tau)
        if passed:
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
            if stream_uniform(key, step, 1) >= q:
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
