"""A hit on a hair strand (engine.curves), rebuilt in float64: the point and the normal
of the round Catmull-Rom curve Embree intersected.

The strand's surface is swept by a sphere of radius r(u) moving along the spline c(u);
Embree reports the segment parameter u of the sphere the ray touches and the distance t.
The normal there points from the sphere's centre c(u) to the hit point, so the point is
rebuilt on that sphere, c(u) + r(u) n, with n the direction from c(u) to the ray's point
at t (the float32 distance fixes only the direction, not the point). The surface has no
inside for shading: a hit is always on the front, its normal turned to face the ray, as
Cycles shades thick curves. Shading normal = geometric normal."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .frame import dot
from .jit import kernel
from ..nodes.hash import hash_uint2, uint_to_float


class PackedCurves(NamedTuple):
    """Every strand of a scene (engine.curves.pack_curves)."""
    span: np.ndarray     # (2,) int64: the segments' first global primitive id, and the end
    points: np.ndarray   # (P, 4) float64 control points: x, y, z, radius (world space)
    first: np.ndarray    # (S,) int64 each segment's first control point (4 from it)
    # (S, 4) what the Hair Info node reads: the intercepts of the segment's two keys,
    # its strand's length and Random
    info: np.ndarray


@kernel(inline="always")
def is_curve(C, prim):
    """Whether global primitive `prim` is a strand's segment."""
    return prim >= C.span[0] and prim < C.span[1]


@kernel(inline="always")
def _basis(u):
    """The uniform Catmull-Rom weights of the 4 control points at u, and their derivatives
    (the segment runs from the second point, u = 0, to the third, u = 1)."""
    u2, u3 = u * u, u * u * u
    return (0.5 * (-u3 + 2.0 * u2 - u), 0.5 * (3.0 * u3 - 5.0 * u2 + 2.0),
            0.5 * (-3.0 * u3 + 4.0 * u2 + u), 0.5 * (u3 - u2),
            0.5 * (-3.0 * u2 + 4.0 * u - 1.0), 0.5 * (9.0 * u2 - 10.0 * u),
            0.5 * (-9.0 * u2 + 8.0 * u + 1.0), 0.5 * (3.0 * u2 - 2.0 * u))


@kernel(allocates=False)
def curve_point(C, seg, u):
    """The spline of segment `seg` at u: (centre, radius, tangent dc/du)."""
    i = C.first[seg]
    P = C.points
    w0, w1, w2, w3, d0, d1, d2, d3 = _basis(min(max(u, 0.0), 1.0))
    cx = w0 * P[i, 0] + w1 * P[i + 1, 0] + w2 * P[i + 2, 0] + w3 * P[i + 3, 0]
    cy = w0 * P[i, 1] + w1 * P[i + 1, 1] + w2 * P[i + 2, 1] + w3 * P[i + 3, 1]
    cz = w0 * P[i, 2] + w1 * P[i + 1, 2] + w2 * P[i + 2, 2] + w3 * P[i + 3, 2]
    r = w0 * P[i, 3] + w1 * P[i + 1, 3] + w2 * P[i + 2, 3] + w3 * P[i + 3, 3]
    tx = d0 * P[i, 0] + d1 * P[i + 1, 0] + d2 * P[i + 2, 0] + d3 * P[i + 3, 0]
    ty = d0 * P[i, 1] + d1 * P[i + 1, 1] + d2 * P[i + 2, 1] + d3 * P[i + 3, 1]
    tz = d0 * P[i, 2] + d1 * P[i + 1, 2] + d2 * P[i + 2, 2] + d3 * P[i + 3, 2]
    return cx, cy, cz, max(r, 0.0), tx, ty, tz


@kernel(allocates=False)
def curve_surface(C, center, prim, u, ox, oy, oz, t, dx, dy, dz):
    """The hit of the ray o + t d on segment prim (a global id) at parameter u.
    Returns (position, geometric normal facing the ray, shading normal (the same),
    front (always), offset scale), as engine.kernels.surface.rebuild does for triangles."""
    seg = prim - C.span[0]
    cx, cy, cz, r, tx, ty, tz = curve_point(C, seg, u)
    qx, qy, qz = ox + t * dx - cx, oy + t * dy - cy, oz + t * dz - cz
    ln = math.sqrt(qx * qx + qy * qy + qz * qz)
    if ln > 0.0 and ln < math.inf:
        nx, ny, nz = qx / ln, qy / ln, qz / ln
    else:
        # no usable point (a hit rebuilt without its ray): the side facing the ray
        lt = math.sqrt(tx * tx + ty * ty + tz * tz)
        nx, ny, nz = -dx, -dy, -dz
        if lt > 0.0:
            k = dot(nx, ny, nz, tx, ty, tz) / (lt * lt)
            px, py, pz = nx - k * tx, ny - k * ty, nz - k * tz
            lp = math.sqrt(px * px + py * py + pz * pz)
            if lp > 0.0:
                nx, ny, nz = px / lp, py / lp, pz / lp
    px, py, pz = cx + r * nx, cy + r * ny, cz + r * nz
    if dot(nx, ny, nz, dx, dy, dz) > 0.0:
        nx, ny, nz = -nx, -ny, -nz            # a ray from inside the tube
    # the control points' magnitude about the scene's centre bounds the float32 error of
    # what Embree intersected (engine.surface)
    i = C.first[seg]
    scale = 0.0
    for k in range(4):
        for a in range(3):
            scale = max(scale, abs(C.points[i + k, a] - center[a]))
    return px, py, pz, nx, ny, nz, nx, ny, nz, True, scale + r


@kernel(allocates=False)
def strand_randoms(first_index, out):
    """The Hair Info node's Random of strands first_index, first_index + 1, ... of an
    object: Cycles' hash_uint2_to_float(index, 0)."""
    for i in range(out.shape[0]):
        out[i] = uint_to_float(hash_uint2(first_index + i, 0))


@kernel(allocates=False)
def strand_info(C, prim, u, ix, iy, iz):
    """What the Hair Info node reads at a hit on primitive prim at parameter u, seen
    from the direction i (towards the ray's origin): (is strand, intercept, length,
    thickness, random, tangent normal); zeros on a triangle, as in Cycles. Intercept and
    thickness run linearly between the segment's two keys, as Cycles interpolates curve
    attributes; the tangent normal is i made perpendicular to the spline's tangent."""
    if not is_curve(C, prim):
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    seg = prim - C.span[0]
    info = C.info
    intercept = info[seg, 0] + u * (info[seg, 1] - info[seg, 0])
    i = C.first[seg]
    r = C.points[i + 1, 3] + u * (C.points[i + 2, 3] - C.points[i + 1, 3])
    _, _, _, _, tx, ty, tz = curve_point(C, seg, u)
    lt2 = tx * tx + ty * ty + tz * tz
    k = dot(ix, iy, iz, tx, ty, tz) / lt2 if lt2 > 0.0 else 0.0
    nx, ny, nz = ix - k * tx, iy - k * ty, iz - k * tz
    ln = math.sqrt(nx * nx + ny * ny + nz * nz)
    if ln > 0.0:
        nx, ny, nz = nx / ln, ny / ln, nz / ln
    return 1.0, intercept, info[seg, 2], 2.0 * r, info[seg, 3], nx, ny, nz
