"""What the shading stages add up: multiple importance sampling weights (the power
heuristic, as Cycles and pbrt use), Cycles' clamp, and the film coverage of a camera
sample, shared by the surface stage (path_vertex) and the volume stage (medium_vertex)."""
from __future__ import annotations

import math

import numpy as np

from .. import visibility
from .jit import kernel

MIS, LIGHT_ONLY, BSDF_ONLY = 0, 1, 2
# Numba freezes these into its cache; the cache's fingerprint covers every engine file
DIFFUSE_BIT, GLOSSY_BIT, TRANSMISSION_BIT, SHADOW_BIT = (
    visibility.DIFFUSE, visibility.GLOSSY, visibility.TRANSMISSION, visibility.SHADOW)
ROULETTE_START = 3
_INF = np.inf


@kernel(allocates=False)
def power_heuristic(a, b):
    if math.isinf(a):
        return 1.0
    if math.isinf(b):
        return 0.0
    a2, b2 = a * a, b * b
    return a2 / (a2 + b2) if a2 + b2 > 0.0 else 0.0


@kernel(allocates=False)
def hit_weight(mode, prev_pdf, light_pdf):
    """Weight of emission found by a BSDF-sampled ray (pdf prev_pdf; inf after a camera
    ray or a specular bounce) that light sampling reaches with light_pdf."""
    if mode == MIS:
        return power_heuristic(prev_pdf, light_pdf)
    if mode == LIGHT_ONLY:
        return 1.0 if (math.isinf(prev_pdf) or not light_pdf > 0.0) else 0.0
    return 1.0


@kernel(allocates=False)
def nee_weight(mode, light_pdf, bsdf_pdf, delta):
    """Weight of a light sample that the BSDF would have sampled with bsdf_pdf."""
    if mode == MIS:
        return 1.0 if delta else power_heuristic(light_pdf, bsdf_pdf)
    if mode == LIGHT_ONLY:
        return 1.0
    return 1.0 if (delta or not bsdf_pdf > 0.0) else 0.0


@kernel(allocates=False)
def clamp_scale(r, g, b, limit):
    """Cycles' clamp (its film_clamp_light): the factor that scales (r, g, b) so that the
    sum of its channels is at most 3 x limit. A saturated colour keeps most of its light:
    (0.5, 30, 1) under a clamp of 10 keeps 30 / 31.5 of it, where a largest-channel rule
    would keep a third."""
    s = abs(r) + abs(g) + abs(b)
    if limit > 0.0 and s > 3.0 * limit:
        return 3.0 * limit / max(s, 1e-300)   # 0 for an infinite s: see _add
    return 1.0


@kernel(allocates=False)
def _add(L, p, r, g, b, limit):
    if limit > 0.0 and max(r, g, b) == _INF:
        # an overflowed contribution (parameters near float32's limit, multiplied over
        # bounces), clamped: the limit of the clamp as those channels grow, shared by
        # them; the other channels 0
        n = float((r == _INF) + (g == _INF) + (b == _INF))
        r, g, b = (1.0 if r == _INF else 0.0), (1.0 if g == _INF else 0.0), \
            (1.0 if b == _INF else 0.0)
        s = 3.0 * limit / n
    else:
        s = clamp_scale(r, g, b, limit)
    L[p, 0] += r * s
    L[p, 1] += g * s
    L[p, 2] += b * s
    return r * s, g * s, b * s          # what was added (engine.kernels.light_tally)


@kernel(allocates=False)
def uncovered(br, bg, bb):
    """Alpha of a camera sample whose ray got through with throughput b. A camera
    sample's coverage is 1 unless its camera ray, possibly continued through transparent
    surfaces, escapes to the background with Film > Transparent or reaches a holdout
    surface (Cycles' holdout: no colour, and a hole in the alpha whatever the film
    setting); the uncovered part is then what got through: 1 - mean(b)."""
    return 1.0 - min(max((br + bg + bb) / 3.0, 0.0), 1.0)


@kernel(allocates=False)
def holdout_share(h, u_lobe, b, alpha, p, br, bg, bb):
    """A Holdout shader's share h of a material's hits (a Mix Shader with a Holdout,
    Material.holdout_weight): with probability h (u_lobe < h) the hit is a hole in the
    alpha for camera rays (through transparent surfaces too) and its path ends, no light
    for other rays, as Cycles' holdout closure; else the other shaders shade it. Returns
    (a hole, u_lobe remapped to [0, 1) for the shaders' own choice)."""
    if h > 0.0:
        if u_lobe < h:
            if b == 0 and alpha.shape[0] > 0:
                alpha[p] = uncovered(br, bg, bb)
            return True, u_lobe
        return False, min((u_lobe - h) / (1.0 - h), 1.0 - 1e-16)
    return False, u_lobe


VOLUME = 3    # the kind of a scattering in a volume (0, 1, 2: the BSDF lobes' skind)


# cont of a path whose last bounce used a budget up (ends_path): it ends at the vertex
# its ray reaches, as with the roulette's 0, and gathers what it finds there as Cycles
# gathers it on a path flagged to terminate (bsdf.layered_emission)
SPENT = -1.0


@kernel(allocates=False)
def ends_path(cfg, bounces, kind_count, kind):
    """Whether the bounce that brings a path to `bounces` bounces, and its kind (0
    diffuse, 1 glossy, 2 transmission, VOLUME) to `kind_count`, uses up a budget. As in
    Cycles (scene/integrator.cpp adds one to every limit, "so that a bounce of 0 indicates
    no global illumination, only direct illumination"), a path may take Max Bounces + 1
    bounces, and as many of each kind as its own limit + 1; the ray of the bounce that
    uses a budget up gathers only what it finds (emission and the world, weighted
    against the light sample of the vertex it left) and the path ends at the vertex it
    reaches (cont SPENT, ended as by the roulette's 0)."""
    if bounces > cfg.max_bounces:
        return True
    if kind == 0:
        return kind_count > cfg.diffuse_bounces
    if kind == 1:
        return kind_count > cfg.glossy_bounces
    if kind == 2:
        return kind_count > cfg.transmission_bounces
    return kind_count > cfg.volume_bounces


@kernel(allocates=False)
def roulette(u, br, bg, bb):
    """Cycles' Russian roulette on throughput b (its path_state_continuation_probability):
    the path survives with probability q = min(sqrt(max(b)), 1) (the square root roughly
    follows a view transform, so paths end later than with q = max(b)). Returns q when it
    survives, 0 when it ends. The decision is taken when the next ray leaves, and applied
    at the vertex it finds (`continues`): the emission that ray finds is added either way,
    as in Cycles, which decides after the closest hit, and is not lost to the roulette."""
    q = min(math.sqrt(max(br, bg, bb, 0.0)), 1.0)
    return q if u < q else 0.0


@kernel(allocates=False)
def continues(cont, p):
    """At path p's vertex, after the emission its ray found: the factor its throughput
    is divided by when it goes on (the survival probability of the roulette that let
    the ray leave, 1 without one), or 0 when the roulette or a spent budget (SPENT)
    ended it. Resets the entry."""
    q = cont[p]
    cont[p] = 1.0
    return q if q > 0.0 else 0.0


@kernel(allocates=False)
def previous_receiver(prev_pos, p):
    """The receiver (lights/tree.py) of path p's last vertex, which its light sample was
    picked for: prev_pos[p] holds its point, normal and mode (a point: no segment)."""
    return (prev_pos[p, 0], prev_pos[p, 1], prev_pos[p, 2], prev_pos[p, 3], prev_pos[p, 4],
            prev_pos[p, 5], prev_pos[p, 6], 0.0)


@kernel(allocates=False)
def keep_receiver(prev_pos, p, recv):
    """Remember recv as path p's last vertex (see `previous_receiver`)."""
    prev_pos[p, 0], prev_pos[p, 1], prev_pos[p, 2] = recv[0], recv[1], recv[2]
    prev_pos[p, 3], prev_pos[p, 4], prev_pos[p, 5] = recv[3], recv[4], recv[5]
    prev_pos[p, 6] = recv[6]
