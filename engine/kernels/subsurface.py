"""Subsurface scattering: Cycles' random walk (Chiang, Kutz and Burley 2016, "Practical
and Controllable Subsurface Scattering for Production Path Tracing"), compiled, with the
rays cast from the kernel (engine.embree.rays).

The material below its surface is a medium (the facts are Cycles', closure/bssrdf.h and
integrator/subsurface_random_walk.h):

- coefficients per colour channel from the surface albedo A (the base colour) and the
  mean free path d (Radius x Scale): sigma_t = 1 / (d (1 - g)) and a single-scattering
  albedo alpha(A, g) from Chiang et al.'s fit, chosen so that the walk's total
  reflectance is about A. Random Walk scales d by 1 / (4 pi) first; Random Walk (Skin)
  by sqrt(3 (1 - alpha')), alpha' solving the dipole's Rd(alpha') = A;
- the walk's throughput starts at the path's over A (scattering puts the albedo back);
  a channel of alpha below MIN_ALPHA is raised to it, its throughput scaled down alike;
- each step picks a channel in proportion to throughput x alpha, samples a distance in
  it, and combines the channels by the balance heuristic (one-sample MIS); up to
  MAX_BOUNCES steps, the path is lost if it has not left by then;
- directions after the first: the Henyey-Greenstein phase function (anisotropy g in
  [0, 0.9]), or Dwivedi's guided distribution towards the entry plane's normal N (or,
  once the first ray has seen the opposite side, away from it), the three combined by
  the balance heuristic; after SIMILARITY steps the walk goes on isotropically with the
  similarity relation's sigma_s (1 - g);
- the walk meets only the surface of the object it entered: other objects' triangles
  are passed through.

`walk` returns where it left (a hit of its object, from inside) and the throughput.
engine/kernels/subsurface_vertex.py turns that into a path vertex. The walk's random
numbers are hashed from the path's key (any number of steps).
"""
from __future__ import annotations

import math

from ..embree.rays import intersect1, new_ray_record
from ..sampling.hashing import stream_key, stream_uniform
from .cdf_search import bisect_last
from .frame import dot, to_world
from .jit import kernel
from .volume import hg_phase, hg_sample

MAX_BOUNCES = 256          # Cycles' BSSRDF_MAX_BOUNCES
SIMILARITY = 9             # steps before the walk turns isotropic (Cycles' level)
MIN_ALPHA = 0.2            # Cycles' floor of the single-scattering albedo
THROUGHPUT_EPSILON = 1e-6  # a walk whose throughput fell below this ends
MAX_SKIPS = 64             # other objects' surfaces one step may pass through
WALK_DIM = 1 << 27         # the walk's own random stream (hashed: any count)
INV_2PI = 0.5 / math.pi


@kernel(allocates=False)
def walk_key(pkey, index, depth):
    """The random stream of path (pkey, index)'s walk at wavefront step `depth`."""
    return stream_key(pkey, index, WALK_DIM, depth)


# --------------------------------------------------------------------------- coefficients
# The coefficients in g (c0 .. c7) of the albedo fit's six terms (Cycles' remap)
FIT_A = (1.8260523782, -1.28451056436, -1.79904629312, 9.19393289202, -22.8215585862,
         32.0234874259, -23.6264803333, 7.21067002658)
FIT_B = (0.0, 31.1491581433, -201.847017512, 841.576016723, -2018.09288505,
         2731.71560286, -1935.41424244, 559.009054474)
FIT_C = (1.09686102424, -0.394704063468, 1.05258115941, -8.83963712726, 28.8643230661,
         -46.8802913581, 38.5402837518, -12.7181042538)
FIT_D = (0.496310210422, 0.360146581622, -2.15139309747, 17.8896899217, -55.2984010333,
         82.065982243, -58.5106008578, 15.8478295021)
FIT_E = (0.0, 76.7316253952, -594.356773233, 2448.8834203, -5576.68528998,
         7116.60171912, -4763.54467887, 1303.5318055)
FIT_F = (2.40602999408, -2.51814844609, 9.18494908356, -79.2191708682, 259.082868209,
         -403.613804597, 302.85712436, -87.4370473567)


@kernel(allocates=False)
def _poly7(g, c):
    """c[0] + c[1] g + ... + c[7] g^7 (Horner)."""
    return c[0] + g * (c[1] + g * (c[2] + g * (c[3] + g * (c[4] + g * (c[5] + g * (
        c[6] + g * c[7]))))))


@kernel(allocates=False)
def remap(albedo, d, g):
    """(sigma_t, alpha) of one channel: the medium whose walk reflects about `albedo`,
    for mean free path d and anisotropy g (Chiang et al. 2016, with Cycles' fit in g)."""
    A = _poly7(g, FIT_A)
    B = 4.98511194385 + 0.127355959438 * math.exp(_poly7(g, FIT_B))
    C = _poly7(g, FIT_C)
    D = _poly7(g, FIT_D)
    E = 4.23190299701 + 0.00310603949088 * math.exp(_poly7(g, FIT_E))
    F = _poly7(g, FIT_F)
    a = max(albedo, 0.0)
    blend = a ** 0.25
    alpha = ((1.0 - blend) * A * math.atan(B * a) ** C
             + blend * D * math.atan(E * a) ** F)
    alpha = min(max(alpha, 0.0), 0.999999)
    return 1.0 / (max(d, 1e-16) * (1.0 - g)), alpha


@kernel(allocates=False)
def dipole_rd(alpha_prime, four_thirds_a):
    """The dipole's total diffuse reflectance for reduced albedo alpha_prime."""
    s = math.sqrt(3.0 * (1.0 - alpha_prime))
    return 0.5 * alpha_prime * (1.0 + math.exp(-four_thirds_a * s)) * math.exp(-s)


@kernel(allocates=False)
def skin_radius_scale(albedo, ior):
    """Random Walk (Skin)'s factor on the radius: sqrt(3 (1 - alpha')), alpha' the
    reduced albedo whose dipole reflectance is `albedo` (12 bisection steps, as Cycles)."""
    inv = 1.0 / ior
    f_dr = inv * (-1.440 * inv + 0.710) + 0.668 + 0.0636 * ior
    four_thirds_a = (4.0 / 3.0) * (1.0 + f_dr) / (1.0 - f_dr)
    if albedo < 1e-4:
        ap = 0.0
    elif albedo >= 0.995:
        ap = 0.999999
    else:
        lo, hi, ap = 0.0, 1.0, 0.5
        for _ in range(12):
            ap = 0.5 * (lo + hi)
            if dipole_rd(ap, four_thirds_a) < albedo:
                lo = ap
            else:
                hi = ap
    return math.sqrt(3.0 * (1.0 - ap))


@kernel(allocates=False)
def walk_radius(radius, albedo, ior, skin):
    """The mean free path the walk uses for one channel of Radius x Scale `radius`."""
    if skin:
        return radius * skin_radius_scale(albedo, ior)
    return radius * 0.25 / math.pi


@kernel(allocates=False)
def diffusion_length(alpha):
    """Dwivedi's diffusion length for single-scattering albedo alpha (d'Eon and
    Krivanek 2020, eq. 67)."""
    return 1.0 / math.sqrt(1.0 - alpha ** (2.44294 - 0.0215813 * alpha + 0.578637 / alpha))


# --------------------------------------------------------------------------- local rays
@kernel(allocates=False)
def object_of(mesh_start, prim):
    """The mesh (engine.accel's order) global triangle `prim` belongs to."""
    return bisect_last(mesh_start, prim, 0, mesh_start.shape[0] - 1)


@kernel(allocates=False)
def local_hit(rays, rec, mesh, inst, ox, oy, oz, dx, dy, dz, tmax, time, skip=-1,
              tnear=0.0):
    """The first hit within [tnear, tmax] of the surface of mesh `mesh` placed as instance
    `inst` (-1: not instanced) along o + t d, passing other objects' triangles and
    triangle `skip` of the mesh (the one the ray leaves; -1: none). rays: (the scene's
    engine.embree.rays.Target, each mesh's first global triangle); rec: a RayRecord of
    it. Returns (prim, inst, t, u, v); prim -1 when nothing is hit."""
    tg, mesh_start = rays
    center, geom_base, geom_row = tg.center, tg.geom_base, tg.geom_row
    for _ in range(MAX_SKIPS):
        g, pr, k, e, t, u, v = intersect1(tg.handle, rec, ox - center[0], oy - center[1],
                                          oz - center[2], dx, dy, dz, tnear, tmax, time,
                                          skip, inst)
        if g < 0:
            return -1, -1, math.inf, 0.0, 0.0
        owner = k if k >= 0 else g
        prim = pr + geom_base[owner]
        row = geom_row[owner]
        placed = row + e if row >= 0 else -1
        if placed == inst and object_of(mesh_start, prim) == mesh:
            return prim, placed, t, u, v
        tnear = t + max(t * 1e-6, 1e-30)
    return -1, -1, math.inf, 0.0, 0.0


# --------------------------------------------------------------------------- the walk
@kernel(allocates=False)
def _pick(u, w0, w1, w2):
    """The channel u picks with weights w (normalised; equal where all are 0)."""
    s = w0 + w1 + w2
    if not s > 0.0:
        w0 = w1 = w2 = 1.0 / 3.0
    else:
        w0, w1, w2 = w0 / s, w1 / s, w2 / s
    c = 0 if u < w0 else (1 if u < w0 + w1 else 2)
    return c, w0, w1, w2


@kernel(allocates=False)
def _from_cosine(nx, ny, nz, cos_theta, u):
    """The direction at angle acos(cos_theta) from n, at azimuth 2 pi u."""
    s = math.sqrt(max(0.0, 1.0 - cos_theta * cos_theta))
    phi = 2.0 * math.pi * u
    return to_world(s * math.cos(phi), s * math.sin(phi), cos_theta, nx, ny, nz)


@kernel(allocates=False)
def walk(rays, rec, key, time, mesh, inst, entry, px, py, pz, dx, dy, dz, nx, ny, nz,
         albedo, radius, g, beta, guided_walk):
    """Walk from p along d into the surface, the surface's normal at the entry being n
    (outward); the first ray names the triangle `entry` it leaves (-1: none, p is
    inside already). albedo, radius (walk_radius), beta: per channel (3-tuples); g the
    anisotropy (clamped to [0, 0.9]); guided_walk False: the classic walk alone (a test's
    second estimator). Returns (left, prim, inst, u, v, dx, dy, dz, throughput r, g, b):
    the exit hit and the direction it was reached along."""
    g = min(max(g, 0.0), 0.9)
    st0, al0 = remap(albedo[0], radius[0], g)
    st1, al1 = remap(albedo[1], radius[1], g)
    st2, al2 = remap(albedo[2], radius[2], g)
    t0 = beta[0] / albedo[0] if albedo[0] != 0.0 else 0.0
    t1 = beta[1] / albedo[1] if albedo[1] != 0.0 else 0.0
    t2 = beta[2] / albedo[2] if albedo[2] != 0.0 else 0.0
    if al0 < MIN_ALPHA:
        t0, al0 = t0 * al0 / MIN_ALPHA, MIN_ALPHA
    if al1 < MIN_ALPHA:
        t1, al1 = t1 * al1 / MIN_ALPHA, MIN_ALPHA
    if al2 < MIN_ALPHA:
        t2, al2 = t2 * al2 / MIN_ALPHA, MIN_ALPHA
    dl = diffusion_length(max(al0, max(al1, al2)))
    if not dl > 1.0:
        return False, -1, -1, 0.0, 0.0, dx, dy, dz, 0.0, 0.0, 0.0
    phase_log = math.log((dl + 1.0) / (dl - 1.0))
    guided_fraction = 1.0 - max(0.5, g ** 0.125) if guided_walk else 0.0
    # the similarity relation's coefficients, used after SIMILARITY steps
    ss0, ss1, ss2 = st0 * al0, st1 * al1, st2 * al2
    sr0, sr1, sr2 = ss0 * (1.0 - g), ss1 * (1.0 - g), ss2 * (1.0 - g)
    ox, oy, oz = px, py, pz
    have_opposite = False
    opposite = 0.0
    prim, placed, hu, hv = -1, -1, 0.0, 0.0
    for step in range(MAX_BOUNCES):
        if step <= SIMILARITY:
            gs, gf = g, guided_fraction
            e0, e1, e2, s0, s1, s2 = st0, st1, st2, ss0, ss1, ss2
        else:
            gs, gf = 0.0, (0.75 if guided_walk else 0.0)
            e0, e1, e2 = st0 - ss0 + sr0, st1 - ss1 + sr1, st2 - ss2 + sr2
            s0, s1, s2 = sr0, sr1, sr2
        c, q0, q1, q2 = _pick(stream_uniform(key, step, 0), abs(t0 * al0), abs(t1 * al1),
                              abs(t2 * al2))
        sample_st = e0 if c == 0 else (e1 if c == 1 else e2)
        back_fraction = 0.0
        fwd_factor = back_factor = 0.0
        fwd_stretch = back_stretch = 1.0
        if step > 0:
            guided = stream_uniform(key, step, 1) < gf
            backward = False
            if have_opposite:
                x = min(max(-dot(ox - px, oy - py, oz - pz, nx, ny, nz), 0.0), opposite)
                back_fraction = 1.0 / (1.0 + math.exp((opposite - 2.0 * x) / dl))
                backward = stream_uniform(key, step, 2) < back_fraction
            u3, u4 = stream_uniform(key, step, 3), stream_uniform(key, step, 4)
            if guided:
                cos_t = dl - (dl + 1.0) * math.exp(-u3 * phase_log)
                if backward:
                    cos_t = -cos_t
                ndx, ndy, ndz = _from_cosine(nx, ny, nz, cos_t, u4)
                hg = hg_phase(gs, dot(dx, dy, dz, ndx, ndy, ndz))
            else:
                ndx, ndy, ndz, hg = hg_sample(gs, dx, dy, dz, u3, u4)
                cos_t = dot(ndx, ndy, ndz, nx, ny, nz)
            dx, dy, dz = ndx, ndy, ndz
            fwd_factor = INV_2PI / ((dl - cos_t) * phase_log) / hg
            back_factor = INV_2PI / ((dl + cos_t) * phase_log) / hg
            fwd_stretch = 1.0 - cos_t / dl
            back_stretch = 1.0 + cos_t / dl
            if guided:
                sample_st *= back_stretch if backward else fwd_stretch
        t = -math.log(max(1.0 - stream_uniform(key, step, 5), 1e-300)) / sample_st
        reach = max(t, 10.0 / min(e0, min(e1, e2))) if step == 0 else t
        k_prim, k_inst, t_hit, k_u, k_v = local_hit(rays, rec, mesh, inst, ox, oy, oz,
                                                    dx, dy, dz, reach, time,
                                                    entry if step == 0 else -1)
        hit = k_prim >= 0
        if step == 0 and hit:
            # the first ray looks ten mean free paths ahead for the opposite side
            have_opposite = True
            opposite = -dot(ox + t_hit * dx - px, oy + t_hit * dy - py,
                            oz + t_hit * dz - pz, nx, ny, nz)
            hit = t_hit < t
        if hit:
            t = t_hit
            prim, placed, hu, hv = k_prim, k_inst, k_u, k_v
        ox, oy, oz = ox + t * dx, oy + t * dy, oz + t * dz
        T0, T1, T2 = math.exp(-e0 * t), math.exp(-e1 * t), math.exp(-e2 * t)
        p0 = T0 if hit else e0 * T0
        p1 = T1 if hit else e1 * T1
        p2 = T2 if hit else e2 * T2
        if step > 0:
            p0 = _guided_pdf(p0, e0, t, hit, gf, have_opposite, back_fraction,
                             fwd_stretch, back_stretch, fwd_factor, back_factor)
            p1 = _guided_pdf(p1, e1, t, hit, gf, have_opposite, back_fraction,
                             fwd_stretch, back_stretch, fwd_factor, back_factor)
            p2 = _guided_pdf(p2, e2, t, hit, gf, have_opposite, back_fraction,
                             fwd_stretch, back_stretch, fwd_factor, back_factor)
        denom = q0 * p0 + q1 * p1 + q2 * p2
        if not denom > 0.0:
            return False, -1, -1, 0.0, 0.0, dx, dy, dz, 0.0, 0.0, 0.0
        if hit:
            t0, t1, t2 = t0 * T0 / denom, t1 * T1 / denom, t2 * T2 / denom
            return True, prim, placed, hu, hv, dx, dy, dz, t0, t1, t2
        t0, t1, t2 = t0 * s0 * T0 / denom, t1 * s1 * T1 / denom, t2 * s2 * T2 / denom
        if max(t0, max(t1, t2)) < THROUGHPUT_EPSILON:
            break
    return False, -1, -1, 0.0, 0.0, dx, dy, dz, 0.0, 0.0, 0.0


@kernel(allocates=False)
def _guided_pdf(classic, sigma_t, t, hit, gf, have_opposite, back_fraction, fwd_stretch,
                back_stretch, fwd_factor, back_factor):
    """One channel's density of a step after the first, over the classic, forward-guided
    and backward-guided strategies (balance heuristic)."""
    if gf <= 0.0:
        return classic
    s = fwd_stretch * sigma_t
    fwd = math.exp(-s * t) * (1.0 if hit else s)
    guided = fwd * fwd_factor
    if have_opposite:
        s = back_stretch * sigma_t
        back = math.exp(-s * t) * (1.0 if hit else s)
        guided = guided * (1.0 - back_fraction) + back * back_factor * back_fraction
    return classic * (1.0 - gf) + guided * gf


@kernel
def walk_batch(rays, keys, mesh, start, direction, normal, albedo, radius, g, guided_walk,
               out):
    """`walk` from one start point along one direction (normal: the entry's) once per
    key, for tests: out (n, 5) gets (left, throughput r, g, b, exit triangle) per walk,
    the path's throughput on entry the albedo (as the lobe's weight makes it), so the
    mean throughput is the reflectance."""
    rec = new_ray_record(rays[0])
    for i in range(keys.shape[0]):
        left, prim, _, _, _, _, _, _, tr, tg, tb = walk(
            rays, rec, keys[i], 0.0, mesh, -1, -1, start[0], start[1], start[2], direction[0],
            direction[1], direction[2], normal[0], normal[1], normal[2], albedo, radius, g,
            albedo, guided_walk)
        out[i, 0] = 1.0 if left else 0.0
        out[i, 1], out[i, 2], out[i, 3] = tr, tg, tb
        out[i, 4] = prim
