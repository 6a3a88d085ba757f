"""Moving objects, compiled: where a moving triangle is at one ray's time, as Embree
traces it (engine.accel): a rigid object's transform at that time
(`engine.motion.RigidMotion.at`, same formulas, Embree's quaternion decomposition), and a
deforming object's vertices interpolated between its time steps.

`pack_motion(accel)` describes the accelerator's moving objects, in its global triangle
order, as one `PackedMotion` of NumPy arrays with the same types for every scene (empty
when nothing moves), so one compilation serves every scene. Hot kernels unpack it into
its arrays once and pass those on: a tuple passed into an inlined function costs a copy
per call.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..motion import NLERP_DOT
from .cdf_search import bisect_last
from .frame import cross
from .jit import kernel

RIGID, DEFORM = 0, 1

# columns of PackedMotion.info
I_KIND, I_STEP0, I_STEPS, I_VERT0, I_NVERTS = range(5)


class PackedMotion(NamedTuple):
    prim_start: np.ndarray    # int64 (n + 1,) first global triangle id of each moving
    #                           object, then the total triangle count
    info: np.ndarray          # int64 (n, 5) kind (RIGID / DEFORM), first motion step row
    #                           (rigid), step count (evenly spaced over [0, 1]), first
    #                           vertex row, vertices per step
    step_trans: np.ndarray    # float64 (S, 3) translation at each step (rigid objects)
    step_quat: np.ndarray     # float64 (S, 4) rotation (w, x, y, z), shorter arc between steps
    step_upper: np.ndarray    # float64 (S, 3, 3) upper triangular scale and skew
    verts: np.ndarray         # float64 (V, 3) object-space vertices (rigid) or every time
    #                           step's world vertices, one step after the other (deform)
    tris: np.ndarray          # int64 (T, 3) per moving triangle (global id - static count)
    #                           its object-local vertex indices


def pack_motion(accel) -> PackedMotion:
    """The moving objects of `accel` (engine.accel.Accelerator) packed for the kernels."""
    objs = accel.moving
    n = len(objs)
    prim_start = np.empty(n + 1, np.int64)
    info = np.zeros((n, 5), np.int64)
    trans, quats, upper, verts, tris = [], [], [], [], []
    step, vert = 0, 0
    for i, obj in enumerate(objs):
        mesh, motion = obj.mesh, obj.motion
        prim_start[i] = obj.prim_offset
        tris.append(np.asarray(mesh.triangles, np.int64).reshape(-1, 3))
        k = len(motion.times)
        if obj.rigid:
            tr, q, up = motion._decomposed
            info[i] = (RIGID, step, k, vert, len(mesh.positions))
            trans.append(tr)
            quats.append(q)
            upper.append(up)
            verts.append(np.asarray(mesh.positions, np.float64).reshape(-1, 3))
            step += k
            vert += len(mesh.positions)
        else:
            nv = motion.positions.shape[1]
            info[i] = (DEFORM, 0, k, vert, nv)
            verts.append(np.asarray(motion.positions, np.float64).reshape(-1, 3))
            vert += nv * k
    prim_start[n] = accel.total_triangles if n else accel.moving_start

    def cat(parts, shape, dtype):
        if not parts:
            return np.zeros(shape, dtype)
        if len(parts) == 1:                  # one object's own array, not a copy
            return np.ascontiguousarray(parts[0], dtype=dtype)
        return np.ascontiguousarray(np.concatenate(parts), dtype=dtype)

    return PackedMotion(prim_start, info, cat(trans, (0, 3), np.float64),
                        cat(quats, (0, 4), np.float64), cat(upper, (0, 3, 3), np.float64),
                        cat(verts, (0, 3), np.float64), cat(tris, (0, 3), np.int64))


@kernel(inline="always")
def step_of(k, t):
    """(segment a in [0, k - 2], fraction f in [0, 1] of the way to step a + 1) of time
    t over k evenly spaced steps from 0 to 1 (Embree's time segments); (0, 0) for one
    step."""
    if k < 2:
        return 0, 0.0
    x = min(max(t, 0.0), 1.0) * (k - 1)
    a = min(int(x), k - 2)
    return a, min(max(x - a, 0.0), 1.0)


@kernel(inline="always")
def object_of(M, prim):
    """The moving object (row of M.info) that global triangle `prim` belongs to, by
    bisection of the objects' first triangle ids; -1 for a static triangle."""
    starts = M.prim_start
    n = starts.shape[0] - 1
    if n <= 0 or prim < starts[0] or prim >= starts[n]:
        return -1
    return bisect_last(starts, prim, 0, n)       # starts[0] <= prim < starts[n]


@kernel(inline="always")
def rigid_at(info, trans, quat, upper, obj, t):
    """RigidMotion.at for one time t of moving object obj, on the arrays M.info,
    M.step_trans, step_quat, step_upper: (a00, a01, a02, a10, ..., a22, tx, ty, tz), the
    3x3 linear part row-major then the translation, clamped to the first and last step."""
    a, f = step_of(info[obj, I_STEPS], t)
    a += info[obj, I_STEP0]
    if info[obj, I_STEPS] < 2:
        return interpolate_steps(trans, quat, upper, a, a, 0.0)
    return interpolate_steps(trans, quat, upper, a, a + 1, f)


@kernel(inline="always")
def interpolate_steps(trans, quat, upper, a, b, f):
    """The transform between step rows a and b at fraction f in [0, 1] of the way (the
    body of RigidMotion.at, same formulas), on M.step_trans, step_quat, step_upper:
    translation and scale-and-skew linearly, rotation by spherical linear interpolation
    (normalised linear above NLERP_DOT, as Embree)."""
    tx = trans[a, 0] + f * (trans[b, 0] - trans[a, 0])
    ty = trans[a, 1] + f * (trans[b, 1] - trans[a, 1])
    tz = trans[a, 2] + f * (trans[b, 2] - trans[a, 2])
    s00 = upper[a, 0, 0] + f * (upper[b, 0, 0] - upper[a, 0, 0])
    s01 = upper[a, 0, 1] + f * (upper[b, 0, 1] - upper[a, 0, 1])
    s02 = upper[a, 0, 2] + f * (upper[b, 0, 2] - upper[a, 0, 2])
    s10 = upper[a, 1, 0] + f * (upper[b, 1, 0] - upper[a, 1, 0])
    s11 = upper[a, 1, 1] + f * (upper[b, 1, 1] - upper[a, 1, 1])
    s12 = upper[a, 1, 2] + f * (upper[b, 1, 2] - upper[a, 1, 2])
    s20 = upper[a, 2, 0] + f * (upper[b, 2, 0] - upper[a, 2, 0])
    s21 = upper[a, 2, 1] + f * (upper[b, 2, 1] - upper[a, 2, 1])
    s22 = upper[a, 2, 2] + f * (upper[b, 2, 2] - upper[a, 2, 2])
    # slerp (engine.motion._slerp)
    aw, ax, ay, az = quat[a, 0], quat[a, 1], quat[a, 2], quat[a, 3]
    bw, bx, by, bz = quat[b, 0], quat[b, 1], quat[b, 2], quat[b, 3]
    d = aw * bw + ax * bx + ay * by + az * bz
    d = min(max(d, -1.0), 1.0)
    theta = math.acos(d)
    sn = math.sin(theta)
    if d > NLERP_DOT or sn < 1e-9:
        w0, w1 = 1.0 - f, f
    else:
        w0 = math.sin((1.0 - f) * theta) / sn
        w1 = math.sin(f * theta) / sn
    w = w0 * aw + w1 * bw
    x = w0 * ax + w1 * bx
    y = w0 * ay + w1 * by
    z = w0 * az + w1 * bz
    ln = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / ln, x / ln, y / ln, z / ln
    # engine.motion._matrix_from_quat
    r00, r01, r02 = 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)
    r10, r11, r12 = 2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)
    r20, r21, r22 = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
    return (r00 * s00 + r01 * s10 + r02 * s20, r00 * s01 + r01 * s11 + r02 * s21,
            r00 * s02 + r01 * s12 + r02 * s22,
            r10 * s00 + r11 * s10 + r12 * s20, r10 * s01 + r11 * s11 + r12 * s21,
            r10 * s02 + r11 * s12 + r12 * s22,
            r20 * s00 + r21 * s10 + r22 * s20, r20 * s01 + r21 * s11 + r22 * s21,
            r20 * s02 + r21 * s12 + r22 * s22,
            tx, ty, tz)


@kernel(inline="always")
def adjugate_columns(a00, a01, a02, a10, a11, a12, a20, a21, a22):
    """engine.motion.inverse3 for one matrix: the rows r0, r1, r2 of the adjugate (the
    cross products of the columns) and the determinant, clamped away from 0 as there.
    The inverse is rows r_i / det; the inverse-transpose has them as columns."""
    r0x, r0y, r0z = cross(a01, a11, a21, a02, a12, a22)
    r1x, r1y, r1z = cross(a02, a12, a22, a00, a10, a20)
    r2x, r2y, r2z = cross(a00, a10, a20, a01, a11, a21)
    det = a00 * r0x + a10 * r0y + a20 * r0z
    if not abs(det) > 1e-300:
        det = 1e-300
    return r0x, r0y, r0z, r1x, r1y, r1z, r2x, r2y, r2z, det
