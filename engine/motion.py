"""Motion over the shutter: the shutter's time distribution and rigid transforms at any
time within it.

Time is normalised to the shutter: t = 0 when it opens, t = 1 when it closes (the exporter
maps Blender's frame, shutter length and shutter position onto this). Each camera sample
draws its own t from the sampler's TIME dimension (stratified and decorrelated from the
pixel and lens dimensions like every other dimension), through the shutter curve.

Rigid motion is exact at each ray's own time: the transforms at the motion steps are
decomposed into translation, rotation (a unit quaternion) and an upper triangular
scale-and-skew matrix (A = R U: the QR decomposition with U's diagonal positive, a mirror
kept in U's last entry), and those are interpolated, linearly for translation and U and
by spherical linear interpolation for rotation, never the matrix entries (which would
shrink a rotating object and cut arcs into chords). This is the decomposition Embree
interpolates (RTCQuaternionDecomposition), so the geometry Embree traces and the hit
points DRT rebuilds from it agree at every time; between nearly equal rotations
(quaternion dot above 0.9995) both take the normalised linear interpolation, as Embree
does. For an object that rotates and scales along its own axes, U is the scale and this
is Cycles' decomposition too (Cycles takes a symmetric polar stretch; they differ only
for sheared objects that rotate during the shutter).

Motion steps are evenly spaced over the shutter, as Embree's time steps are (Blender's
motion steps are); `evenly_spaced()` resamples other step times.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np


@dataclass
class Shutter:
    """curve: optional (M,) samples of Blender's shutter curve over [0, 1] (the shutter's
    openness); None means a box shutter (uniform in time)."""
    curve: Optional[np.ndarray] = None

    def __post_init__(self):
        if self.curve is not None:
            c = np.clip(np.asarray(self.curve, dtype=np.float64), 0.0, None)
            if c.ndim != 1 or c.size < 2 or not np.isfinite(c).all() or c.sum() <= 0:
                raise ValueError("shutter curve must be a finite, non-negative, non-zero 1D array")
            xs = np.linspace(0.0, 1.0, c.size)
            cdf = np.concatenate([[0.0], np.cumsum(0.5 * (c[1:] + c[:-1]) * np.diff(xs))])
            self._xs, self._cdf = xs, cdf / cdf[-1]

    def sample(self, u: np.ndarray) -> np.ndarray:
        """Shutter times in [0, 1) for u in [0, 1), distributed as the curve (monotone, so
        strata of u map to strata of time)."""
        if self.curve is None:
            return np.asarray(u, dtype=np.float64)
        return np.minimum(np.interp(u, self._cdf, self._xs), 1.0 - 2.0 ** -53)


def _quat_from_matrix(r: np.ndarray) -> np.ndarray:
    """Unit quaternions (w, x, y, z) of rotation matrices (k, 3, 3) (Shepperd's method)."""
    k = len(r)
    q = np.empty((k, 4))
    tr = np.trace(r, axis1=1, axis2=2)
    for i in range(k):                       # k = number of motion steps: a handful
        m = r[i]
        if tr[i] > 0:
            s = np.sqrt(tr[i] + 1.0) * 2
            q[i] = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s,
                    (m[1, 0] - m[0, 1]) / s]
        elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
            s = np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
            q[i] = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s,
                    (m[0, 2] + m[2, 0]) / s]
        elif m[1, 1] > m[2, 2]:
            s = np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
            q[i] = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s,
                    (m[1, 2] + m[2, 1]) / s]
        else:
            s = np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
            q[i] = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s,
                    0.25 * s]
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    # Take the shorter arc between consecutive steps.
    for i in range(1, k):
        if np.dot(q[i], q[i - 1]) < 0:
            q[i] = -q[i]
    return q


def _matrix_from_quat(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)


# Rotations closer than this (quaternion dot) interpolate linearly, then normalised, as
# Embree's slerp does (common/math/quaternion.h)
NLERP_DOT = 0.9995


def _slerp(q0: np.ndarray, q1: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Spherical linear interpolation of unit quaternions (n, 4), f (n,) in [0, 1]; the
    normalised linear one when they are closer than NLERP_DOT."""
    dot = np.clip((q0 * q1).sum(1), -1.0, 1.0)
    theta = np.arccos(dot)
    sin = np.sin(theta)
    near = (dot > NLERP_DOT) | (sin < 1e-9)
    w0 = np.where(near, 1.0 - f, np.sin((1.0 - f) * theta) / np.where(near, 1.0, sin))
    w1 = np.where(near, f, np.sin(f * theta) / np.where(near, 1.0, sin))
    q = w0[:, None] * q0 + w1[:, None] * q1
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def inverse3(a: np.ndarray) -> np.ndarray:
    """Inverses of (n, 3, 3) matrices in closed form (adjugate over determinant): an
    order of magnitude faster than batched LAPACK for 3x3, and exact enough in float64."""
    c0, c1, c2 = a[:, :, 0], a[:, :, 1], a[:, :, 2]
    r0, r1, r2 = np.cross(c1, c2), np.cross(c2, c0), np.cross(c0, c1)
    det = (c0 * r0).sum(1)
    det = np.where(np.abs(det) > 1e-300, det, 1e-300)
    return np.stack([r0, r1, r2], axis=1) / det[:, None, None]


@dataclass
class RigidMotion:
    """A transform sampled at motion steps: times (K,) increasing in [0, 1] (shutter
    time), matrices (K, 4, 4) object-to-world (or camera-to-world)."""
    times: np.ndarray
    matrices: np.ndarray
    _decomposed: tuple = field(default=None, repr=False)

    def __post_init__(self):
        self.times = np.asarray(self.times, dtype=np.float64).reshape(-1)
        self.matrices = np.asarray(self.matrices, dtype=np.float64).reshape(-1, 4, 4)
        if len(self.times) != len(self.matrices) or len(self.times) < 1:
            raise ValueError("motion needs one matrix per time step")
        if not (np.isfinite(self.times).all() and np.isfinite(self.matrices).all()):
            raise ValueError("motion steps must be finite")
        if np.any(np.diff(self.times) <= 0):
            raise ValueError("motion step times must increase")
        self._decomposed = decompose(self.matrices)

    def is_static(self) -> bool:
        return len(self.times) == 1 or bool(np.all(np.abs(self.matrices - self.matrices[0]) < 1e-12))

    def at(self, t: np.ndarray) -> np.ndarray:
        """(n, 4, 4) transforms at shutter times t (n,); clamped to the first and last step."""
        t = np.asarray(t, dtype=np.float64)
        trans, quat, upper = self._decomposed
        k = len(self.times)
        if k == 1:
            return np.broadcast_to(self.matrices[0], (len(t), 4, 4)).copy()
        i = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, k - 2)
        span = self.times[i + 1] - self.times[i]
        f = np.clip((t - self.times[i]) / span, 0.0, 1.0)
        tr = trans[i] + f[:, None] * (trans[i + 1] - trans[i])
        up = upper[i] + f[:, None, None] * (upper[i + 1] - upper[i])
        r = _matrix_from_quat(_slerp(quat[i], quat[i + 1], f))
        out = np.zeros((len(t), 4, 4))
        out[:, :3, :3] = r @ up
        out[:, :3, 3] = tr
        out[:, 3, 3] = 1.0
        return out

    def evenly_spaced(self) -> "RigidMotion":
        """The motion on evenly spaced steps from 0 to 1 (itself when its steps are)."""
        k = _even_count(self.times)
        if k == len(self.times):
            return self
        grid = np.linspace(0.0, 1.0, k)
        return RigidMotion(grid, self.at(grid))

    def embree_steps(self, shift=None) -> np.ndarray:
        """(K, 16) rows of Embree's RTCQuaternionDecomposition, one per step: scale x, y,
        z (U's diagonal), skew xy, xz, yz (U's upper entries), shift 0, quaternion r, i,
        j, k, translation x, y, z (minus `shift`, the tracer's origin)."""
        trans, quat, upper = self._decomposed
        rows = np.zeros((len(self.times), 16))
        rows[:, 0], rows[:, 1], rows[:, 2] = upper[:, 0, 0], upper[:, 1, 1], upper[:, 2, 2]
        rows[:, 3], rows[:, 4], rows[:, 5] = upper[:, 0, 1], upper[:, 0, 2], upper[:, 1, 2]
        rows[:, 9:13] = quat
        rows[:, 13:16] = trans - (0.0 if shift is None else np.asarray(shift, np.float64))
        return rows


def decompose(matrices: np.ndarray) -> tuple:
    """(translations (K, 3), rotations (K, 4) w, x, y, z on the shorter arc from one step
    to the next, upper triangular scale and skew (K, 3, 3)) of transforms (K, 4, 4):
    A = R U, QR with U's diagonal made positive; a mirroring A keeps its mirror in U[2, 2]
    (R stays a rotation)."""
    a = matrices[:, :3, :3]
    q, u = np.linalg.qr(a)
    sign = np.where(np.diagonal(u, axis1=1, axis2=2) < 0, -1.0, 1.0)   # (K, 3)
    q = q * sign[:, None, :]
    u = u * sign[:, :, None]
    mirror = np.linalg.det(q) < 0
    q[mirror, :, 2] *= -1.0
    u[mirror, 2, :] *= -1.0
    return matrices[:, :3, 3].copy(), _quat_from_matrix(q), np.triu(u)


def _even_count(times: np.ndarray) -> int:
    """len(times) when the times run evenly from 0 to 1; else the fewest evenly spaced
    steps from 0 to 1 that hold every one of them (0, 0.3, 1: 11 steps), on which the
    motion resamples exactly (it is linear, or spherical, between its own steps); at
    most Embree's 129, an approximation for times on no such grid."""
    k = len(times)
    if k < 2 or (times[0] == 0.0 and times[-1] == 1.0 and np.abs(
            times - np.arange(k) / (k - 1)).max() <= 1e-9):
        return k
    for segments in range(k, 129):
        x = times * segments
        if np.allclose(x, np.round(x), rtol=0.0, atol=1e-7 * segments) \
                and times[0] == 0.0 and abs(times[-1] - 1.0) < 1e-9:
            return segments + 1
    return 129


@dataclass
class DeformMotion:
    """Vertex positions that change over the shutter: times (K,) increasing in [0, 1],
    positions (K, V, 3) world space. A vertex moves linearly from step to step, as
    Embree traces it (its time steps) and as Cycles' deformation blur moves it."""
    times: np.ndarray
    positions: np.ndarray

    def __post_init__(self):
        self.times = np.asarray(self.times, dtype=np.float64).reshape(-1)
        self.positions = np.asarray(self.positions, dtype=np.float64)
        if self.positions.ndim != 3 or len(self.positions) != len(self.times):
            raise ValueError("deformation needs (K, V, 3) positions for K times")
        if not np.isfinite(self.positions).all():
            raise ValueError("deformation positions must be finite")
        if np.any(np.diff(self.times) <= 0):
            raise ValueError("deformation step times must increase")

    def positions_at(self, t: float) -> np.ndarray:
        k = len(self.times)
        if k == 1:
            return self.positions[0]
        i = int(np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, k - 2))
        f = float(np.clip((t - self.times[i]) / (self.times[i + 1] - self.times[i]), 0, 1))
        return self.positions[i] * (1 - f) + self.positions[i + 1] * f

    def evenly_spaced(self) -> "DeformMotion":
        """The deformation on evenly spaced steps from 0 to 1 (itself when its steps are)."""
        k = _even_count(self.times)
        if k == len(self.times):
            return self
        grid = np.linspace(0.0, 1.0, k)
        return DeformMotion(grid, np.stack([self.positions_at(t) for t in grid]))
