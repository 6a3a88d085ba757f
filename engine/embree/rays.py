"""Rays cast from compiled kernels: Embree's `rtcIntersect1` and `rtcOccluded1`.

The kernels call Embree's C functions directly (Numba external functions, resolved by
LLVM to the addresses `engine.embree.library` registers), so a kernel can trace a ray
anywhere: a path's bounce, a shadow ray, an ambient-occlusion probe, a random walk.

A query fills one `RTCRayHit` (96 bytes, 16-byte aligned) that the caller provides as
two views of one scratch buffer, float32 fields and uint32 fields (the named offsets
below, from Embree's rtcore_ray.h), with the query's arguments and context beside it
(engine.embree.self_hits): a `RayRecord`, made by `ray_record()` in Python or
`new_ray_record()` inside a kernel, for one scene (a `Target`). Each thread uses its own.

A ray may name up to two primitives it must not hit (engine.embree.self_hits): the one
it leaves and, for a shadow ray, the emissive triangle it goes to (DRT's global ids,
-1: none). A ray that names none is traced without the filter.

Precision: Embree takes float32 rays. The caller's float64 origin is moved by `center`
(the scene's own origin shift, see `engine.accel`) before rounding; distances come back
in float32 and callers rebuild hit points in float64 from the barycentrics.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import types
from numba.core import config

from ..kernels.jit import kernel
from . import library
from . import self_hits as S

if config.DISABLE_JIT:
    # kernels run as plain Python (NUMBA_DISABLE_JIT=1, for stepping through them): the
    # same two calls through ctypes
    rtc_intersect1 = library.load().rtcIntersect1
    rtc_occluded1 = library.load().rtcOccluded1
else:
    library.register_kernel_symbols()
    _sig = types.void(types.uintp, types.uintp, types.uintp)
    rtc_intersect1 = types.ExternalFunction("drt_rtcIntersect1", _sig)
    rtc_occluded1 = types.ExternalFunction("drt_rtcOccluded1", _sig)

# RTCRayHit, in 4-byte words
ORG_X, ORG_Y, ORG_Z, TNEAR = 0, 1, 2, 3
DIR_X, DIR_Y, DIR_Z, TIME = 4, 5, 6, 7
TFAR, MASK, RAY_ID, FLAGS = 8, 9, 10, 11
NG_X, NG_Y, NG_Z, HIT_U, HIT_V = 12, 13, 14, 15, 16
PRIM_ID, GEOM_ID, INST_ID, INST_PRIM_ID = 17, 18, 19, 20
WORDS = 24
INVALID = np.uint32(0xFFFFFFFF)
FAR = np.float32(1e30)       # a ray without end: Embree wants a finite tfar


class Target(NamedTuple):
    """A committed Embree scene as the kernels trace it: its handle, the centre its
    geometry is placed relative to (engine.accel), the self-hit filter's address, and
    each top-scene geometry's first global primitive id and first object-table row
    (-1: not an instance array) for the filter (engine.embree.self_hits), and the top
    scene's curve geometry id (-1: none)."""
    handle: int
    center: np.ndarray
    filter: int
    geom_base: np.ndarray
    geom_row: np.ndarray
    curve_geom: int


class RayRecord(NamedTuple):
    """One thread's query memory: the RTCRayHit as float32 and uint32 words (f, w), and
    the query's arguments and context (q, int64 words, engine.embree.self_hits)."""
    f: np.ndarray
    w: np.ndarray
    q: np.ndarray


def target(handle, center, geom_base, geom_row, curve_geom=-1) -> Target:
    """The Target of a committed scene (the filter compiled on first use)."""
    return Target(int(handle), np.asarray(center, np.float64), S.filter_address(),
                  np.ascontiguousarray(geom_base, np.int64),
                  np.ascontiguousarray(geom_row, np.int64), int(curve_geom))


@kernel(allocates=False)
def _arguments(q, tg):
    """Fill the query's arguments and context (engine.embree.self_hits)."""
    q[S.Q_FLAGS] = S.FLAGS_WORD
    q[S.Q_CONTEXT] = np.int64(q.ctypes.data) + 8 * S.Q_CONTEXT_AT
    q[S.Q_FILTER] = 0
    q[S.Q_FILTER_ADDRESS] = np.int64(tg.filter)
    q[S.Q_CURVE_GEOM] = tg.curve_geom
    c = S.Q_CONTEXT_AT
    q[c] = -1                  # instID, instPrimID: invalid until Embree sets them
    q[c + S.C_SKIP_PRIM] = q[c + S.C_SKIP_ROW] = -1
    q[c + S.C_LIGHT_PRIM] = q[c + S.C_LIGHT_ROW] = -1
    q[c + S.C_BASE] = np.int64(tg.geom_base.ctypes.data)
    q[c + S.C_ROW] = np.int64(tg.geom_row.ctypes.data)


def ray_record(tg: Target) -> RayRecord:
    """One 16-byte aligned RTCRayHit, with its query memory for scene tg."""
    raw = np.zeros(WORDS + 4, np.float32)
    start = (-raw.ctypes.data % 16) // 4
    f = raw[start:start + WORDS]
    q = np.zeros(S.Q_WORDS, np.int64)
    _arguments(q, tg)
    return RayRecord(f, f.view(np.uint32), q)


@kernel
def new_ray_record(tg):
    """ray_record() inside a kernel."""
    raw = np.zeros(WORDS + 4, np.float32)
    start = (np.int64(-np.int64(raw.ctypes.data) % 16)) // 4
    f = raw[start:start + WORDS]
    q = np.zeros(S.Q_WORDS, np.int64)
    _arguments(q, tg)
    return RayRecord(f, f.view(np.uint32), q)


@kernel(allocates=False)
def _name(q, skip_prim, skip_row, light_prim, light_row):
    """The primitives the ray must not hit (-1: none); the filter only if it names one."""
    c = S.Q_CONTEXT_AT
    q[c + S.C_SKIP_PRIM], q[c + S.C_SKIP_ROW] = skip_prim, skip_row
    q[c + S.C_LIGHT_PRIM], q[c + S.C_LIGHT_ROW] = light_prim, light_row
    q[S.Q_FILTER] = q[S.Q_FILTER_ADDRESS] if skip_prim >= 0 or light_prim >= 0 else 0


@kernel(allocates=False)
def inside(u, v):
    """Barycentrics (u, v) moved at most INSIDE of their sum into the triangle.

    A ray leaving a hit starts on it and names its triangle (engine.embree.self_hits);
    from a point within float32 precision of an edge it could still meet the neighbour
    across that edge at distance 0. Cycles tests for such points (its
    ray_triangle_intersect_self: every barycentric at least FLT_EPSILON of their sum)
    and lifts their rays' origins 256 float32 ulps off the plane; every triangle hit
    reported here already passes that test, so no origin needs lifting. (A path kernel
    that tested each origin itself ran 16 % slower per vertex.) Hits further inside are
    returned unchanged."""
    u, v = max(u, S.INSIDE), max(v, S.INSIDE)
    s = u + v
    if s > 1.0 - S.INSIDE:
        f = (1.0 - S.INSIDE) / s
        return u * f, v * f
    return u, v


@kernel(allocates=False)
def _set_ray(f, w, ox, oy, oz, dx, dy, dz, tnear, tfar, time):
    f[ORG_X] = np.float32(ox)
    f[ORG_Y] = np.float32(oy)
    f[ORG_Z] = np.float32(oz)
    f[TNEAR] = np.float32(tnear)
    f[DIR_X] = np.float32(dx)
    f[DIR_Y] = np.float32(dy)
    f[DIR_Z] = np.float32(dz)
    f[TIME] = np.float32(time)
    f[TFAR] = min(np.float32(tfar), FAR)
    w[MASK] = INVALID
    w[RAY_ID] = 0
    w[FLAGS] = 0
    w[GEOM_ID] = INVALID
    w[INST_ID] = INVALID
    w[INST_PRIM_ID] = INVALID


@kernel(allocates=False)
def intersect1(scene, rec, ox, oy, oz, dx, dy, dz, tnear, tfar, time, skip_prim=-1,
               skip_row=-1, light_prim=-1, light_row=-1):
    """The closest hit along origin + t dir, tnear <= t <= tfar (float32 ray), on no
    primitive the ray names (skip_prim of place skip_row, light_prim of place light_row;
    -1: none), a triangle's barycentrics moved `inside` it: returns
    (geometry id, primitive id, instance id, element, t, u, v); a miss has geometry id
    -1. For a hit inside an instance, the instance id is the instance's (or instance
    array's) geometry id in the top scene and element the instance's index in its array
    (0 for a single instance); both are -1 for a hit on the top scene's own geometry."""
    f, w = rec.f, rec.w
    _set_ray(f, w, ox, oy, oz, dx, dy, dz, tnear, tfar, time)
    _name(rec.q, skip_prim, skip_row, light_prim, light_row)
    rtc_intersect1(scene, f.ctypes.data, rec.q.ctypes.data)
    if w[GEOM_ID] == INVALID:
        return -1, -1, -1, -1, np.inf, 0.0, 0.0
    inst, element = -1, -1
    if w[INST_ID] != INVALID:
        inst = np.int64(w[INST_ID])
        element = 0 if w[INST_PRIM_ID] == INVALID else np.int64(w[INST_PRIM_ID])
    g = np.int64(w[GEOM_ID])
    u, v = np.float64(f[HIT_U]), np.float64(f[HIT_V])
    if inst >= 0 or g != rec.q[S.Q_CURVE_GEOM]:      # a triangle's
        u, v = inside(u, v)
    return g, np.int64(w[PRIM_ID]), inst, element, np.float64(f[TFAR]), u, v


@kernel(allocates=False)
def occluded1(scene, rec, ox, oy, oz, dx, dy, dz, tnear, tfar, time, skip_prim=-1,
              skip_row=-1, light_prim=-1, light_row=-1):
    """Whether anything but the primitives the ray names lies on origin + t dir, tnear
    <= t <= tfar."""
    f = rec.f
    _set_ray(f, rec.w, ox, oy, oz, dx, dy, dz, tnear, tfar, time)
    _name(rec.q, skip_prim, skip_row, light_prim, light_row)
    rtc_occluded1(scene, f.ctypes.data, rec.q.ctypes.data)
    return f[TFAR] == -np.inf


@kernel
def intersect_batch(tg, o, d, tmax, time, skip, geom, prim, inst, element, t, u, v):
    """intersect1 on Target tg for rays (n, 3) float64 whose origins are moved by
    -tg.center; tmax and time (n,) (time may be empty: 0); skip (n, 2) or (n, 4): the
    global primitive and place each ray leaves, and for a shadow ray the ones it goes to
    (empty: none). Writes the hits' ids (-1 where missed) and t (inf where missed), u,
    v."""
    rec = new_ray_record(tg)
    scene, center = tg.handle, tg.center
    timed = len(time) > 0
    named = skip.shape[0] > 0
    both = named and skip.shape[1] > 2
    for i in range(o.shape[0]):
        g, p, k, e, ti, ui, vi = intersect1(
            scene, rec, o[i, 0] - center[0], o[i, 1] - center[1], o[i, 2] - center[2],
            d[i, 0], d[i, 1], d[i, 2], 0.0, tmax[i], time[i] if timed else 0.0,
            skip[i, 0] if named else -1, skip[i, 1] if named else -1,
            skip[i, 2] if both else -1, skip[i, 3] if both else -1)
        geom[i], prim[i], inst[i], element[i], t[i], u[i], v[i] = g, p, k, e, ti, ui, vi


@kernel
def occluded_batch(tg, o, d, tmax, time, skip, blocked):
    """occluded1 on Target tg for rays (n, 3) float64 whose origins are moved by
    -tg.center; skip (n, 4): the global primitive and place each ray leaves and the one
    it goes to (empty: none)."""
    rec = new_ray_record(tg)
    scene, center = tg.handle, tg.center
    timed = len(time) > 0
    named = skip.shape[0] > 0
    for i in range(o.shape[0]):
        blocked[i] = occluded1(
            scene, rec, o[i, 0] - center[0], o[i, 1] - center[1], o[i, 2] - center[2],
            d[i, 0], d[i, 1], d[i, 2], 0.0, tmax[i], time[i] if timed else 0.0,
            skip[i, 0] if named else -1, skip[i, 1] if named else -1,
            skip[i, 2] if named else -1, skip[i, 3] if named else -1)
