"""The (ray, unit) pairs `engine.kernels.motion_trace.trace_moving` leaves to Embree:
grouped by unit so each unit's Embree scene gets one batch of rays in its own space, and
Embree's answers merged back into the rays' nearest hits or occlusion."""
from __future__ import annotations

import numpy as np

from .jit import kernel
from .motion_trace import unit_ray

_BIG32 = float(np.float32(1e30))


@kernel
def group_pairs(M, T, pair_ray, pair_unit, count, origins, dirs, tfar, time,
                s_ray, s_unit, o32, d32, f32, unit_start):
    """Sorts the first `count` pairs by unit (stable: rays keep their order) into
    s_ray, s_unit and writes each pair's ray as the unit's Embree scene sees it: moved
    into the object's space at the ray's time for a rigid object, as is for a deforming
    one; origin, direction and far distance (min(tfar, 1e30)) rounded to float32, as
    Embree takes them (into arrays of any float type). unit_start (U + 1,) receives each
    unit's first pair."""
    unit_obj, inverses = T.unit_obj, T.translation_inverse
    info, times, trans, quat = M.info, M.step_time, M.step_trans, M.step_quat
    stretch, linear = M.step_stretch, M.step_linear
    nu = unit_obj.shape[0]
    unit_start[:] = 0
    for k in range(count):
        unit_start[pair_unit[k] + 1] += 1
    for k in range(nu):
        unit_start[k + 1] += unit_start[k]
    fill = unit_start[:nu].copy()
    for k in range(count):
        un = pair_unit[k]
        r = pair_ray[k]
        w = fill[un]
        fill[un] += 1
        s_ray[w] = r
        s_unit[w] = un
        ox, oy, oz, dx, dy, dz = unit_ray(unit_obj, inverses, info, times, trans, quat,
                                          stretch, linear, un, time[r], origins[r, 0],
                                          origins[r, 1], origins[r, 2], dirs[r, 0],
                                          dirs[r, 1], dirs[r, 2])
        o32[w, 0], o32[w, 1], o32[w, 2] = np.float32(ox), np.float32(oy), np.float32(oz)
        d32[w, 0], d32[w, 1], d32[w, 2] = np.float32(dx), np.float32(dy), np.float32(dz)
        f32[w] = np.float32(min(tfar[r], _BIG32))


@kernel
def merge_hits(M, T, s_ray, s_unit, prim32, tfar32, u32, v32, t, prim, u, v, best, hit_unit):
    """Embree's hits of the grouped pairs merged into the rays' nearest hits, with the
    brute-force order's tie rule (at equal distance the static hit, then the lower unit,
    wins)."""
    prim_start, unit_obj = M.prim_start, T.unit_obj
    for k in range(s_ray.shape[0]):
        p = prim32[k]
        if p < 0:
            continue
        r = s_ray[k]
        un = s_unit[k]
        tt = np.float64(tfar32[k])
        if tt < best[r] or (tt == best[r] and hit_unit[r] > un):
            t[r] = tt
            prim[r] = p + prim_start[unit_obj[un]]
            u[r] = np.float64(u32[k])
            v[r] = np.float64(v32[k])
            best[r] = tt
            hit_unit[r] = un


@kernel
def merge_blocked(s_ray, prim32, blocked):
    """Embree's occlusion answers (-1: open) of the grouped pairs into blocked."""
    for k in range(s_ray.shape[0]):
        if prim32[k] != -1:
            blocked[s_ray[k]] = True
