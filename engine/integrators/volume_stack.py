"""The volumes the camera is inside, where every camera path's volume stack starts
(Cycles' volume_stack_init, which also casts a ray from the camera for this).

A ray from the camera to infinity crosses every closed mesh around the camera once more
outwards (a back face) than inwards (a front face); the world's volume, when there is
one, is at the bottom of every stack."""
from __future__ import annotations

import numpy as np

from ..kernels.volume import STACK, V_HAS

_PROBE = np.array([0.2672612419124244, 0.5345224838248488, 0.8017837257372732])
_MAX_CROSSINGS = 4096


def camera_stack(ctx, vol: np.ndarray, tri_material: np.ndarray) -> np.ndarray:
    """The start stack (STACK,) int32 of the camera at ctx.scene.camera (-1 = empty)."""
    stack = np.full(STACK, -1, np.int32)
    top = 0
    world = vol.shape[0] - 1
    if vol[world, V_HAS]:
        stack[top] = world
        top += 1
    origin = np.asarray(ctx.scene.camera.matrix, np.float64)[:3, 3].copy()
    outward = {}
    o = origin[None, :]
    d = _PROBE[None, :]
    time = np.full(1, 0.5) if ctx.has_motion else None
    travelled = 0.0
    for _ in range(_MAX_CROSSINGS):
        h = ctx.accel.intersect(o, d, np.full(1, np.inf), time)
        prim = int(h.prim[0])
        if prim < 0:
            break
        m = int(tri_material[prim])
        if vol[m, V_HAS]:
            leaving = float(np.dot(ctx.surfaces.normals(h.prim)[0], _PROBE)) > 0.0
            outward[m] = outward.get(m, 0) + (1 if leaving else -1)
        travelled += float(h.t[0])
        step = max(float(h.t[0]), 0.0) + 1e-6 * max(1.0, travelled)
        o = o + d * step
    for m, n in sorted(outward.items()):
        if n > 0 and top < STACK:
            stack[top] = m
            top += 1
    return stack
