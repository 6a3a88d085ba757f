"""Moving objects, compiled: the transform of a rigidly moving object at one ray's time
(`engine.motion.RigidMotion.at`, same formulas) and a world ray moved into its space.

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

from .cdf_search import bisect_last
from .frame import cross
from .jit import kernel

RIGID, DEFORM = 0, 1

# columns of PackedMotion.info
I_KIND, I_STEP0, I_STEPS, I_VERT0, I_NVERTS, I_SLICES = range(6)


class PackedMotion(NamedTuple):
    prim_start: np.ndarray    # int64 (n + 1,) first global triangle id of each moving
    #                           object, then the total triangle count
    info: np.ndarray          # int64 (n, 6) kind (RIGID / DEFORM), first motion step row,
    #                           step count, first vertex row, vertices per slice, slices
    step_time: np.ndarray     # float64 (S,) motion step times (rigid objects, concatenated)
    step_trans: np.ndarray    # float64 (S, 3) translation at each step
    step_quat: np.ndarray     # float64 (S, 4) rotation (w, x, y, z), shorter arc between steps
    step_stretch: np.ndarray  # float64 (S, 3, 3) symmetric stretch (polar decomposition)
    step_linear: np.ndarray   # float64 (S, 3, 3) the step's own 3x3 (one-step motions)
    verts: np.ndarray         # float64 (V, 3) object-space vertices (rigid) or every time
    #                           slice's world vertices, one slice after the other (deform)
    tris: np.ndarray          # int64 (T, 3) per moving triangle (global id - static count)
    #                           its object-local vertex indices


def pack_motion(accel) -> PackedMotion:
    """The moving objects of `accel` (engine.accel.Accelerator) packed for the kernels."""
    objs = accel.moving
    n = len(objs)
    prim_start = np.empty(n + 1, np.int64)
    info = np.zeros((n, 6), np.int64)
    times, trans, quats, stretch, linear, verts, tris = [], [], [], [], [], [], []
    step, vert = 0, 0
    for i, obj in enumerate(objs):
        mesh = obj.mesh
        prim_start[i] = obj.prim_offset
        tris.append(np.asarray(mesh.triangles, np.int64).reshape(-1, 3))
        if obj.rigid:
            motion = mesh.motion
            tr, q, st = motion._decomposed
            k = len(motion.times)
            info[i] = (RIGID, step, k, vert, len(mesh.positions), 1)
            times.append(motion.times)
            trans.append(tr)
            quats.append(q)
            stretch.append(st)
            linear.append(motion.matrices[:, :3, :3])
            verts.append(np.asarray(mesh.positions, np.float64).reshape(-1, 3))
            step += k
            vert += len(mesh.positions)
        else:
            slices = obj.slice_positions
            nv = len(slices[0])
            info[i] = (DEFORM, step, 0, vert, nv, len(slices))
            verts.extend(np.asarray(p, np.float64).reshape(-1, 3) for p in slices)
            vert += nv * len(slices)
    prim_start[n] = accel.total_triangles if n else accel.moving_start

    def cat(parts, shape, dtype):
        if not parts:
            return np.zeros(shape, dtype)
        return np.ascontiguousarray(np.concatenate(parts), dtype=dtype)

    return PackedMotion(prim_start, info, cat(times, (0,), np.float64),
                        cat(trans, (0, 3), np.float64), cat(quats, (0, 4), np.float64),
                        cat(stretch, (0, 3, 3), np.float64), cat(linear, (0, 3, 3), np.float64),
                        cat(verts, (0, 3), np.float64), cat(tris, (0, 3), np.int64))


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
def step_of(info, times, obj, t):
    """(first step row a of the interval holding t, fraction f in [0, 1] of the way to
    step a + 1): searchsorted(times, t, side="right") - 1 clipped to [0, k - 2], as in
    RigidMotion.at. Objects with one step only: (that step, 0)."""
    s0 = info[obj, I_STEP0]
    k = info[obj, I_STEPS]
    if k < 2:
        return s0, 0.0
    j = 0
    while j < k and times[s0 + j] <= t:
        j += 1
    a = s0 + min(max(j - 1, 0), k - 2)
    f = (t - times[a]) / (times[a + 1] - times[a])
    return a, min(max(f, 0.0), 1.0)


@kernel(inline="always")
def rigid_at(info, times, trans, quat, stretch, linear, obj, t):
    """RigidMotion.at for one time t of moving object obj, on the arrays M.info ..
    M.step_linear: (a00, a01, a02, a10, ..., a22, tx, ty, tz), the 3x3 linear part
    row-major then the translation. Translation and stretch interpolate linearly,
    rotation by spherical linear interpolation, clamped to the first and last step."""
    a, f = step_of(info, times, obj, t)
    if info[obj, I_STEPS] < 2:
        return (linear[a, 0, 0], linear[a, 0, 1], linear[a, 0, 2], linear[a, 1, 0],
                linear[a, 1, 1], linear[a, 1, 2], linear[a, 2, 0], linear[a, 2, 1],
                linear[a, 2, 2], trans[a, 0], trans[a, 1], trans[a, 2])
    return interpolate_steps(trans, quat, stretch, a, f)


@kernel(inline="always")
def interpolate_steps(trans, quat, stretch, a, f):
    """The transform between step rows a and a + 1 at fraction f in [0, 1] of the way
    (the body of RigidMotion.at, same formulas), on M.step_trans, step_quat,
    step_stretch."""
    b = a + 1
    tx = trans[a, 0] + f * (trans[b, 0] - trans[a, 0])
    ty = trans[a, 1] + f * (trans[b, 1] - trans[a, 1])
    tz = trans[a, 2] + f * (trans[b, 2] - trans[a, 2])
    s00 = stretch[a, 0, 0] + f * (stretch[b, 0, 0] - stretch[a, 0, 0])
    s01 = stretch[a, 0, 1] + f * (stretch[b, 0, 1] - stretch[a, 0, 1])
    s02 = stretch[a, 0, 2] + f * (stretch[b, 0, 2] - stretch[a, 0, 2])
    s10 = stretch[a, 1, 0] + f * (stretch[b, 1, 0] - stretch[a, 1, 0])
    s11 = stretch[a, 1, 1] + f * (stretch[b, 1, 1] - stretch[a, 1, 1])
    s12 = stretch[a, 1, 2] + f * (stretch[b, 1, 2] - stretch[a, 1, 2])
    s20 = stretch[a, 2, 0] + f * (stretch[b, 2, 0] - stretch[a, 2, 0])
    s21 = stretch[a, 2, 1] + f * (stretch[b, 2, 1] - stretch[a, 2, 1])
    s22 = stretch[a, 2, 2] + f * (stretch[b, 2, 2] - stretch[a, 2, 2])
    # slerp (engine.motion._slerp)
    aw, ax, ay, az = quat[a, 0], quat[a, 1], quat[a, 2], quat[a, 3]
    bw, bx, by, bz = quat[b, 0], quat[b, 1], quat[b, 2], quat[b, 3]
    d = aw * bw + ax * bx + ay * by + az * bz
    d = min(max(d, -1.0), 1.0)
    theta = math.acos(d)
    sn = math.sin(theta)
    if sn < 1e-9:
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


@kernel(inline="always")
def object_ray(info, times, trans, quat, stretch, linear, obj, t, ox, oy, oz, dx, dy, dz):
    """A world ray (o, d) moved into rigid object obj's space at time t: the inverse of
    the transform at t (`rigid_at`) applied to o - translation and to d. The ray
    parameter is unchanged by an affine map, so distances compare directly."""
    a00, a01, a02, a10, a11, a12, a20, a21, a22, tx, ty, tz = rigid_at(
        info, times, trans, quat, stretch, linear, obj, t)
    r0x, r0y, r0z, r1x, r1y, r1z, r2x, r2y, r2z, det = adjugate_columns(
        a00, a01, a02, a10, a11, a12, a20, a21, a22)
    qx, qy, qz = ox - tx, oy - ty, oz - tz
    return ((r0x / det) * qx + (r0y / det) * qy + (r0z / det) * qz,
            (r1x / det) * qx + (r1y / det) * qy + (r1z / det) * qz,
            (r2x / det) * qx + (r2y / det) * qy + (r2z / det) * qz,
            (r0x / det) * dx + (r0y / det) * dy + (r0z / det) * dz,
            (r1x / det) * dx + (r1y / det) * dy + (r1z / det) * dz,
            (r2x / det) * dx + (r2y / det) * dy + (r2z / det) * dz)
