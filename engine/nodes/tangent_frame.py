"""The frame a tangent-space Normal Map builds on at a hit, in the object's space, as
Cycles' svm_node_normal_map reads it: the UV map's tangent and the smooth normal, each
interpolated from its corners' unit vectors and left unnormalised
(primitive_surface_attribute, triangle_smooth_normal_unnormalized), and the bitangent
sign. Cycles interpolates in object space, also where it has moved a mesh into the world
(it takes each corner's normal back first); interpolated in the world they differ under
a non-uniform scale, and normalised they change how far the map tilts the normal where
the corners' normals fan out.

DRT keeps a mesh that is not instanced in the world (corner tangents through the
object's matrix, corner normals through its inverse transpose, signs turned over by a
mirror), so each corner is taken back to the object and renormalised; an instance's
corners are in its object space already."""
from __future__ import annotations

import numpy as np

from ..kernels.frame import unit
from ..kernels.jit import kernel
from .context import O_NORMAL, O_TO_OBJECT, mirrors


@kernel(allocates=False)
def _corner(c, prim, k, objects, obj, world, matrix_at):
    """Corner k of triangle prim of a (T, 3, >=3) array, unit, in object space: through
    object row obj's 3 x 3 at column offset matrix_at (O_TO_OBJECT: a tangent by M^-1;
    O_NORMAL: a normal by M^T) when world is set (a world-space mesh)."""
    x, y, z = float(c[prim, k, 0]), float(c[prim, k, 1]), float(c[prim, k, 2])
    if world:
        o = objects[obj]
        stride = 4 if matrix_at == O_TO_OBJECT else 3
        x, y, z = (o[matrix_at] * x + o[matrix_at + 1] * y + o[matrix_at + 2] * z,
                   o[matrix_at + stride] * x + o[matrix_at + stride + 1] * y
                   + o[matrix_at + stride + 2] * z,
                   o[matrix_at + 2 * stride] * x + o[matrix_at + 2 * stride + 1] * y
                   + o[matrix_at + 2 * stride + 2] * z)
    return unit(x, y, z)


@kernel(allocates=False)
def object_frame(tangents, normals, objects, prim, inst, obj, bu, bv):
    """(tx, ty, tz, sign, nx, ny, nz) at barycentrics (bu, bv) of triangle prim: the
    object-space tangent and smooth normal, interpolated and unnormalised, and the
    object-space bitangent sign (+-1); the normal is 0 without corner normals (a mesh
    shaded flat: the map builds on the geometric normal). inst >= 0: a hit on an
    instance (object-space corners); else obj: the mesh's object row, -1 for none."""
    b = (1.0 - bu - bv, bu, bv)
    world = inst < 0 and obj >= 0
    tx = ty = tz = ts = 0.0
    for k in range(3):
        x, y, z = _corner(tangents, prim, k, objects, obj, world, O_TO_OBJECT)
        tx += b[k] * x
        ty += b[k] * y
        tz += b[k] * z
        ts += b[k] * tangents[prim, k, 3]
    ts = 1.0 if ts > 0.0 else (-1.0 if ts < 0.0 else 0.0)
    if world and mirrors(objects[obj]):
        ts = -ts                # the world sign holds the mirror's turn (tangents.to_world)
    nx = ny = nz = 0.0
    if normals.shape[0] > 0:
        for k in range(3):
            x, y, z = _corner(normals, prim, k, objects, obj, world, O_NORMAL)
            nx += b[k] * x
            ny += b[k] * y
            nz += b[k] * z
    return tx, ty, tz, ts, nx, ny, nz


@kernel
def object_frames(tangents, normals, objects, prim, inst, obj, bary):
    """`object_frame` for n hits given as arrays (bary: (n, 2)): (n, 7) float64 rows of
    (tangent, sign, normal), for NumPy callers that fill hit rows (engine.aov)."""
    n = prim.shape[0]
    out = np.zeros((n, 7))
    for i in range(n):
        f = object_frame(tangents, normals, objects, prim[i], inst[i], obj[i], bary[i, 0],
                         bary[i, 1])
        for k in range(7):
            out[i, k] = f[k]
    return out
