"""The rays the shading stages queue for the next Embree queries: the shadow rays of
next-event estimation, from a surface point (its origin offset off the surface) or a
point in a volume towards a sampled light point or direction, and each continuing
path's next ray; the caller traces them after the stage."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .jit import kernel


@kernel(allocates=False)
def towards(sox, soy, soz, px, py, pz, wx, wy, wz, dist, margin, scene_radius):
    """Direction and length of the shadow ray from origin so (for the shading point p)
    towards direction w for `dist` (inf: a sun or the world): to the sampled point,
    stopping short of it by `margin` (emissive triangles) and a relative 2e-5."""
    sdx, sdy, sdz = wx, wy, wz
    if math.isfinite(dist):
        tx = px + wx * dist - sox
        ty = py + wy * dist - soy
        tz = pz + wz * dist - soz
        seg = math.sqrt(tx * tx + ty * ty + tz * tz)
        if seg > 0.0:
            sdx, sdy, sdz = tx / seg, ty / seg, tz / seg
        far = min(seg * (1.0 - 2e-5), seg - margin)
    else:
        far = scene_radius * 4.0
    return sdx, sdy, sdz, max(far, 0.0)


class ShadowQueue(NamedTuple):
    """The shadow rays one bounce queues: each one's path, origin, direction, length,
    contribution if unoccluded, the bounce of the vertex it left (the clamp that applies)
    and a copy of the path's volume stack (no rows without media)."""
    path: np.ndarray
    org: np.ndarray
    dir: np.ndarray
    far: np.ndarray
    contrib: np.ndarray
    bounce: np.ndarray
    stack: np.ndarray


class NextQueue(NamedTuple):
    """The continuing paths' next rays: each one's path, origin and direction."""
    path: np.ndarray
    org: np.ndarray
    dir: np.ndarray


@kernel(allocates=False)
def push(q, n, p, b, ox, oy, oz, dx, dy, dz, far, cr, cg, cb, stacks):
    """Write shadow ray n of path p at its bounce b (contribution c if unoccluded; the
    clamp that applies depends on b) to the ShadowQueue q, with a copy of the path's
    volume stack when the scene has volumes. Returns n + 1."""
    q.path[n] = p
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
def push_next(q, n, p, ox, oy, oz, dx, dy, dz):
    """Write next ray n to the NextQueue q: path p goes on from o along d. Returns n + 1."""
    q.path[n] = p
    q.org[n, 0], q.org[n, 1], q.org[n, 2] = ox, oy, oz
    q.dir[n, 0], q.dir[n, 1], q.dir[n, 2] = dx, dy, dz
    return n + 1
