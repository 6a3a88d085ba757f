"""World bounds of a rigidly moving object over a stretch of shutter time, valid at every
time in it (rotation included), for the hierarchy over moving objects
(`engine.kernels.motion_tlas`).

The motion between two motion steps a and b (`engine.motion.RigidMotion.at`): at
fraction f in [0, 1] of the interval, an object-space point p is at
    x(f) = R(f) S(f) p + T(f),
T and S (the symmetric stretch of the polar decomposition) linear in f, R the
spherical linear interpolation of the steps' rotations: a turn at constant rate about a
fixed axis through the angle phi = 2 acos(q_a . q_b) over the interval.

Bounds of the object's box [lo, hi] over fractions [f0, f1]:
- at one time, x is affine in p, so the box's points lie in the convex hull of its 8
  corners: the world box of the corners bounds the object;
- between times, differentiate twice: T'' = S'' = 0, |R'| = phi, |R''| = phi^2, so
      |x''(f)| <= (phi^2 |S|max + 2 phi |S_b - S_a|) |p|max =: C,
  |S| a Frobenius norm (>= the operator norm; |S(f)| <= max(|S_a|, |S_b|) by
  convexity), |p|max the largest norm of a corner of the box (the largest over the box);
- linear interpolation between two times h apart is off by at most h^2 / 8 C in each
  coordinate, and the interpolating segment lies in the union of the two times' boxes.
So the union of the corners' world boxes at N + 1 evenly spaced fractions, grown on every
side by (f1 - f0)^2 / (8 N^2) C, holds the object at every time of [f0, f1]. Pure
translation and scaling (phi = 0) need no margin: the swept box is exact.

How finely to cut (`plan_interval`): an interval is cut into segments of time (up to
MAX_SEGMENTS), about one per object size travelled, so that a fast object's box is a
chain of small boxes rather than one long one; each segment gets enough sampled times
(up to MAX_SAMPLES) to keep the margin below MARGIN_FRACTION of the object's size.
"""
from __future__ import annotations

import math

import numpy as np

from .jit import kernel
from .motion import DEFORM, I_KIND, I_STEP0, I_STEPS, interpolate_steps

MAX_SEGMENTS = 16           # time segments per motion interval
MAX_SAMPLES = 256           # sampled times per segment
MARGIN_FRACTION = 1.0 / 64  # target interpolation margin, of the object's size


@kernel
def corner_box(a00, a01, a02, a10, a11, a12, a20, a21, a22, tx, ty, tz, lo, hi, out):
    """Grow out (6,) by the world box of the 8 corners of the object box [lo, hi] under
    the affine map (3x3 row-major, translation)."""
    for c in range(8):
        x = hi[0] if c & 1 else lo[0]
        y = hi[1] if c & 2 else lo[1]
        z = hi[2] if c & 4 else lo[2]
        wx = a00 * x + a01 * y + a02 * z + tx
        wy = a10 * x + a11 * y + a12 * z + ty
        wz = a20 * x + a21 * y + a22 * z + tz
        out[0] = min(out[0], wx)
        out[1] = min(out[1], wy)
        out[2] = min(out[2], wz)
        out[3] = max(out[3], wx)
        out[4] = max(out[4], wy)
        out[5] = max(out[5], wz)


@kernel
def _frobenius(s, a):
    acc = 0.0
    for i in range(3):
        for j in range(3):
            acc += s[a, i, j] * s[a, i, j]
    return math.sqrt(acc)


@kernel
def _frobenius_of_difference(s, a, b):
    acc = 0.0
    for i in range(3):
        for j in range(3):
            d = s[b, i, j] - s[a, i, j]
            acc += d * d
    return math.sqrt(acc)


@kernel
def _largest_corner_norm(lo, hi):
    pmax = 0.0
    for c in range(8):
        x = hi[0] if c & 1 else lo[0]
        y = hi[1] if c & 2 else lo[1]
        z = hi[2] if c & 4 else lo[2]
        pmax = max(pmax, math.sqrt(x * x + y * y + z * z))
    return pmax


@kernel
def turn_angle(quat, a):
    """phi: the angle the slerp between step rows a and a + 1 turns through. The steps'
    quaternions are on the shorter arc (engine.motion), so phi <= pi; a negative dot
    product (the longer arc) would give phi > pi, which slerp would then turn through."""
    d = 0.0
    for c in range(4):
        d += quat[a, c] * quat[a + 1, c]
    return 2.0 * math.acos(min(max(d, -1.0), 1.0))


@kernel
def interval_curvature(M, a, lo, hi):
    """C = max |x''| over the interval between step rows a and a + 1 for points of the
    object box [lo, hi] (see the module docstring)."""
    phi = turn_angle(M.step_quat, a)
    smax = max(_frobenius(M.step_stretch, a), _frobenius(M.step_stretch, a + 1))
    ds = _frobenius_of_difference(M.step_stretch, a, a + 1)
    return (phi * phi * smax + 2.0 * phi * ds) * _largest_corner_norm(lo, hi)


@kernel
def swept_box(M, a, lo, hi, f0, f1, samples, margin, out):
    """Bounds out (6,) of the object box [lo, hi] moving between step rows a and a + 1
    over the fractions [f0, f1]: the corners' world boxes at samples + 1 evenly spaced
    fractions, grown by the interpolation error bound. margin=False leaves the sampled
    boxes alone, which is NOT conservative under rotation (for tests and the ends of
    intervals)."""
    for c in range(3):
        out[c] = np.inf
        out[3 + c] = -np.inf
    for j in range(samples + 1):
        f = f1 if j == samples else f0 + (f1 - f0) * (j / samples)
        a00, a01, a02, a10, a11, a12, a20, a21, a22, tx, ty, tz = interpolate_steps(
            M.step_trans, M.step_quat, M.step_stretch, a, f)
        corner_box(a00, a01, a02, a10, a11, a12, a20, a21, a22, tx, ty, tz, lo, hi, out)
    if margin:
        h = (f1 - f0) / samples
        g = h * h / 8.0 * interval_curvature(M, a, lo, hi)
        for c in range(3):
            out[c] -= g
            out[3 + c] += g


@kernel
def plan_interval(M, a, lo, hi):
    """(segments, samples per segment) for the interval between step rows a and a + 1:
    about one segment per object size travelled (the centre's displacement plus the
    path length of the farthest corner's turn and stretch), and enough samples to keep
    the margin h^2 / 8 C below MARGIN_FRACTION of the object's size."""
    box = np.empty(6)
    swept_box(M, a, lo, hi, 0.0, 0.0, 1, False, box)
    size = max(box[3] - box[0], box[4] - box[1], box[5] - box[2], 1e-300)
    c0x, c0y, c0z = (box[0] + box[3]) * 0.5, (box[1] + box[4]) * 0.5, (box[2] + box[5]) * 0.5
    swept_box(M, a, lo, hi, 1.0, 1.0, 1, False, box)
    size = max(size, box[3] - box[0], box[4] - box[1], box[5] - box[2])
    c1x, c1y, c1z = (box[0] + box[3]) * 0.5, (box[1] + box[4]) * 0.5, (box[2] + box[5]) * 0.5
    smax = max(_frobenius(M.step_stretch, a), _frobenius(M.step_stretch, a + 1))
    turn = (turn_angle(M.step_quat, a) * smax
            + _frobenius_of_difference(M.step_stretch, a, a + 1)) * _largest_corner_norm(lo, hi)
    travel = math.sqrt((c1x - c0x) ** 2 + (c1y - c0y) ** 2 + (c1z - c0z) ** 2) + turn
    segments = min(MAX_SEGMENTS, max(1, int(math.ceil(travel / size))))
    width = 1.0 / segments
    need = math.sqrt(interval_curvature(M, a, lo, hi) * width * width
                     / (8.0 * MARGIN_FRACTION * size))
    return segments, min(MAX_SAMPLES, max(1, int(math.ceil(need))))


def condition_bound(M) -> np.ndarray:
    """Per moving object a bound kappa >= 1 on the condition number of its linear part
    over the shutter (1 for deforming objects, whose rays are not transformed):
    max |eigenvalue| / min |eigenvalue| of the stretches S over all steps. That bounds
    every interpolated stretch when all are positive definite (the extreme eigenvalues
    of symmetric matrices are convex / concave in the matrix); a mirrored or singular
    stretch is not, so there the bound is x4 and capped at 1e6."""
    out = np.ones(len(M.info))
    for o in range(len(M.info)):
        if M.info[o, I_KIND] == DEFORM:
            continue
        s0, k = M.info[o, I_STEP0], M.info[o, I_STEPS]
        ev = np.linalg.eigvalsh(M.step_stretch[s0:s0 + k])
        small = np.abs(ev).min()
        kappa = np.abs(ev).max() / small if small > 0 else 1e6
        if (ev <= 0).any():
            kappa *= 4.0
        out[o] = min(max(kappa, 1.0), 1e6)
    return out
