"""Directions uniform in the solid angle a triangle subtends: J. Arvo, "Stratified
Sampling of Spherical Triangles" (SIGGRAPH 1995), the sampler Cycles uses for emissive
triangles near the shading point (triangles.py says when).

The triangle seen from p projects to the spherical triangle of unit vectors a, b, c. Its
area, the solid angle, is (Van Oosterom and Strackee)
    omega = 2 atan2(|a . (b x c)|, 1 + a.b + b.c + c.a).
Arvo's map of (u0, u1) in [0, 1)^2: with alpha the spherical angle at a, the sub-triangle
(a, b, c') of area u0 omega has its third corner c' on the arc from a to c at
    cos(arc a c') = q = ((v cos(phi) - w sin(phi)) cos(alpha) - v)
                        / ((v sin(phi) + w cos(phi)) sin(alpha)),
    phi = u0 omega - alpha, w = cos(phi) - cos(alpha), v = sin(phi) + sin(alpha) (a.b),
so c' = q a + sqrt(1 - q^2) (the unit part of c orthogonal to a); the direction is then
uniform in the cosine along the arc from b to c':
    z = 1 - u1 (1 - c'.b),  d = z b + sqrt(1 - z^2) (the unit part of c' orthogonal to b).
The density of d is 1 / omega everywhere on the spherical triangle."""
from __future__ import annotations

import math

from ..frame import cross, dot, unit
from ..jit import kernel


@kernel(allocates=False)
def solid_angle(ax, ay, az, bx, by, bz, cx, cy, cz):
    """The solid angle of the spherical triangle of unit vectors a, b, c."""
    bcx, bcy, bcz = cross(bx, by, bz, cx, cy, cz)
    triple = abs(dot(ax, ay, az, bcx, bcy, bcz))
    return 2.0 * math.atan2(triple, 1.0 + dot(ax, ay, az, bx, by, bz)
                            + dot(bx, by, bz, cx, cy, cz) + dot(ax, ay, az, cx, cy, cz))


@kernel(allocates=False)
def _orthogonal_unit(x, y, z, ax, ay, az):
    """The unit part of (x, y, z) orthogonal to the unit vector a."""
    k = dot(x, y, z, ax, ay, az)
    return unit(x - k * ax, y - k * ay, z - k * az)


@kernel(allocates=False)
def sample_direction(ax, ay, az, bx, by, bz, cx, cy, cz, omega, u0, u1):
    """Arvo's direction for (u0, u1) in the spherical triangle of unit vectors a, b, c of
    solid angle omega (> 0)."""
    # the angle at a, between the great circles a-b and a-c
    n1x, n1y, n1z = cross(ax, ay, az, bx, by, bz)
    n1x, n1y, n1z = unit(n1x, n1y, n1z)
    n2x, n2y, n2z = cross(ax, ay, az, cx, cy, cz)
    n2x, n2y, n2z = unit(n2x, n2y, n2z)
    cos_alpha = min(max(dot(n1x, n1y, n1z, n2x, n2y, n2z), -1.0), 1.0)
    sin_alpha = math.sqrt(max(1.0 - cos_alpha * cos_alpha, 0.0))
    alpha = math.acos(cos_alpha)
    phi = u0 * omega - alpha
    s, t = math.sin(phi), math.cos(phi)
    w = t - cos_alpha
    v = s + sin_alpha * dot(ax, ay, az, bx, by, bz)
    den = (v * s + w * t) * sin_alpha
    q = ((v * t - w * s) * cos_alpha - v) / den if den != 0.0 else 1.0
    q = min(max(q, -1.0), 1.0)
    ux, uy, uz = _orthogonal_unit(cx, cy, cz, ax, ay, az)
    sq = math.sqrt(max(1.0 - q * q, 0.0))
    px, py, pz = unit(q * ax + sq * ux, q * ay + sq * uy, q * az + sq * uz)
    z = 1.0 - u1 * (1.0 - dot(px, py, pz, bx, by, bz))
    z = min(max(z, -1.0), 1.0)
    ox, oy, oz = _orthogonal_unit(px, py, pz, bx, by, bz)
    sz = math.sqrt(max(1.0 - z * z, 0.0))
    return unit(z * bx + sz * ox, z * by + sz * oy, z * bz + sz * oz)
