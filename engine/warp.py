"""Warps from [0,1)^2 to geometric domains, each with its pdf.

Every warp is measure-preserving up to its stated pdf and continuous, so stratification
in the unit square survives the mapping (which is why concentric, not polar, disk maps).
All functions are vectorised over arrays of shape (n, 2).
"""
from __future__ import annotations

import numpy as np

INV_PI = 1.0 / np.pi


def concentric_disk(u: np.ndarray) -> np.ndarray:
    """Shirley-Chiu concentric map onto the unit disk; pdf 1/pi in area."""
    a = 2.0 * u[..., 0] - 1.0
    b = 2.0 * u[..., 1] - 1.0
    use_a = np.abs(a) > np.abs(b)
    safe_a = np.where(a == 0.0, 1.0, a)
    safe_b = np.where(b == 0.0, 1.0, b)
    r = np.where(use_a, a, b)
    phi = np.where(use_a, (np.pi / 4.0) * (b / safe_a), (np.pi / 2.0) - (np.pi / 4.0) * (a / safe_b))
    zero = (a == 0.0) & (b == 0.0)
    r = np.where(zero, 0.0, r)
    return np.stack([r * np.cos(phi), r * np.sin(phi)], axis=-1)


def cosine_hemisphere(u: np.ndarray) -> np.ndarray:
    """Cosine-weighted directions about +Z (Malley's method); pdf cos(theta)/pi."""
    d = concentric_disk(u)
    z = np.sqrt(np.maximum(0.0, 1.0 - (d * d).sum(-1)))
    return np.concatenate([d, z[..., None]], axis=-1)


def cosine_hemisphere_pdf(cos_theta: np.ndarray) -> np.ndarray:
    return np.maximum(cos_theta, 0.0) * INV_PI


def uniform_sphere(u: np.ndarray) -> np.ndarray:
    """Uniform directions on the unit sphere; pdf 1/(4 pi)."""
    z = 1.0 - 2.0 * u[..., 0]
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    phi = 2.0 * np.pi * u[..., 1]
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def uniform_cone(u: np.ndarray, cos_max) -> np.ndarray:
    """Uniform directions in the cone of half-angle acos(cos_max) about +Z;
    pdf 1 / (2 pi (1 - cos_max)). Written with 1 - cos in a cancellation-free form so
    that tiny cones (a distant sun, a small far sphere light) keep their precision."""
    cos_max = np.asarray(cos_max, dtype=np.float64)
    one_minus = np.asarray(one_minus_cos(cos_max), dtype=np.float64)
    one_minus_z = u[..., 0] * one_minus             # 1 - cos(theta), exactly
    z = 1.0 - one_minus_z
    sin_t = np.sqrt(np.maximum(0.0, one_minus_z * (2.0 - one_minus_z)))
    phi = 2.0 * np.pi * u[..., 1]
    return np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), z], axis=-1)


def one_minus_cos(cos_max):
    """1 - cos(theta) for cos(theta) = cos_max, without cancellation near 1."""
    cos_max = np.asarray(cos_max, dtype=np.float64)
    sin2 = np.maximum(0.0, 1.0 - cos_max * cos_max)
    return np.where(cos_max > 0.5, sin2 / (1.0 + cos_max), 1.0 - cos_max)


def orthonormal_basis(n: np.ndarray):
    """Two tangents (t, b) with (t, b, n) right-handed and orthonormal, for unit n
    (Duff et al. 2017, branchless)."""
    sign = np.where(n[..., 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + n[..., 2])
    b = n[..., 0] * n[..., 1] * a
    t = np.stack([1.0 + sign * n[..., 0] ** 2 * a, sign * b, -sign * n[..., 0]], axis=-1)
    bt = np.stack([b, sign + n[..., 1] ** 2 * a, -n[..., 1]], axis=-1)
    return t, bt


def to_world(local: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Rotate directions given about +Z into the frame of normal n."""
    t, b = orthonormal_basis(n)
    return local[..., 0:1] * t + local[..., 1:2] * b + local[..., 2:3] * n


def to_local(v: np.ndarray, n: np.ndarray) -> np.ndarray:
    t, b = orthonormal_basis(n)
    return np.stack([(v * t).sum(-1), (v * b).sum(-1), (v * n).sum(-1)], axis=-1)
