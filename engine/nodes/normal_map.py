"""Cycles' tangent-space Normal Map node (kernel/svm/tex_coord.h, svm_node_normal_map),
for one hit: the colour's 2c - 1, its x and y scaled by Strength and its z mixed from 1 by
Strength clamped to [0, 1], taken in the frame of the UV map's tangent T, the bitangent
sign x N x T and the normal N it builds on, in the object's space, and the result taken
back to the world as a normal (by the inverse transpose of the object's matrix). As in
Cycles, T and N are interpolated in object space and not normalised (tangent_frame):
with a non-uniform scale a frame built in the world differs, and normalised they tilt
the map less where the corners' normals fan out.

N is the interpolated smooth normal, but on a face shaded flat the face's own normal
(Cycles' sd->Ng there), also on the flat faces Displacement and Bump moved, whose
shading normal is the undisplaced one (engine.scene TriangleMesh.flat_faces). Where the
mesh has no tangents the map gives the surface normal it is handed (nx, ny, nz: the
hit's, or the one a Displacement's bump set, Cycles' sd->N)."""
from __future__ import annotations

import math

from ..kernels.frame import cross as _cross, unit as _unit
from ..kernels.jit import kernel
from .context import (H_BACKFACING, H_FLAT_FACE, H_MAP_NORMAL, H_NG, H_OBJ_MATRIX,
                      H_TANGENT, H_TANGENT_SIGN)


@kernel(allocates=False)
def _cofactors(hit):
    """The rows of the cofactor matrix C = det(M) M^-T of the hit's object matrix M
    (context.H_OBJ_MATRIX, rows a, b, c): b x c, c x a, a x b; and det(M)."""
    m = H_OBJ_MATRIX
    ax, ay, az = hit[m], hit[m + 1], hit[m + 2]
    bx, by, bz = hit[m + 3], hit[m + 4], hit[m + 5]
    cx, cy, cz = hit[m + 6], hit[m + 7], hit[m + 8]
    r0 = _cross(bx, by, bz, cx, cy, cz)
    r1 = _cross(cx, cy, cz, ax, ay, az)
    r2 = _cross(ax, ay, az, bx, by, bz)
    det = ax * r0[0] + ay * r0[1] + az * r0[2]
    return r0, r1, r2, det


@kernel(allocates=False)
def to_object_normal(hit, x, y, z):
    """A world normal in the hit object's space: M^T (x, y, z) normalised (Cycles'
    object_inverse_normal_transform, safe_normalize), M = context.H_OBJ_MATRIX."""
    m = H_OBJ_MATRIX
    return _unit(hit[m] * x + hit[m + 3] * y + hit[m + 6] * z,
                 hit[m + 1] * x + hit[m + 4] * y + hit[m + 7] * z,
                 hit[m + 2] * x + hit[m + 5] * y + hit[m + 8] * z)


@kernel(allocates=False)
def normal_map(hit, cr, cg, cb, strength, nx, ny, nz):
    """The Normal Map's normal at the hit (the module's docstring), unit length and
    facing as the surface normal (nx, ny, nz) faces, that normal where the map fails."""
    sign = hit[H_TANGENT_SIGN]
    if sign == 0.0:
        return nx, ny, nz
    back = hit[H_BACKFACING] > 0.0
    r0, r1, r2, det = _cofactors(hit)
    if det == 0.0 or not math.isfinite(det):
        return nx, ny, nz
    flip = 1.0 if det > 0.0 else -1.0
    ox, oy, oz = hit[H_MAP_NORMAL], hit[H_MAP_NORMAL + 1], hit[H_MAP_NORMAL + 2]
    if hit[H_FLAT_FACE] != 0.0 or (ox == 0.0 and oy == 0.0 and oz == 0.0):
        qx, qy, qz = hit[H_NG], hit[H_NG + 1], hit[H_NG + 2]
        if back:                # the maths on the normal as the mesh has it
            qx, qy, qz = -qx, -qy, -qz
        ox, oy, oz = to_object_normal(hit, qx, qy, qz)
    ux, uy, uz = hit[H_TANGENT], hit[H_TANGENT + 1], hit[H_TANGENT + 2]
    bx, by, bz = _cross(ox, oy, oz, ux, uy, uz)
    bx, by, bz = sign * bx, sign * by, sign * bz
    cx, cy = 2.0 * (cr - 0.5) * strength, 2.0 * (cg - 0.5) * strength
    cz = 1.0 + (2.0 * (cb - 0.5) - 1.0) * min(max(strength, 0.0), 1.0)
    x, y, z = _unit(cx * ux + cy * bx + cz * ox, cx * uy + cy * by + cz * oy,
                    cx * uz + cy * bz + cz * oz)
    # back to the world as a normal: M^-T = C / det
    x, y, z = _unit(flip * (r0[0] * x + r0[1] * y + r0[2] * z),
                    flip * (r1[0] * x + r1[1] * y + r1[2] * z),
                    flip * (r2[0] * x + r2[1] * y + r2[2] * z))
    if back:
        x, y, z = -x, -y, -z
    if x == 0.0 and y == 0.0 and z == 0.0:
        return nx, ny, nz
    return x, y, z
