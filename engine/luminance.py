"""The luminance lights are weighed by (Rec. 709 / sRGB primaries, Blender's default
scene-linear space)."""
from __future__ import annotations

import numpy as np


def luminance(rgb) -> float:
    r, g, b = np.asarray(rgb, dtype=np.float64)[..., :3].T
    return 0.2126 * r + 0.7152 * g + 0.0722 * b
