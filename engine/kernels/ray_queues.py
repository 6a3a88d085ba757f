"""The rays the shading stages queue for the next Embree queries: the shadow rays of
next-event estimation, from a surface point (its origin offset off the surface) or a
point in a volume towards a sampled light point or direction, and each continuing
path's next ray; the caller traces them after the stage."""
from __future__ import annotations

import math

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


@kernel(allocates=False)
def push(n, p, b, ox, oy, oz, dx, dy, dz, far, cr, cg, cb, sh_path, sh_org, sh_dir, sh_far,
         sh_contrib, sh_bounce, stacks, sh_stack):
    """Write shadow ray n of path p at its bounce b (contribution c if unoccluded; the
    clamp that applies depends on b), with a copy of the path's volume stack when the
    scene has volumes. Returns n + 1."""
    sh_path[n] = p
    sh_bounce[n] = b
    sh_org[n, 0], sh_org[n, 1], sh_org[n, 2] = ox, oy, oz
    sh_dir[n, 0], sh_dir[n, 1], sh_dir[n, 2] = dx, dy, dz
    sh_far[n] = far
    sh_contrib[n, 0], sh_contrib[n, 1], sh_contrib[n, 2] = cr, cg, cb
    if sh_stack.shape[0] > 0:
        for i in range(sh_stack.shape[1]):    # element-wise: a slice copy allocates
            sh_stack[n, i] = stacks[p, i]
    return n + 1


@kernel(allocates=False)
def push_next(n, p, ox, oy, oz, dx, dy, dz, nx_path, nx_org, nx_dir):
    """Write next ray n: path p goes on from o along d. Returns n + 1."""
    nx_path[n] = p
    nx_org[n, 0], nx_org[n, 1], nx_org[n, 2] = ox, oy, oz
    nx_dir[n, 0], nx_dir[n, 1], nx_dir[n, 2] = dx, dy, dz
    return n + 1
