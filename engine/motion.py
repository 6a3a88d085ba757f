"""Motion over the shutter: the shutter's time distribution and rigid transforms at any
time within it.

Time is normalised to the shutter: t = 0 when it opens, t = 1 when it closes (the exporter
maps Blender's frame, shutter length and shutter position onto this). Each camera sample
draws its own t from the sampler's TIME dimension (stratified and decorrelated from the
pixel and lens dimensions like every other dimension), through the shutter curve.

Rigid motion is exact at each ray's own time: the transforms at the motion steps are
decomposed into translation, rotation (a unit quaternion) and a symmetric stretch (polar
decomposition, so scale and even shear survive), and those are interpolated, linearly for
translation and stretch and by spherical linear interpolation for rotation, never the
matrix entries (which would shrink a rotating object and cut arcs into chords).
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


def _slerp(q0: np.ndarray, q1: np.ndarray, f: np.ndarray) -> np.ndarray:
    dot = np.clip((q0 * q1).sum(1), -1.0, 1.0)
    theta = np.arccos(dot)
    sin = np.sin(theta)
    small = sin < 1e-9
    w0 = np.where(small, 1.0 - f, np.sin((1.0 - f) * theta) / np.where(small, 1.0, sin))
    w1 = np.where(small, f, np.sin(f * theta) / np.where(small, 1.0, sin))
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
        a = self.matrices[:, :3, :3]
        u, s, vt = np.linalg.svd(a)
        rot = u @ vt
        flip = np.linalg.det(rot) < 0           # mirrored: keep the mirror in the stretch
        u[flip, :, -1] *= -1
        rot = u @ vt
        stretch = np.transpose(vt, (0, 2, 1)) @ (s[:, :, None] * vt)
        stretch[flip] = np.transpose(vt[flip], (0, 2, 1)) @ (
            (s[flip] * np.array([1, 1, -1]))[:, :, None] * vt[flip])
        self._decomposed = (self.matrices[:, :3, 3].copy(), _quat_from_matrix(rot), stretch)

    def is_static(self) -> bool:
        return len(self.times) == 1 or bool(np.all(np.abs(self.matrices - self.matrices[0]) < 1e-12))

    def at(self, t: np.ndarray) -> np.ndarray:
        """(n, 4, 4) transforms at shutter times t (n,); clamped to the first and last step."""
        t = np.asarray(t, dtype=np.float64)
        trans, quat, stretch = self._decomposed
        k = len(self.times)
        if k == 1:
            return np.broadcast_to(self.matrices[0], (len(t), 4, 4)).copy()
        i = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, k - 2)
        span = self.times[i + 1] - self.times[i]
        f = np.clip((t - self.times[i]) / span, 0.0, 1.0)
        tr = trans[i] + f[:, None] * (trans[i + 1] - trans[i])
        st = stretch[i] + f[:, None, None] * (stretch[i + 1] - stretch[i])
        r = _matrix_from_quat(_slerp(quat[i], quat[i + 1], f))
        out = np.zeros((len(t), 4, 4))
        out[:, :3, :3] = r @ st
        out[:, :3, 3] = tr
        out[:, 3, 3] = 1.0
        return out


@dataclass
class DeformMotion:
    """Vertex positions that change over the shutter: times (K,) increasing in [0, 1],
    positions (K, V, 3) world space. Traced in `slices` stratified time slices, each with
    its own acceleration structure built from the positions at the slice's middle."""
    times: np.ndarray
    positions: np.ndarray
    slices: int = 8

    def __post_init__(self):
        self.times = np.asarray(self.times, dtype=np.float64).reshape(-1)
        self.positions = np.asarray(self.positions, dtype=np.float64)
        if self.positions.ndim != 3 or len(self.positions) != len(self.times):
            raise ValueError("deformation needs (K, V, 3) positions for K times")
        if not np.isfinite(self.positions).all():
            raise ValueError("deformation positions must be finite")
        if self.slices < 1:
            raise ValueError("deformation needs at least one time slice")

    def positions_at(self, t: float) -> np.ndarray:
        k = len(self.times)
        if k == 1:
            return self.positions[0]
        i = int(np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, k - 2))
        f = float(np.clip((t - self.times[i]) / (self.times[i + 1] - self.times[i]), 0, 1))
        return self.positions[i] * (1 - f) + self.positions[i + 1] * f

    def slice_of(self, t: np.ndarray) -> np.ndarray:
        return np.clip((np.asarray(t) * self.slices).astype(np.int64), 0, self.slices - 1)

    def slice_times(self) -> np.ndarray:
        return (np.arange(self.slices) + 0.5) / self.slices
