"""The rays the shading stages queue for the next Embree queries: the shadow rays of
next-event estimation, from a surface point or a point in a volume towards a sampled
light point or direction, and each continuing path's next ray; the caller traces them
after the stage. A ray leaving a surface starts on it (engine.kernels.ray_origin) and
names what it must not hit (engine.embree.self_hits): the global primitive and place
it leaves (-1, -1 from a point in a volume)."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .jit import kernel


@kernel(allocates=False)
def towards(sox, soy, soz, px, py, pz, wx, wy, wz, dist, margin):
    """Direction and length of the shadow ray from origin so (for the shading point p)
    towards direction w for `dist` (inf: a sun or the world, and the ray is endless, so
    a volume that fills the world lets nothing through, as in Cycles): to the sampled
    point, stopping `margin` short of it (a point on an emissive triangle, which the ray
    also names: push's light_prim, Cycles' ls->prim), or a relative 2e-5 short where
    margin is 0 (a lamp's)."""
    sdx, sdy, sdz = wx, wy, wz
    if math.isfinite(dist):
        tx = px + wx * dist - sox
        ty = py + wy * dist - soy
        tz = pz + wz * dist - soz
        seg = math.sqrt(tx * tx + ty * ty + tz * tz)
        if seg > 0.0:
            sdx, sdy, sdz = tx / seg, ty / seg, tz / seg
        far = seg - margin if margin > 0.0 else seg * (1.0 - 2e-5)
    else:
        far = math.inf
    return sdx, sdy, sdz, max(far, 0.0)


class ShadowQueue(NamedTuple):
    """The shadow rays one bounce queues: each one's path, origin, direction, length,
    contribution if unoccluded, the bounce of the vertex it left (the clamp that applies)
    and a copy of the path's volume stack (no rows without media); skip: the primitive
    and place it leaves, and the emissive triangle and place it goes to (n, 4; -1:
    none)."""
    path: np.ndarray
    org: np.ndarray
    dir: np.ndarray
    far: np.ndarray
    contrib: np.ndarray
    bounce: np.ndarray
    stack: np.ndarray
    skip: np.ndarray


class NextQueue(NamedTuple):
    """The continuing paths' next rays: each one's path, origin and direction, and the
    primitive and place it leaves (n, 2; -1: none)."""
    path: np.ndarray
    org: np.ndarray
    dir: np.ndarray
    skip: np.ndarray


def shadow_queue(n: int, stacks: bool, stack_size: int) -> ShadowQueue:
    """An empty ShadowQueue for n rays (volume stacks copied only if `stacks`)."""
    return ShadowQueue(np.empty(n, np.int64), np.empty((n, 3)), np.empty((n, 3)),
                       np.empty(n), np.empty((n, 3)), np.empty(n, np.int64),
                       np.full((n if stacks else 0, stack_size), -1, np.int32),
                       np.empty((n, 4), np.int64))


def next_queue(n: int) -> NextQueue:
    """An empty NextQueue for n rays."""
    return NextQueue(np.empty(n, np.int64), np.empty((n, 3)), np.empty((n, 3)),
                     np.empty((n, 2), np.int64))


@kernel(allocates=False)
def push(q, n, p, b, ox, oy, oz, dx, dy, dz, far, cr, cg, cb, stacks, prim=-1, inst=-1,
         light_prim=-1):
    """Write shadow ray n of path p at its bounce b (contribution c if unoccluded; the
    clamp that applies depends on b), leaving primitive prim of place inst (-1: none)
    towards the emissive triangle light_prim (-1: a lamp; emissive triangles are never
    instanced), to the ShadowQueue q, with a copy of the path's volume stack when the
    scene has volumes. Returns n + 1."""
    q.path[n] = p
    q.skip[n, 0], q.skip[n, 1], q.skip[n, 2], q.skip[n, 3] = prim, inst, light_prim, -1
    q.bounce[n] = b
    q.org[n, 0], q.org[n, 1], q.org[n, 2] = ox, oy, oz
    q.dir[n, 0], q.dir[n, 1], q.dir[n, 2] = dx, dy, dz
    q.far[n] = far
    q.contrib[n, 0], q.contrib[n, 1], q.contrib[n, 2] = cr, cg, cb
    if q.stack.shape[0] > 0:
        for i in range(q.stack.shape[1]):     # element-wise: a slice copy allocates
            q.stack[n, i] = stacks[p, i]
    return n + 1


@kernel(allocates=False)
def push_next(q, n, p, ox, oy, oz, dx, dy, dz, prim=-1, inst=-1):
    """Write next ray n to the NextQueue q: path p goes on from o along d, leaving
    primitive prim of place inst (-1: none). Returns n + 1."""
    q.path[n] = p
    q.skip[n, 0], q.skip[n, 1] = prim, inst
    q.org[n, 0], q.org[n, 1], q.org[n, 2] = ox, oy, oz
    q.dir[n, 0], q.dir[n, 1], q.dir[n, 2] = dx, dy, dz
    return n + 1
