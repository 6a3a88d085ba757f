"""Shadow rays from smooth-shaded triangles, as Cycles starts them (its shadow_ray_offset
and shadow_ray_smooth_surface_offset; the idea is Hanika's "Hacking the Shadow
Terminator", Ray Tracing Gems II).

A smooth-shaded mesh is lit by its interpolated normal, so light may come from under a
triangle's own plane while it is above the smooth normal: by the lit silhouette of a
coarse sphere, say. A shadow ray leaving the flat triangle there would run into the mesh.
Cycles instead starts it from the curved surface the normals describe: the hit point
lifted along the interpolated normal by the height of a parabolic patch through the
corners (its parabola's coefficients are the corner normals' differences projected on the
edges), bounded by each corner's tangent plane. The lift fades in as the light nears the
triangle's plane: fully when the light is under it, not at all once the cosine to the
plane exceeds the object's Shadow Terminator > Geometry Offset (0.1 by default; 0 turns
it off). A shadow ray lifted towards a light under the plane may still hit its own
triangle (Cycles then does not name it); any other starts on its triangle and names
it, as every ray does (engine.embree.self_hits).

`cutoff` holds each triangle's Geometry Offset, 0 where there is nothing to lift: flat
shading, a moving object's triangles (their corners are placed per ray elsewhere), an
object with the offset off. An instance's lift is worked out in its object space, from
the mesh's own corners and normals, and placed in the world by the instance's matrix, as
Cycles lifts the triangles of objects whose transform is not applied.
"""
from __future__ import annotations

import numpy as np

from ..nodes.context import O_NORMAL, to_world_direction
from .frame import dot
from .jit import kernel


@kernel(inline="always")
def _corner(positions, corners, c, prim, k):
    """Corner k's position (row corners[prim, k] of positions) and (raw, unflipped)
    normal."""
    i = corners[prim, k]
    return (positions[i, 0], positions[i, 1], positions[i, 2], np.float64(c[prim, k, 0]),
            np.float64(c[prim, k, 1]), np.float64(c[prim, k, 2]))


@kernel
def smooth_lift(positions, corners, c, prim, u, v, px, py, pz, gx, gy, gz):
    """The vector from the hit p at barycentrics (u, v) of triangle prim to the curved
    surface its corner normals c describe, on the side of g (the geometric normal facing
    the light's side): the interpolated normal times the patch's height there."""
    a0x, a0y, a0z, n0x, n0y, n0z = _corner(positions, corners, c, prim, 0)
    a1x, a1y, a1z, n1x, n1y, n1z = _corner(positions, corners, c, prim, 1)
    a2x, a2y, a2z, n2x, n2y, n2z = _corner(positions, corners, c, prim, 2)
    b0, b1, b2 = 1.0 - u - v, u, v         # the corners' weights
    nx = b0 * n0x + b1 * n1x + b2 * n2x    # not normalised (as Cycles)
    ny = b0 * n0y + b1 * n1y + b2 * n2y
    nz = b0 * n0z + b1 * n1z + b2 * n2z
    # the parabolic patch
    a = dot(n2x - n0x, n2y - n0y, n2z - n0z, a0x - a2x, a0y - a2y, a0z - a2z)
    b = dot(n2x - n1x, n2y - n1y, n2z - n1z, a1x - a2x, a1y - a2y, a1z - a2z)
    cc = dot(n1x - n0x, n1y - n0y, n1z - n0z, a1x - a0x, a1y - a0y, a1z - a0z)
    h = a * b0 * (b0 - 1.0) + (a + b + cc) * b0 * b1 + b * b1 * (b1 - 1.0)
    # each corner's tangent plane, as an envelope
    s = 1.0 if dot(nx, ny, nz, gx, gy, gz) > 0.0 else -1.0
    e0 = max(s * dot(a1x - a0x, a1y - a0y, a1z - a0z, n0x, n0y, n0z),
             s * dot(a2x - a0x, a2y - a0y, a2z - a0z, n0x, n0y, n0z), 0.0)
    e1 = max(s * dot(a0x - a1x, a0y - a1y, a0z - a1z, n1x, n1y, n1z),
             s * dot(a2x - a1x, a2y - a1y, a2z - a1z, n1x, n1y, n1z), 0.0)
    e2 = max(s * dot(a0x - a2x, a0y - a2y, a0z - a2z, n2x, n2y, n2z),
             s * dot(a1x - a2x, a1y - a2y, a1z - a2z, n2x, n2y, n2z), 0.0)
    e0 = max(s * dot(a0x - px, a0y - py, a0z - pz, n0x, n0y, n0z) + e0, 0.0)
    e1 = max(s * dot(a1x - px, a1y - py, a1z - pz, n1x, n1y, n1z) + e1, 0.0)
    e2 = max(s * dot(a2x - px, a2y - py, a2z - pz, n2x, n2y, n2z) + e2, 0.0)
    if s > 0.0:
        h = max(min(e0, e1, e2), 0.5 * h)
    else:
        h = min(-min(e0, e1, e2), 0.5 * h)
    return nx * h, ny * h, nz * h


@kernel(allocates=False)
def _placed_lift(positions, corners, c, o, prim, u, v, fx, fy, fz):
    """smooth_lift of an instance's triangle (object row o): in object space, at the hit's
    object-space point, towards the facing normal f taken into object space (O_NORMAL),
    and the lift placed in the world by the instance's matrix."""
    w = 1.0 - u - v
    i0, i1, i2 = corners[prim, 0], corners[prim, 1], corners[prim, 2]
    qx = w * positions[i0, 0] + u * positions[i1, 0] + v * positions[i2, 0]
    qy = w * positions[i0, 1] + u * positions[i1, 1] + v * positions[i2, 1]
    qz = w * positions[i0, 2] + u * positions[i1, 2] + v * positions[i2, 2]
    n = O_NORMAL
    hx = o[n] * fx + o[n + 1] * fy + o[n + 2] * fz
    hy = o[n + 3] * fx + o[n + 4] * fy + o[n + 5] * fz
    hz = o[n + 6] * fx + o[n + 7] * fy + o[n + 8] * fz
    lx, ly, lz = smooth_lift(positions, corners, c, prim, u, v, qx, qy, qz, hx, hy, hz)
    return to_world_direction(o, lx, ly, lz)


@kernel(allocates=False)
def shadow_origin(positions, corners, corner_normals, cutoff, objects, prim, inst, u, v, px,
                  py, pz, gx, gy, gz, nx, ny, nz, wx, wy, wz):
    """The origin of a shadow ray from hit p (barycentrics (u, v) of triangle prim, whose
    corners are rows corners[prim] of positions (engine.surface.SurfaceBuilder);
    geometric normal g and the surface's own shading normal n, both facing the incoming
    ray) towards the light direction w (unit), and the primitive it names (prim, or -1
    when it may hit its own triangle). inst: the hit's instance, its row of `objects`
    (-1: a mesh in world space)."""
    off = cutoff[prim] if cutoff.shape[0] > 0 else 0.0
    if off > 0.0:
        nl = dot(nx, ny, nz, wx, wy, wz)
        sign = 1.0 if nl >= 0.0 else -1.0      # towards a light under n: the back side
        nl = abs(nl)
        fx, fy, fz = gx * sign, gy * sign, gz * sign
        ngl = dot(fx, fy, fz, wx, wy, wz)
        if nl < off:
            amount = min(max(2.0 - (ngl + nl) / off, 0.0), 1.0)
        else:
            amount = min(max(1.0 - ngl / off, 0.0), 1.0)
        if amount > 0.0:
            if inst < 0:
                lx, ly, lz = smooth_lift(positions, corners, corner_normals, prim, u, v, px,
                                         py, pz, fx, fy, fz)
            else:
                lx, ly, lz = _placed_lift(positions, corners, corner_normals, objects[inst],
                                          prim, u, v, fx, fy, fz)
            px, py, pz = px + lx * amount, py + ly * amount, pz + lz * amount
            if not ngl > 0.0:
                return px, py, pz, -1    # the light is under the plane: its own triangle counts
    return px, py, pz, prim
