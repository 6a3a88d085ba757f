"""What every light model's sample() returns, and the luminance lights are weighed by."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

INF = np.inf


def luminance(rgb) -> float:
    r, g, b = np.asarray(rgb, dtype=np.float64)[..., :3].T
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


@dataclass
class LightSample:
    wi: np.ndarray        # (n, 3) unit direction towards the light
    dist: np.ndarray      # (n,) distance to the sampled point (inf for the sun)
    radiance: np.ndarray  # (n, 3) radiance arriving along -wi (0 where it cannot)
    pdf: np.ndarray       # (n,) solid-angle pdf (1 for delta lights; 0 = no sample)
    delta: bool           # a point or a zero-angle sun: no MIS, BSDF rays never hit it
    # (n,) how far before `dist` a shadow ray must stop so as not to hit the light
    # itself (emissive triangles are scene geometry); None = no such need
    margin: np.ndarray | None = None
