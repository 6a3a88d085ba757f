"""Equiangular sampling of a distance along a ray towards a point light (Kulla and
Fajardo 2012, "Importance Sampling Techniques for Path Tracing in Participating Media"),
to be combined with the distance sampling of volume.segment (volume.distance_pdf).

In a medium the light a ray's segment scatters towards the camera is an integral over
the distance t along it. Sampling t by the medium's transmittance (volume.segment) puts
few points near a lamp in thin fog, where the integrand 1 / r(t)^2 peaks, and a spot
beam renders as fireflies. The equiangular density is proportional to that 1 / r^2 for
a point c:

    pdf(t) = D / ((theta_b - theta_a) (D^2 + (t - delta)^2)),   t in [t_lo, t_hi],

with delta = (c - o).d the foot of c on the ray, D the distance of c from the ray, and
theta = atan((t - delta) / D) at the segment's ends; t = delta + D tan(theta_a +
u (theta_b - theta_a)). t_hi may be infinite (theta_b = pi / 2). The range is the part
of the segment the light can reach (lights/lit_segment.py: a spot's cone, an area
lamp's front), as Cycles clips its equiangular segments. A point on the ray (D
= 0) is held at a small distance (D_MIN relative to the segment's scale), so the density
stays finite. The direct light of a segment is estimated with both strategies and
multiple importance sampling (medium_vertex.py), as Cycles' "Multiple Importance" volume
sampling (its default).
"""
from __future__ import annotations

import math

from .jit import kernel

D_MIN = 1e-9            # the least distance of c from the ray, relative to its scale


@kernel(allocates=False)
def _frame(ox, oy, oz, dx, dy, dz, cx, cy, cz, t_lo, t_hi):
    """(delta, D, theta_a, theta_b) of point c for the ray o + t d, t in [t_lo, t_hi]."""
    vx, vy, vz = cx - ox, cy - oy, cz - oz
    delta = vx * dx + vy * dy + vz * dz
    px, py, pz = vx - delta * dx, vy - delta * dy, vz - delta * dz
    scale = max(abs(delta), math.sqrt(vx * vx + vy * vy + vz * vz), 1e-30)
    D = max(math.sqrt(px * px + py * py + pz * pz), D_MIN * scale)
    theta_a = math.atan2(t_lo - delta, D)
    theta_b = math.atan2(t_hi - delta, D) if math.isfinite(t_hi) else 0.5 * math.pi
    return delta, D, theta_a, theta_b


@kernel(allocates=False)
def sample(ox, oy, oz, dx, dy, dz, cx, cy, cz, t_lo, t_hi, u):
    """A distance t in [t_lo, t_hi] with density proportional to 1 / |o + t d - c|^2,
    and its pdf (0 when the range has no length)."""
    if not t_hi > t_lo:
        return 0.0, 0.0
    delta, D, theta_a, theta_b = _frame(ox, oy, oz, dx, dy, dz, cx, cy, cz, t_lo, t_hi)
    span = theta_b - theta_a
    if not span > 0.0:
        return 0.0, 0.0
    t = delta + D * math.tan(theta_a + u * span)
    t = min(max(t, t_lo), t_hi)
    r = t - delta
    return t, D / (span * (D * D + r * r))


@kernel(allocates=False)
def pdf(ox, oy, oz, dx, dy, dz, cx, cy, cz, t_lo, t_hi, t):
    """The density of `sample` at distance t."""
    if not (t >= t_lo and t <= t_hi and t_hi > t_lo):
        return 0.0
    delta, D, theta_a, theta_b = _frame(ox, oy, oz, dx, dy, dz, cx, cy, cz, t_lo, t_hi)
    span = theta_b - theta_a
    if not span > 0.0:
        return 0.0
    r = t - delta
    return D / (span * (D * D + r * r))
