"""Rays cast from compiled kernels: Embree's `rtcIntersect1` and `rtcOccluded1`.

The kernels call Embree's C functions directly (Numba external functions, resolved by
LLVM to the addresses `engine.embree.library` registers), so a kernel can trace a ray
anywhere: a path's bounce, a shadow ray, an ambient-occlusion probe, a random walk.

A query fills one `RTCRayHit` (96 bytes, 16-byte aligned) that the caller provides as
two views of one scratch buffer, float32 fields and uint32 fields (the named offsets
below, from Embree's rtcore_ray.h). `ray_record()` makes one in Python;
`new_ray_record()` inside a kernel. Each thread uses its own.

Precision: Embree takes float32 rays. The caller's float64 origin is moved by `center`
(the scene's own origin shift, see `engine.accel`) before rounding; distances come back
in float32 and callers rebuild hit points in float64 from the barycentrics.
"""
from __future__ import annotations

import numpy as np
from numba import types
from numba.core import config

from ..kernels.jit import kernel
from . import library

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


def ray_record():
    """(float32 fields, uint32 fields) of one 16-byte aligned RTCRayHit."""
    raw = np.zeros(WORDS + 4, np.float32)
    start = (-raw.ctypes.data % 16) // 4
    f = raw[start:start + WORDS]
    return f, f.view(np.uint32)


@kernel
def new_ray_record():
    """ray_record() inside a kernel."""
    raw = np.zeros(WORDS + 4, np.float32)
    start = (np.int64(-np.int64(raw.ctypes.data) % 16)) // 4
    f = raw[start:start + WORDS]
    return f, f.view(np.uint32)


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
def intersect1(scene, f, w, ox, oy, oz, dx, dy, dz, tnear, tfar, time):
    """The closest hit along origin + t dir, tnear <= t <= tfar (float32 ray): returns
    (geometry id, primitive id, instance id, element, t, u, v); a miss has geometry id
    -1. For a hit inside an instance, the instance id is the instance's (or instance
    array's) geometry id in the top scene and element the instance's index in its array
    (0 for a single instance); both are -1 for a hit on the top scene's own geometry."""
    _set_ray(f, w, ox, oy, oz, dx, dy, dz, tnear, tfar, time)
    rtc_intersect1(scene, f.ctypes.data, 0)
    if w[GEOM_ID] == INVALID:
        return -1, -1, -1, -1, np.inf, 0.0, 0.0
    inst, element = -1, -1
    if w[INST_ID] != INVALID:
        inst = np.int64(w[INST_ID])
        element = 0 if w[INST_PRIM_ID] == INVALID else np.int64(w[INST_PRIM_ID])
    return (np.int64(w[GEOM_ID]), np.int64(w[PRIM_ID]), inst, element, np.float64(f[TFAR]),
            np.float64(f[HIT_U]), np.float64(f[HIT_V]))


@kernel(allocates=False)
def occluded1(scene, f, w, ox, oy, oz, dx, dy, dz, tnear, tfar, time):
    """Whether anything lies on origin + t dir, tnear <= t <= tfar."""
    _set_ray(f, w, ox, oy, oz, dx, dy, dz, tnear, tfar, time)
    rtc_occluded1(scene, f.ctypes.data, 0)
    return f[TFAR] == -np.inf


@kernel
def intersect_batch(scene, center, o, d, tmax, time, geom, prim, inst, element, t, u, v):
    """intersect1 for rays (n, 3) float64 whose origins are moved by -center; tmax and
    time (n,) (time may be empty: 0). Writes the hits' ids (-1 where missed) and t (inf
    where missed), u, v."""
    f, w = new_ray_record()
    timed = len(time) > 0
    for i in range(o.shape[0]):
        g, p, k, e, ti, ui, vi = intersect1(
            scene, f, w, o[i, 0] - center[0], o[i, 1] - center[1], o[i, 2] - center[2],
            d[i, 0], d[i, 1], d[i, 2], 0.0, tmax[i], time[i] if timed else 0.0)
        geom[i], prim[i], inst[i], element[i], t[i], u[i], v[i] = g, p, k, e, ti, ui, vi


@kernel
def occluded_batch(scene, center, o, d, tmax, time, blocked):
    """occluded1 for rays (n, 3) float64 whose origins are moved by -center."""
    f, w = new_ray_record()
    timed = len(time) > 0
    for i in range(o.shape[0]):
        blocked[i] = occluded1(
            scene, f, w, o[i, 0] - center[0], o[i, 1] - center[1], o[i, 2] - center[2],
            d[i, 0], d[i, 1], d[i, 2], 0.0, tmax[i], time[i] if timed else 0.0)
