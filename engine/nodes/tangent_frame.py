"""The frame a tangent-space Normal Map builds on at a hit, in the object's space, as
Cycles' svm_node_normal_map reads it: the UV map's tangent and the smooth normal, each
interpolated from its corners' unit vectors and left unnormalised
(primitive_surface_attribute, triangle_smooth_normal_unnormalized), and the bitangent
sign. Cycles interpolates in object space, also where it has moved a mesh into the world
(it takes each corner's normal back first); interpolated in the world they differ under
a non-uniform scale, and normalised they change how far the map tilts the normal where
the corners' normals fan out.

The tangents are stored in object space for every mesh. DRT keeps the corner normals of a
mesh that is not instanced in the world (through the object's inverse transpose), so
each is taken back to the object (by M^T) and renormalised, as Cycles takes its world
vertex normals back; an instance's corners are in its object space already."""
from __future__ import annotations

import numpy as np

from ..kernels.frame import unit
from ..kernels.jit import kernel
from .context import O_NORMAL


@kernel(allocates=False)
def _corner_normal(normals, prim, k, objects, obj, world):
    """Corner k's normal of triangle prim, unit, in object space: by object row obj's
    M^T (context.O_NORMAL) when world is set (a world-space mesh's)."""
    x, y, z = (float(normals[prim, k, 0]), float(normals[prim, k, 1]),
               float(normals[prim, k, 2]))
    if world:
        o, m = objects[obj], O_NORMAL
        x, y, z = (o[m] * x + o[m + 1] * y + o[m + 2] * z,
                   o[m + 3] * x + o[m + 4] * y + o[m + 5] * z,
                   o[m + 6] * x + o[m + 7] * y + o[m + 8] * z)
    return unit(x, y, z)


@kernel(allocates=False)
def object_frame(tangents, normals, objects, prim, inst, obj, bu, bv):
    """(tx, ty, tz, sign, nx, ny, nz) at barycentrics (bu, bv) of triangle prim: the
    object-space tangent and smooth normal, interpolated from unit corners (MikkTSpace's
    tangents are unit) and unnormalised, and the bitangent sign (+-1); the normal is 0
    without corner normals (a mesh shaded flat: the map builds on the geometric normal).
    inst >= 0: a hit on an instance (object-space corners); else obj: the mesh's object
    row, -1 for none."""
    b = (1.0 - bu - bv, bu, bv)
    tx = ty = tz = ts = 0.0
    for k in range(3):
        tx += b[k] * tangents[prim, k, 0]
        ty += b[k] * tangents[prim, k, 1]
        tz += b[k] * tangents[prim, k, 2]
        ts += b[k] * tangents[prim, k, 3]
    ts = 1.0 if ts > 0.0 else (-1.0 if ts < 0.0 else 0.0)
    world = inst < 0 and obj >= 0
    nx = ny = nz = 0.0
    if normals.shape[0] > 0:
        for k in range(3):
            x, y, z = _corner_normal(normals, prim, k, objects, obj, world)
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
