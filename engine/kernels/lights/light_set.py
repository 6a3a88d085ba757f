"""The whole light set for one shading point or one ray (`engine.lights.LightSet`):
pick an entry, sample it, find lamps hit by rays, and every pdf multiple importance
sampling needs. Entry k < n_lamps is lamp k (row k of L[LAMPS]); entry n_lamps + j is
emissive triangle j.

An entry is picked for a receiver (tree.py: the shading point, its normal and whether
light from below counts) by the light tree, as Cycles does by default; with the tree
off (L's tree fields empty) by its power alone (the CDF searched as
np.searchsorted(side='right')). The pdfs of lights found by rays take the receiver of
the path's previous vertex, so that they give the probability its light sample had.
`time` is the ray's shutter time in [0, 1] (0 when nothing moves): a lamp that moves
during the shutter is its slice at that time (`lamp_row`)."""
from __future__ import annotations

import math

from ...visibility import CAMERA as CAMERA_RAY
from ..cdf_search import last_at_most
from ..jit import kernel
from .area import intersect_area, pdf_area, sample_area
from .environment import pdf_environment, sample_environment
from .environment_map import (has_map, map_radiance, pdf_map, sample_environment_map,
                              seen_by_camera)
from .pack import (C_CENTER, C_POS, C_TYPE, C_VISIBILITY, C_VISIBLE, CDF, CDF_GUIDE, ENV,
                   LAMPS, LAMP_SLICES, SELECT_PDF, SLICE_OF, SUNS, TRI_E1, TRI_E2, TRI_V0,
                   TRI_VISIBILITY, T_AREA, T_DISC, T_ENV, T_ENV_MAP, T_POINT, T_SPHERE,
                   T_SUN, T_SUN_DELTA)
from .point import intersect_point, pdf_point, sample_point
from .sun import escaped_sun, pdf_sun, sample_sun
from .tree import has_tree, pick_pdf
from .tree import pick as tree_pick
from .triangles import pdf_triangle, sample_triangle, triangle_entry

_INF = math.inf


@kernel(allocates=False)
def n_entries(L):
    """len(LightSet): lamps and emissive triangles."""
    return L[SELECT_PDF].shape[0]


@kernel(allocates=False)
def n_lamps(L):
    return L[LAMPS].shape[0]


@kernel(allocates=False)
def slice_row(L, k, time):
    """Lamp k's row in L[LAMP_SLICES] at shutter time `time`: its slice min(floor(time
    K), K - 1) of K; -1 when lamp k does not move (its row is then row k of L[LAMPS])."""
    count = L[SLICE_OF][k, 1]
    if count == 0:
        return -1
    j = min(max(int(time * count), 0), count - 1)
    return L[SLICE_OF][k, 0] + j


@kernel(allocates=False)
def lamp_row(L, k, time):
    """(sliced, row): where lamp k is at shutter time `time`, row `row` of
    L[LAMP_SLICES] if sliced (it moves during the shutter), else of L[LAMPS]."""
    s = slice_row(L, k, time)
    if s >= 0:
        return True, s
    return False, k


@kernel(allocates=False)
def pick(L, u_pick):
    """np.searchsorted(cdf, u_pick, side='right').clip(0, n - 1): the first entry whose
    CDF value exceeds u_pick (-1 for an empty set, as the clip gives), found from the
    CDF's guide table (kernels.cdf_search)."""
    cdf = L[CDF]
    n = cdf.shape[0]
    if n == 0:
        return -1
    return min(last_at_most(cdf, u_pick, L[CDF_GUIDE]) + 1, n - 1)


@kernel(allocates=False)
def sample_lamp(lamps, k, px, py, pz, u0, u1):
    """Lamp k's own sample (pick probability not included):
    (wix, wiy, wiz, dist, r, g, b, pdf, delta)."""
    kind = lamps[k, C_TYPE]
    if kind == T_AREA:
        return sample_area(lamps, k, px, py, pz, u0, u1)
    if kind == T_POINT or kind == T_SPHERE or kind == T_DISC:
        return sample_point(lamps, k, px, py, pz, u0, u1)
    if kind == T_SUN or kind == T_SUN_DELTA:
        return sample_sun(lamps, k, u0, u1)
    return sample_environment(lamps, k, u0, u1)


@kernel(allocates=False)
def sample_lamp_at(L, k, px, py, pz, u1, u2, time):
    """Lamp k (k < n_lamps) sampled with (u1, u2) at shutter time `time`, its pick
    probability not included: (wix, wiy, wiz, dist, r, g, b, pdf, delta)."""
    if L[LAMPS][k, C_TYPE] == T_ENV_MAP:
        return sample_environment_map(L, u1, u2)
    sliced, row = lamp_row(L, k, time)
    table = L[LAMP_SLICES] if sliced else L[LAMPS]
    return sample_lamp(table, row, px, py, pz, u1, u2)


@kernel(allocates=False)
def select_pdf(L, k, recv, time):
    """The probability that `sample` picks entry k for the receiver `recv` (tree.py)."""
    if k < 0:
        return 0.0
    if has_tree(L):
        return pick_pdf(L, k, recv, time)
    return L[SELECT_PDF][k]


@kernel(allocates=False)
def pick_entry(L, recv, u_pick, time):
    """(k, probability): an entry picked for the receiver (by the tree, else by L[SELECT_PDF]),
    k -1 when there is none."""
    if has_tree(L):
        return tree_pick(L, recv, u_pick, time)
    k = pick(L, u_pick)
    return k, (L[SELECT_PDF][k] if k >= 0 else 0.0)


@kernel(allocates=False)
def sample_entry(L, k, px, py, pz, u1, u2, time):
    """Entry k sampled from p with (u1, u2), its pick probability not included: (wix,
    wiy, wiz, dist, r, g, b, pdf, delta, light_prim, margin) as `sample` returns them."""
    n_lamps = L[LAMPS].shape[0]
    if k < n_lamps:
        wx, wy, wz, dist, r, g, b, pdf, delta = sample_lamp_at(L, k, px, py, pz, u1, u2,
                                                               time)
        return wx, wy, wz, dist, r, g, b, pdf, delta, -1, 0.0
    wx, wy, wz, dist, r, g, b, pdf, prim, margin = sample_triangle(L, k - n_lamps, px, py,
                                                                   pz, u1, u2)
    return wx, wy, wz, dist, r, g, b, pdf, False, prim, margin


@kernel(allocates=False)
def sample(L, recv, u_pick, u1, u2, time):
    """Light sampling for one receiver (tree.py: the shading point p, its normal and
    mode) at shutter time `time`: pick an entry with u_pick, sample it with (u1, u2).
    Returns (k, wix, wiy, wiz, dist, r, g, b, pdf, delta, light_prim, margin): k the
    entry (-1 when there is none, or none lights the receiver), dist inf for suns and
    the world, pdf in solid angle including the pick probability (0 = no sample), delta
    for points and zero-angle suns, light_prim the emissive triangle's global id (-1 for
    lamps), which the shadow ray names, and margin how far short of the point it stops
    (0: a lamp, ray_queues.towards' relative stop)."""
    k, select = pick_entry(L, recv, u_pick, time)
    if k < 0:
        return k, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, False, -1, 0.0
    wx, wy, wz, dist, r, g, b, pdf, delta, prim, margin = sample_entry(
        L, k, recv[0], recv[1], recv[2], u1, u2, time)
    return k, wx, wy, wz, dist, r, g, b, pdf * select, delta, prim, margin


@kernel(allocates=False)
def entry_center(L, k, time):
    """(has_one, x, y, z): where light entry k is, at shutter time `time`, for sampling
    distances towards it (kernels/equiangular.py): a point lamp's position, an area
    lamp's centre, an emissive triangle's centroid; suns and the world have none."""
    lamps = L[LAMPS]
    if k < 0:
        return False, 0.0, 0.0, 0.0
    if k >= lamps.shape[0]:
        j = k - lamps.shape[0]
        v0, e1, e2 = L[TRI_V0], L[TRI_E1], L[TRI_E2]
        return (True, v0[j, 0] + (e1[j, 0] + e2[j, 0]) / 3.0,
                v0[j, 1] + (e1[j, 1] + e2[j, 1]) / 3.0, v0[j, 2] + (e1[j, 2] + e2[j, 2]) / 3.0)
    kind = lamps[k, C_TYPE]
    sliced, row = lamp_row(L, k, time)
    table = L[LAMP_SLICES] if sliced else lamps
    if kind == T_POINT or kind == T_SPHERE or kind == T_DISC:
        return True, table[row, C_POS], table[row, C_POS + 1], table[row, C_POS + 2]
    if kind == T_AREA:
        return True, table[row, C_CENTER], table[row, C_CENTER + 1], table[row, C_CENTER + 2]
    return False, 0.0, 0.0, 0.0


@kernel(allocates=False)
def lamp_hit(L, k, ox, oy, oz, dx, dy, dz, ray_bit, time):
    """Where a ray of kind ray_bit (engine.visibility) at shutter time `time` meets lamp
    k's surface (sphere, disc or area lamps, visible to that kind of ray): (t, r, g, b);
    t = inf where it does not."""
    lamps = L[LAMPS]
    kind = lamps[k, C_TYPE]
    if lamps[k, C_VISIBLE] == 0.0 or not int(lamps[k, C_VISIBILITY]) & ray_bit:
        return _INF, 0.0, 0.0, 0.0
    sliced, row = lamp_row(L, k, time)
    table = L[LAMP_SLICES] if sliced else L[LAMPS]
    if kind == T_AREA:
        return intersect_area(table, row, ox, oy, oz, dx, dy, dz)
    if kind == T_SPHERE or kind == T_DISC:
        return intersect_point(table, row, ox, oy, oz, dx, dy, dz)
    return _INF, 0.0, 0.0, 0.0          # not a surface (the world, suns, delta lights)


@kernel(allocates=False)
def hit_lamps(L, ox, oy, oz, dx, dy, dz, tmax, ray_bit, time):
    """The nearest lamp surface (`lamp_hit`) closer than tmax: (t, k, r, g, b); (tmax,
    -1, 0, 0, 0) when there is none. A ray passes through lamps, as in Cycles, and sees
    every lamp in front of what it hits (the shading kernels loop over `lamp_hit`)."""
    best_t = tmax
    best_k = -1
    br, bg, bb = 0.0, 0.0, 0.0
    for k in range(L[LAMPS].shape[0]):
        t, r, g, b = lamp_hit(L, k, ox, oy, oz, dx, dy, dz, ray_bit, time)
        if t < best_t:
            best_t, best_k, br, bg, bb = t, k, r, g, b
    return best_t, best_k, br, bg, bb


@kernel(allocates=False)
def entry_visibility(L, k):
    """The ray kinds that see light entry k (engine.visibility mask): a lamp's own, an
    emissive triangle's object's; every kind for k < 0."""
    lamps = L[LAMPS]
    if k < 0:
        return 31
    if k < lamps.shape[0]:
        return int(lamps[k, C_VISIBILITY])
    return int(L[TRI_VISIBILITY][k - lamps.shape[0]])


@kernel(allocates=False)
def lamp_pdf(L, k, recv, wix, wiy, wiz, t, time):
    """The pdf of one direction at shutter time `time`: solid-angle pdf, pick
    probability for the receiver recv included, of sampling wi from recv's point towards
    lamp k hit at distance t (0 when k is not a lamp)."""
    lamps = L[LAMPS]
    if k < 0 or k >= lamps.shape[0]:
        return 0.0
    select = select_pdf(L, k, recv, time)
    if select == 0.0:
        return 0.0
    px, py, pz = recv[0], recv[1], recv[2]
    kind = lamps[k, C_TYPE]
    sliced, row = lamp_row(L, k, time)
    table = L[LAMP_SLICES] if sliced else L[LAMPS]
    if kind == T_AREA:
        pdf = pdf_area(table, row, px, py, pz, wix, wiy, wiz, t)
    elif kind == T_POINT or kind == T_SPHERE or kind == T_DISC:
        pdf = pdf_point(table, row, px, py, pz, wix, wiy, wiz, t)
    elif kind == T_SUN or kind == T_SUN_DELTA:
        pdf = pdf_sun(table, row, wix, wiy, wiz)
    elif kind == T_ENV_MAP:
        pdf = pdf_map(L, wix, wiy, wiz)
    else:
        pdf = pdf_environment(lamps, k)
    return pdf * select


@kernel(allocates=False)
def mesh_pdf(L, prim, recv, qx, qy, qz, time):
    """The pdf of an emissive triangle's point for one hit: solid-angle pdf, pick
    probability for the receiver recv included, of next-event estimation from recv's
    point sampling the point q of global triangle prim (0 when that triangle is not a
    light)."""
    j = triangle_entry(L, prim)
    if j < 0:
        return 0.0
    select = select_pdf(L, L[LAMPS].shape[0] + j, recv, time)
    if select == 0.0:
        return 0.0
    return pdf_triangle(L, j, recv[0], recv[1], recv[2], qx, qy, qz) * select


@kernel(allocates=False)
def environment_pdf(L, dx, dy, dz, recv, time):
    """The world light's pdf for one escaped ray along d: pick probability for the
    receiver recv x the world light's solid-angle pdf, 0 when the world is not a
    light."""
    env = L[ENV]
    k = int(env[0])
    if k < 0:
        return 0.0
    select = select_pdf(L, k, recv, time)
    if select == 0.0:
        return 0.0
    lamps = L[LAMPS]
    if lamps[k, C_TYPE] == T_ENV_MAP:
        return pdf_map(L, dx, dy, dz) * select
    return pdf_environment(lamps, k) * select


@kernel(allocates=False)
def is_uniform_world(L, k):
    """Whether entry k is the uniform world: next-event
    estimation towards it evaluates refraction on Walter's pairs only."""
    return k >= 0 and int(L[ENV][0]) == k and L[LAMPS][k, C_TYPE] == T_ENV


@kernel(allocates=False)
def world_escaped(L, world, ray_bit, dx, dy, dz, recv, time):
    """What an escaped ray of kind ray_bit (engine.visibility) along d sees of the world,
    and the MIS pdf of that for the receiver recv of the ray's origin: (r, g, b,
    environment_pdf(L, d, recv, time)); the radiance is the
    environment map's when there is one, else the uniform world's `world` (r, g, b),
    and black for the kinds of rays the world is hidden from."""
    if not int(L[ENV][5]) & ray_bit:
        return 0.0, 0.0, 0.0, 0.0
    if has_map(L):
        if ray_bit == CAMERA_RAY:
            r, g, b = seen_by_camera(L, dx, dy, dz)
        else:
            r, g, b = map_radiance(L, dx, dy, dz)
    else:
        r, g, b = world[0], world[1], world[2]
    return r, g, b, environment_pdf(L, dx, dy, dz, recv, time)


@kernel(allocates=False)
def environment_radiance(L):
    """The uniform world light's radiance (zeros when the world is not a light or is an
    environment map)."""
    env = L[ENV]
    return env[1], env[2], env[3]


@kernel(allocates=False)
def n_suns(L):
    """The number of suns with an angular diameter (L[SUNS])."""
    return L[SUNS].shape[0]


@kernel(allocates=False)
def sun_entry(L, j):
    """The light entry of the j-th non-delta sun."""
    return L[SUNS][j]


@kernel(allocates=False)
def sun_escaped(L, j, dx, dy, dz, recv, time):
    """The j-th non-delta sun seen by an escaped ray d at shutter time `time`: (r, g, b,
    pdf) with the radiance of sun.escaped(d) and pdf = sun.pdf(None, d, None) x its pick
    probability for the receiver recv of the ray's origin."""
    k = L[SUNS][j]
    sliced, row = lamp_row(L, k, time)
    table = L[LAMP_SLICES] if sliced else L[LAMPS]
    r, g, b = escaped_sun(table, row, dx, dy, dz)
    if not (r > 0.0 or g > 0.0 or b > 0.0):
        return r, g, b, 0.0
    return r, g, b, pdf_sun(table, row, dx, dy, dz) * select_pdf(L, k, recv, time)
