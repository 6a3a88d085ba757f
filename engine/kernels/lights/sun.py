"""Sun lamps (`engine.lights.SunLightModel`): a delta direction (T_SUN_DELTA) or a uniform
cone of half-angle angle / 2 (T_SUN), never hit as a surface (escaped rays see it)."""
from __future__ import annotations

import math

from ..jit import kernel
from .pack import (C_IRRADIANCE, C_ONE_MINUS, C_RAD, C_SUN_B, C_SUN_T, C_TO_LIGHT, C_TYPE,
                   T_SUN_DELTA)
from ..warp import TWO_PI, cone_from_one_minus_cos

INF = math.inf


@kernel(allocates=False)
def sample_sun(lamps, k, u0, u1):
    """A direction towards sun k: (wix, wiy, wiz, dist = inf, r, g, b, pdf, delta)."""
    if lamps[k, C_TYPE] == T_SUN_DELTA:
        return (lamps[k, C_TO_LIGHT], lamps[k, C_TO_LIGHT + 1], lamps[k, C_TO_LIGHT + 2],
                INF, lamps[k, C_IRRADIANCE], lamps[k, C_IRRADIANCE + 1],
                lamps[k, C_IRRADIANCE + 2], 1.0, True)
    om = lamps[k, C_ONE_MINUS]
    lx, ly, lz, _ = cone_from_one_minus_cos(u0, u1, om)
    wx = lx * lamps[k, C_SUN_T] + ly * lamps[k, C_SUN_B] + lz * lamps[k, C_TO_LIGHT]
    wy = lx * lamps[k, C_SUN_T + 1] + ly * lamps[k, C_SUN_B + 1] + lz * lamps[k, C_TO_LIGHT + 1]
    wz = lx * lamps[k, C_SUN_T + 2] + ly * lamps[k, C_SUN_B + 2] + lz * lamps[k, C_TO_LIGHT + 2]
    return (wx, wy, wz, INF, lamps[k, C_RAD], lamps[k, C_RAD + 1], lamps[k, C_RAD + 2],
            1.0 / (TWO_PI * om), False)


@kernel(allocates=False)
def inside_sun(lamps, k, dx, dy, dz):
    """Whether d is within the sun's disc (1 - cos compared exactly)."""
    ex = dx - lamps[k, C_TO_LIGHT]
    ey = dy - lamps[k, C_TO_LIGHT + 1]
    ez = dz - lamps[k, C_TO_LIGHT + 2]
    return 0.5 * (ex * ex + ey * ey + ez * ez) <= lamps[k, C_ONE_MINUS]


@kernel(allocates=False)
def pdf_sun(lamps, k, wix, wiy, wiz):
    """The solid-angle pdf of sampling wi (0 for a delta sun)."""
    if lamps[k, C_TYPE] == T_SUN_DELTA:
        return 0.0
    if inside_sun(lamps, k, wix, wiy, wiz):
        return 1.0 / (TWO_PI * lamps[k, C_ONE_MINUS])
    return 0.0


@kernel(allocates=False)
def escaped_sun(lamps, k, dx, dy, dz):
    """The radiance an escaping ray d sees (0 off the disc)."""
    if lamps[k, C_TYPE] == T_SUN_DELTA or not inside_sun(lamps, k, dx, dy, dz):
        return 0.0, 0.0, 0.0
    return lamps[k, C_RAD], lamps[k, C_RAD + 1], lamps[k, C_RAD + 2]
