"""Thin-lens aperture sampling: round or polygonal (bladed) apertures.

Only used when the camera has a non-zero aperture: a pinhole camera never reads the lens
dimension of the sampler (see `engine.camera`).
"""
from __future__ import annotations

import numpy as np

from .warp import concentric_disk


def sample_aperture(u: np.ndarray, radius: float, blades: int = 0, rotation: float = 0.0,
                    ratio: float = 1.0) -> np.ndarray:
    """Points on the aperture (camera-space x, y in metres), uniform in area.

    blades >= 3 gives a regular polygon inscribed in the circle of `radius` with corners
    at angles rotation + (2k + 1) pi / blades (Cycles' orientation); u.x picks the blade's triangle and is reused (rescaled) inside it,
    so strata stay strata. ratio is Blender's anamorphic aperture ratio: x is divided by
    it, as in Cycles.
    """
    if blades >= 3:
        k = np.minimum(np.floor(u[..., 0] * blades), blades - 1)
        u0 = u[..., 0] * blades - k                       # reuse the remainder
        # Uniform point in triangle (centre, corner k, corner k+1) with the square-root map.
        s = np.sqrt(u0)
        b1 = s * (1.0 - u[..., 1])                         # weight of corner k
        b2 = s * u[..., 1]                                 # weight of corner k+1
        # Corners at rotation + (2k + 1) pi / blades, as Cycles places them (an edge,
        # not a corner, faces +x at rotation 0).
        a0 = rotation + np.pi * (2.0 * k + 1.0) / blades
        a1 = a0 + 2.0 * np.pi / blades
        x = b1 * np.cos(a0) + b2 * np.cos(a1)
        y = b1 * np.sin(a0) + b2 * np.sin(a1)
        p = np.stack([x, y], axis=-1)
    else:
        p = concentric_disk(u)
    p = p * radius
    if ratio != 1.0:
        p[..., 0] /= ratio
    return p


def aperture_area(radius: float, blades: int = 0, ratio: float = 1.0) -> float:
    if blades >= 3:
        area = 0.5 * blades * radius * radius * np.sin(2.0 * np.pi / blades)
    else:
        area = np.pi * radius * radius
    return area / ratio
