"""Lambertian reflection: f = albedo / pi, sampled by the cosine-weighted hemisphere.

All directions are in the local shading frame (normal = +Z), pointing away from the
surface. Reflection only: wi below the surface gives zero. wo may be below it too (the
view at a smooth mesh's silhouette, under the interpolated normal): as Cycles' diffuse
closure, only wi's side counts.
"""
from __future__ import annotations

import numpy as np

from ..warp import INV_PI, cosine_hemisphere


def eval_f(albedo: np.ndarray, wo: np.ndarray, wi: np.ndarray) -> np.ndarray:
    return np.where((wi[:, 2] > 0)[:, None], albedo * INV_PI, 0.0)


def pdf(wo: np.ndarray, wi: np.ndarray) -> np.ndarray:
    return np.where(wi[:, 2] > 0, wi[:, 2] * INV_PI, 0.0)


def sample(wo: np.ndarray, u: np.ndarray) -> np.ndarray:
    return cosine_hemisphere(u)
