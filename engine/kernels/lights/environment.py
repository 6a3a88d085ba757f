"""The uniform world as a light (`engine.lights.EnvironmentLightModel`): uniform
directions over the sphere, pdf 1 / (4 pi); never hit as a surface."""
from __future__ import annotations

import math

from ..jit import kernel
from .pack import C_ENV_PDF, C_RAD
from ..warp import uniform_sphere

INF = math.inf


@kernel(allocates=False)
def sample_environment(lamps, k, u0, u1):
    """A uniform direction over the sphere: (wix, wiy, wiz, inf, r, g, b, pdf, delta = False)."""
    wx, wy, wz = uniform_sphere(u0, u1)
    return (wx, wy, wz, INF, lamps[k, C_RAD], lamps[k, C_RAD + 1], lamps[k, C_RAD + 2],
            lamps[k, C_ENV_PDF], False)


@kernel(allocates=False)
def pdf_environment(lamps, k):
    return lamps[k, C_ENV_PDF]
