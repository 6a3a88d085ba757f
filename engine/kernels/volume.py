"""Homogeneous volumes (participating media), compiled: the medium a path is in, the
distance it travels through it and the phase function it scatters by.

Cycles' model, read for its meaning (kernel/integrator/shade_volume.h, volume_stack.h):
a material's volume fills the inside of its closed meshes, the world's volume all space.
Each path carries a *volume stack*, the media it is inside: entering a mesh (crossing a
front face) pushes its material, leaving it (a back face) removes it; the medium at a
point is the sum of the coefficients of every entry. A material with a volume and no
surface shader has a *boundary* surface that rays cross without a bounce.

Along a segment of length t in a medium of extinction sigma_t = sigma_a + sigma_s (RGB):

- transmittance T = exp(-sigma_t t) per channel;
- emission: the radiance sigma_e integrated along the segment, exactly:
  sigma_e (1 - T) / sigma_t (sigma_e t where sigma_t = 0);
- scattering (sigma_s > 0): a distance is sampled in one colour channel, picked with
  probability proportional to the throughput times the single-scattering albedo (Cycles'
  volume_sample_channel), with the one-sample MIS pdf over the channels, sum_c w_c
  sigma_t,c exp(-sigma_t,c s); passing the segment without scattering has probability
  sum_c w_c exp(-sigma_t,c t). The throughput is multiplied by sigma_s T / pdf at a
  scattering and by T / P(pass) past it: an unbiased estimator for any colour;
- a medium that only absorbs just multiplies the throughput by T.

The packed table VOL (materials + 1 rows, the last the world's): absorption RGB,
scattering RGB, anisotropy g, emission RGB, has-a-volume flag, boundary flag (the
material has no surface shader), heterogeneous flag (the material's program computes
its coefficients per point: engine.kernels.medium_density, which also fills the
majorant and object columns; the row's coefficients are then zeros), majorant, object,
sampling method (V_METHOD: how the direct light of a segment picks distances,
medium_vertex.py).
Paths whose media are all homogeneous use this module only.
Stacks are (paths, STACK) int32 of material rows, -1 for empty slots; the world's row
sits at the bottom of every stack when it has a volume.
"""
from __future__ import annotations

import math

import numpy as np

from .frame import basis
from .jit import kernel

STACK = 8                          # media one path can be inside at once (Cycles: 4+)
V_SA, V_SS, V_G, V_EM, V_HAS, V_BOUNDARY = 0, 3, 6, 7, 10, 11
V_HET, V_MAJ, V_OBJ, V_METHOD, NV = 12, 13, 14, 15, 16
# V_METHOD: how a segment's direct light picks distances (Cycles' Volume Sampling Method)
DISTANCE, EQUIANGULAR, MULTIPLE_IMPORTANCE = 0, 1, 2
_METHODS = {"DISTANCE": DISTANCE, "EQUIANGULAR": EQUIANGULAR,
            "MULTIPLE_IMPORTANCE": MULTIPLE_IMPORTANCE}
VOLUME_OUTPUTS = ("volume_absorption", "volume_scattering", "volume_emission")
VOLUME_DIM = 1 << 25               # the volume decisions' own sampler dimensions
_INV_4PI = 1.0 / (4.0 * math.pi)


def pack_volumes(materials, world_volume) -> np.ndarray:
    """The VOL table of engine.scene materials (with .volume, .surface, .shader) and the
    world's Volume (or None); an empty (0, NV) table when nothing has a volume, so scenes without
    media skip every volume step."""
    rows = list(materials) + [None]
    if all(m.volume is None and m.surface for m in materials) and world_volume is None:
        return np.zeros((0, NV))
    vol = np.zeros((len(rows), NV))
    for i, m in enumerate(rows):
        v = world_volume if m is None else m.volume
        if m is not None and not m.surface:
            vol[i, V_BOUNDARY] = 1.0
        if v is None:
            continue
        vol[i, V_G] = min(max(float(v.anisotropy), -0.999), 0.999)
        vol[i, V_HAS] = 1.0
        vol[i, V_METHOD] = _METHODS.get(getattr(v, "sampling", ""), MULTIPLE_IMPORTANCE)
        vol[i, V_OBJ] = -1.0
        shader = getattr(m, "shader", None) if m is not None else None
        if shader is not None and any(k in shader.outputs for k in VOLUME_OUTPUTS):
            vol[i, V_HET] = 1.0       # its coefficients are its program's, not constants
            continue
        vol[i, V_SA:V_SA + 3] = np.maximum(np.asarray(v.absorption, np.float64)[:3], 0.0)
        vol[i, V_SS:V_SS + 3] = np.maximum(np.asarray(v.scattering, np.float64)[:3], 0.0)
        vol[i, V_EM:V_EM + 3] = np.maximum(np.asarray(v.emission, np.float64)[:3], 0.0)
    return vol


@kernel(allocates=False)
def volume_dim(depth, offset):
    return VOLUME_DIM + depth * 8 + offset


# --------------------------------------------------------------------------- stacks
@kernel(allocates=False)
def stack_cross(stacks, p, m, entering):
    """Path p crosses a surface of material row m: entering pushes m, leaving removes
    one entry of m (none: nothing). A full stack ignores a push."""
    K = stacks.shape[1]
    if entering:
        for k in range(K):
            if stacks[p, k] < 0:
                stacks[p, k] = m
                return
        return
    for k in range(K):
        if stacks[p, k] == m:
            for j in range(k, K - 1):
                stacks[p, j] = stacks[p, j + 1]
            stacks[p, K - 1] = -1
            return


@kernel(allocates=False)
def in_medium(stacks, p):
    return stacks.shape[0] > 0 and stacks[p, 0] >= 0


@kernel(allocates=False)
def medium(vol, stacks, p):
    """The medium at path p's position: (sigma_a RGB, sigma_s RGB, g, emission RGB),
    summed over its stack (g: the scattering-weighted mean)."""
    sar = sag = sab = ssr = ssg = ssb = er = eg = eb = 0.0
    gw = gs = 0.0
    for k in range(stacks.shape[1]):
        m = stacks[p, k]
        if m < 0:
            break
        sar += vol[m, V_SA]
        sag += vol[m, V_SA + 1]
        sab += vol[m, V_SA + 2]
        ssr += vol[m, V_SS]
        ssg += vol[m, V_SS + 1]
        ssb += vol[m, V_SS + 2]
        er += vol[m, V_EM]
        eg += vol[m, V_EM + 1]
        eb += vol[m, V_EM + 2]
        s = vol[m, V_SS] + vol[m, V_SS + 1] + vol[m, V_SS + 2]
        gw += s * vol[m, V_G]
        gs += s
    g = gw / gs if gs > 0.0 else 0.0
    return sar, sag, sab, ssr, ssg, ssb, g, er, eg, eb


@kernel(allocates=False)
def extinction(vol, stacks, p):
    sar, sag, sab, ssr, ssg, ssb, _, _, _, _ = medium(vol, stacks, p)
    return sar + ssr, sag + ssg, sab + ssb


@kernel(allocates=False)
def sample_method(vol, stacks, p):
    """The Volume Sampling Method of path p's medium: its media's own when they agree
    (those that scatter), else multiple importance (as Cycles' volume_stack_sample_method)."""
    method = -1
    for k in range(stacks.shape[1]):
        m = stacks[p, k]
        if m < 0:
            break
        if vol[m, V_SS] + vol[m, V_SS + 1] + vol[m, V_SS + 2] > 0.0 or vol[m, V_HET] != 0.0:
            mk = int(vol[m, V_METHOD])
            method = mk if method < 0 or method == mk else MULTIPLE_IMPORTANCE
    return MULTIPLE_IMPORTANCE if method < 0 else method


# --------------------------------------------------------------------------- segments
@kernel(allocates=False)
def _emitted(e, st, t):
    """Emission e per metre integrated along t through extinction st."""
    if e <= 0.0:
        return 0.0
    if st > 0.0:
        return e * (1.0 - math.exp(-st * t)) / st if math.isfinite(t) else e / st
    return e * t if math.isfinite(t) else 0.0


@kernel(allocates=False)
def _tr(st, t):
    if st <= 0.0:
        return 1.0
    return math.exp(-st * t) if math.isfinite(t) else 0.0


@kernel(allocates=False)
def segment(vol, stacks, p, br, bg, bb, t, u_channel, u_distance):
    """Path p (throughput b) travels distance t (inf: to infinity) through its medium.

    Returns (mode, scattered, t_end, new throughput RGB, extinction RGB, channel
    weights RGB, emitted radiance RGB (times b)): mode 0 no medium, 1 absorption only
    (T applied), 2 distance sampled; t_end the scattering distance or t."""
    sar, sag, sab, ssr, ssg, ssb, _, er, eg, eb = medium(vol, stacks, p)
    str_, stg, stb = sar + ssr, sag + ssg, sab + ssb
    Er = br * _emitted(er, str_, t)
    Eg = bg * _emitted(eg, stg, t)
    Eb = bb * _emitted(eb, stb, t)
    if not max(str_, stg, stb) > 0.0:
        return 0, False, t, br, bg, bb, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, Er, Eg, Eb
    if not max(ssr, ssg, ssb) > 0.0:
        return (1, False, t, br * _tr(str_, t), bg * _tr(stg, t), bb * _tr(stb, t),
                str_, stg, stb, 0.0, 0.0, 0.0, Er, Eg, Eb)
    # the channel: throughput x albedo (channels that cannot scatter are never picked)
    wr = abs(br) * (ssr / str_ if str_ > 0.0 else 0.0)
    wg = abs(bg) * (ssg / stg if stg > 0.0 else 0.0)
    wb = abs(bb) * (ssb / stb if stb > 0.0 else 0.0)
    ws = wr + wg + wb
    if not ws > 0.0:
        wr = wg = wb = 1.0 / 3.0
    else:
        wr, wg, wb = wr / ws, wg / ws, wb / ws
    u = u_channel
    if u < wr:
        sc = str_
    elif u < wr + wg:
        sc = stg
    else:
        sc = stb
    s = -math.log(max(1.0 - u_distance, 1e-300)) / sc if sc > 0.0 else math.inf
    if s < t:
        Tr, Tg, Tb = math.exp(-str_ * s), math.exp(-stg * s), math.exp(-stb * s)
        pdf = distance_pdf(str_, stg, stb, wr, wg, wb, s)
        if not pdf > 0.0:
            return 2, True, s, 0.0, 0.0, 0.0, str_, stg, stb, wr, wg, wb, Er, Eg, Eb
        return (2, True, s, br * ssr * Tr / pdf, bg * ssg * Tg / pdf, bb * ssb * Tb / pdf,
                str_, stg, stb, wr, wg, wb, Er, Eg, Eb)
    fr, fg, fb = passed(2, str_, stg, stb, wr, wg, wb, t)
    return 2, False, t, br * fr, bg * fg, bb * fb, str_, stg, stb, wr, wg, wb, Er, Eg, Eb


@kernel(allocates=False)
def distance_pdf(str_, stg, stb, wr, wg, wb, t):
    """The density of `segment`'s scattering distance at t (the one-sample mixture over
    the colour channels picked with weights w, extinctions st): sum_c w_c st_c
    exp(-st_c t). Its integral over a segment is the probability of scattering there;
    equiangular sampling is weighed against it (medium_vertex.py)."""
    return (wr * str_ * math.exp(-str_ * t) + wg * stg * math.exp(-stg * t)
            + wb * stb * math.exp(-stb * t))


@kernel(allocates=False)
def passed(mode, str_, stg, stb, wr, wg, wb, t):
    """The throughput factor of getting past distance t of a segment without scattering
    (T / P(pass) for a sampled distance, T for absorption, 1 outside media)."""
    if mode == 0:
        return 1.0, 1.0, 1.0
    Tr, Tg, Tb = _tr(str_, t), _tr(stg, t), _tr(stb, t)
    if mode == 1:
        return Tr, Tg, Tb
    P = wr * Tr + wg * Tg + wb * Tb
    if not P > 0.0:
        return 0.0, 0.0, 0.0
    return Tr / P, Tg / P, Tb / P


# --------------------------------------------------------------------------- phase
@kernel(allocates=False)
def hg_phase(g, cos_theta):
    """Henyey-Greenstein phase function of the angle between the propagation directions
    before and after scattering (g > 0 favours going on forward)."""
    d = 1.0 + g * g - 2.0 * g * cos_theta
    return (1.0 - g * g) * _INV_4PI / (max(d, 1e-12) * math.sqrt(max(d, 1e-12)))


@kernel(allocates=False)
def hg_sample(g, dx, dy, dz, u1, u2):
    """A direction scattered from propagation direction d, and its pdf."""
    if abs(g) < 1e-3:
        c = 1.0 - 2.0 * u1
    else:
        q = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1)
        c = (1.0 + g * g - q * q) / (2.0 * g)
    c = min(max(c, -1.0), 1.0)
    s = math.sqrt(max(0.0, 1.0 - c * c))
    phi = 2.0 * math.pi * u2
    tx, ty, tz, bx, by, bz = basis(dx, dy, dz)
    cp, sp = math.cos(phi) * s, math.sin(phi) * s
    wx = tx * cp + bx * sp + dx * c
    wy = ty * cp + by * sp + dy * c
    wz = tz * cp + bz * sp + dz * c
    return wx, wy, wz, hg_phase(g, c)


# --------------------------------------------------------------------------- shadows
@kernel(allocates=False)
def attenuate(vol, stacks, r, trans, t):
    """Shadow ray r's transmittance through its medium over distance t."""
    if not in_medium(stacks, r):
        return
    str_, stg, stb = extinction(vol, stacks, r)
    trans[r, 0] *= _tr(str_, t)
    trans[r, 1] *= _tr(stg, t)
    trans[r, 2] *= _tr(stb, t)
