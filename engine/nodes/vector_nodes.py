"""Vector nodes. Opcodes 400-499.

  VEC_MATH out, a, b, c, scale, operation        Vector Math, vector results
  VEC_MATH_VALUE out, a, b, c, scale, operation  its float results (Dot Product,
                                                 Distance, Length)
  VEC_MAPPING out, vector, location, rotation, scale, type   Mapping (MAPPING_TYPES;
                                                 rotation as Euler XYZ)
  VEC_NORMAL_MAP out, color, strength, normal    Normal Map in tangent space
                                                 (normal_map.py); normal: the surface
                                                 normal (sd->N) it falls back to
  VEC_OBJECT_NORMAL out, normal                  a world normal in the object's space,
                                                 normalize(M^T normal) (M:
                                                 context.H_OBJ_MATRIX), as the Texture
                                                 Coordinate node's Normal
"""
from __future__ import annotations

import math

import numpy as np

from ..kernels.frame import unit as _normalize
from ..kernels.jit import kernel
from .converter_nodes import MATH_OPS, math_op, safe_divide
from .normal_map import normal_map, to_object_normal

VEC_MATH = 400
VEC_MATH_VALUE = 401
VEC_MAPPING = 402
VEC_NORMAL_MAP = 403
VEC_OBJECT_NORMAL = 404

VECTOR_OPS = ("ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "CROSS_PRODUCT",
              "PROJECT", "REFLECT", "REFRACT", "FACEFORWARD", "DOT_PRODUCT", "DISTANCE",
              "LENGTH", "SCALE", "NORMALIZE", "ABSOLUTE", "POWER", "SIGN", "MINIMUM",
              "MAXIMUM", "FLOOR", "CEIL", "FRACTION", "MODULO", "WRAP", "SNAP", "SINE",
              "COSINE", "TANGENT")
VALUE_OPS = ("DOT_PRODUCT", "DISTANCE", "LENGTH")
MAPPING_TYPES = ("POINT", "TEXTURE", "VECTOR", "NORMAL")


# The per-component operations, as the Math operation that computes each component
# (-1: not per component)
_AS_MATH = np.array([MATH_OPS.index(o) if o in MATH_OPS else
                     {"FRACTION": MATH_OPS.index("FRACT")}.get(o, -1) for o in VECTOR_OPS],
                    np.int64)


@kernel(allocates=False)
def _component(op, a, b, c):
    return math_op(_AS_MATH[op], a, b, c)


@kernel(allocates=False)
def vector_math(op, ax, ay, az, bx, by, bz, cx, cy, cz, s):
    """(vector, value) of Cycles' svm_vector_math for operation VECTOR_OPS[op]."""
    if op == 5:
        return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx, 0.0
    if op == 6:
        l2 = bx * bx + by * by + bz * bz
        f = (ax * bx + ay * by + az * bz) / l2 if l2 != 0.0 else 0.0
        return bx * f, by * f, bz * f, 0.0
    if op == 7:
        nx, ny, nz = _normalize(bx, by, bz)
        d = 2.0 * (ax * nx + ay * ny + az * nz)
        return ax - d * nx, ay - d * ny, az - d * nz, 0.0
    if op == 8:
        nx, ny, nz = _normalize(bx, by, bz)
        d = nx * ax + ny * ay + nz * az
        k = 1.0 - s * s * (1.0 - d * d)
        if k < 0.0:
            return 0.0, 0.0, 0.0, 0.0
        f = s * d + math.sqrt(k)
        return s * ax - f * nx, s * ay - f * ny, s * az - f * nz, 0.0
    if op == 9:
        if bx * cx + by * cy + bz * cz < 0.0:
            return ax, ay, az, 0.0
        return -ax, -ay, -az, 0.0
    if op == 10:
        return 0.0, 0.0, 0.0, ax * bx + ay * by + az * bz
    if op == 11:
        dx, dy, dz = ax - bx, ay - by, az - bz
        return 0.0, 0.0, 0.0, math.sqrt(dx * dx + dy * dy + dz * dz)
    if op == 12:
        return 0.0, 0.0, 0.0, math.sqrt(ax * ax + ay * ay + az * az)
    if op == 13:
        return ax * s, ay * s, az * s, 0.0
    if op == 14:
        x, y, z = _normalize(ax, ay, az)
        return x, y, z, 0.0
    return (_component(op, ax, bx, cx), _component(op, ay, by, cy),
            _component(op, az, bz, cz), 0.0)


@kernel(allocates=False)
def euler_rows(rx, ry, rz):
    """The rotation matrix of Euler XYZ angles (X applied first), row-major."""
    c1, c2, c3 = math.cos(rx), math.cos(ry), math.cos(rz)
    s1, s2, s3 = math.sin(rx), math.sin(ry), math.sin(rz)
    return (c2 * c3, s1 * s2 * c3 - c1 * s3, c1 * s2 * c3 + s1 * s3,
            c2 * s3, s1 * s2 * s3 + c1 * c3, c1 * s2 * s3 - s1 * c3,
            -s2, c2 * s1, c2 * c1)


@kernel(allocates=False)
def mapping(kind, x, y, z, lx, ly, lz, rx, ry, rz, sx, sy, sz):
    m = euler_rows(rx, ry, rz)
    if kind == 1:                             # TEXTURE: the inverse of POINT
        x, y, z = x - lx, y - ly, z - lz
        tx = m[0] * x + m[3] * y + m[6] * z
        ty = m[1] * x + m[4] * y + m[7] * z
        tz = m[2] * x + m[5] * y + m[8] * z
        return safe_divide(tx, sx), safe_divide(ty, sy), safe_divide(tz, sz)
    if kind == 3:                             # NORMAL
        x, y, z = safe_divide(x, sx), safe_divide(y, sy), safe_divide(z, sz)
    else:
        x, y, z = x * sx, y * sy, z * sz
    tx = m[0] * x + m[1] * y + m[2] * z
    ty = m[3] * x + m[4] * y + m[5] * z
    tz = m[6] * x + m[7] * y + m[8] * z
    if kind == 0:
        return tx + lx, ty + ly, tz + lz
    if kind == 3:
        return _normalize(tx, ty, tz)
    return tx, ty, tz


@kernel(allocates=False)
def execute(ins, regs, hit):
    code, out = ins[0], ins[1]
    if code == VEC_MATH or code == VEC_MATH_VALUE:
        a, b, c = ins[2], ins[3], ins[4]
        x, y, z, v = vector_math(ins[6], regs[a], regs[a + 1], regs[a + 2], regs[b],
                                 regs[b + 1], regs[b + 2], regs[c], regs[c + 1], regs[c + 2],
                                 regs[ins[5]])
        if code == VEC_MATH:
            regs[out], regs[out + 1], regs[out + 2] = x, y, z
        else:
            regs[out] = v
    elif code == VEC_MAPPING:
        v, lo, ro, so = ins[2], ins[3], ins[4], ins[5]
        regs[out], regs[out + 1], regs[out + 2] = mapping(
            ins[6], regs[v], regs[v + 1], regs[v + 2], regs[lo], regs[lo + 1], regs[lo + 2],
            regs[ro], regs[ro + 1], regs[ro + 2], regs[so], regs[so + 1], regs[so + 2])
    elif code == VEC_NORMAL_MAP:
        c = ins[2]
        n = ins[4]
        regs[out], regs[out + 1], regs[out + 2] = normal_map(
            hit, regs[c], regs[c + 1], regs[c + 2], regs[ins[3]], regs[n], regs[n + 1],
            regs[n + 2])
    elif code == VEC_OBJECT_NORMAL:
        n = ins[2]
        regs[out], regs[out + 1], regs[out + 2] = to_object_normal(hit, regs[n],
                                                                   regs[n + 1], regs[n + 2])
