"""Bounding cones of emission directions, as the light tree bounds its lights' normals
(Conty Estevez and Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree
Splitting", section 4.1; the same cone as Cycles' `OrientationBounds`).

A cone is (axis, theta_o, theta_e): every emitter inside emits along directions within
theta_o of the axis, each spreading its light up to theta_e further (pi/2 for a
Lambertian surface). An empty cone has theta_o < 0.
"""
from __future__ import annotations

import math

from ..jit import kernel

PI = math.pi
EMPTY = -1.0


@kernel(allocates=False)
def measure(theta_o, theta_e):
    """The cone's orientation measure M_Omega (the paper's Eq. 1): the integral over
    the directions the cone's emitters can reach, cosine-weighted past theta_o."""
    if theta_o < 0.0:
        return 0.0
    theta_w = min(PI, theta_o + theta_e)
    co, so = math.cos(theta_o), math.sin(theta_o)
    return (2.0 * PI * (1.0 - co)
            + 0.5 * PI * (2.0 * theta_w * so - math.cos(theta_o - 2.0 * theta_w)
                          - 2.0 * theta_o * so + co))


@kernel(allocates=False)
def merge(ax, ay, az, ao, ae, bx, by, bz, bo, be):
    """The smallest cone of this construction holding cones a and b (either may be
    empty): (x, y, z, theta_o, theta_e)."""
    if ao < 0.0:
        return bx, by, bz, bo, be
    if bo < 0.0:
        return ax, ay, az, ao, ae
    if bo > ao:                       # a has the wider theta_o
        ax, ay, az, ao, ae, bx, by, bz, bo, be = bx, by, bz, bo, be, ax, ay, az, ao, ae
    cos_ab = ax * bx + ay * by + az * bz
    theta_d = math.acos(min(1.0, max(-1.0, cos_ab)))
    theta_e = max(ae, be)
    if ao + 5e-4 >= min(PI, theta_d + bo):
        return ax, ay, az, ao, theta_e            # a already holds b
    theta_o = 0.5 * (theta_d + ao + bo)
    if theta_o >= PI:
        return ax, ay, az, PI, theta_e
    if cos_ab < -0.9995:
        # opposite axes: any axis orthogonal to a's
        if abs(ax) < 0.9:
            ox, oy, oz = 0.0, -az, ay
        else:
            ox, oy, oz = az, 0.0, -ax
        n = math.sqrt(ox * ox + oy * oy + oz * oz)
        return ox / n, oy / n, oz / n, theta_o, theta_e
    # rotate a's axis towards b's by theta_o - theta_o(a)
    theta_r = theta_o - ao
    ox, oy, oz = bx - ax * cos_ab, by - ay * cos_ab, bz - az * cos_ab
    n = math.sqrt(ox * ox + oy * oy + oz * oz)
    if n > 0.0:
        ox, oy, oz = ox / n, oy / n, oz / n
    c, s = math.cos(theta_r), math.sin(theta_r)
    return ax * c + ox * s, ay * c + oy * s, az * c + oz * s, theta_o, theta_e


@kernel(allocates=False)
def box_measure(x0, y0, z0, x1, y1, z1):
    """A box's surface area, or its diagonal when it is flat (the paper's M_A)."""
    dx, dy, dz = max(x1 - x0, 0.0), max(y1 - y0, 0.0), max(z1 - z0, 0.0)
    area = 2.0 * (dx * dy + dy * dz + dz * dx)
    if area == 0.0:
        return math.sqrt(dx * dx + dy * dy + dz * dz)
    return area
