"""Cycles' Hair BSDF node (kernel/closure/bsdf_hair.h, after Open Shading Language): a
fibre's reflection R and transmission TT lobes about its tangent T, with longitudinal
roughness r1 (RoughnessU), azimuthal roughness r2 (RoughnessV) and the cuticle tilt
`offset` (Cycles' bsdf->offset, minus the node's Offset; 0 on a mesh).

Angles, for a direction v: theta = asin(T.v), its tilt out of the plane normal to T;
phi, its azimuth about T measured from the view's own azimuth (the unit part of wo
perpendicular to T). With the view at theta_r and the light at theta_i, the half
angle t = (theta_i + theta_r) / 2 - offset follows a Cauchy distribution of width r1
cut to the light's range, and phi
  R:  phi = 2 r2 asin(1 - 2u), density cos(phi / (2 r2)) / (4 r2), |phi| <= pi r2;
  TT: phi = pi + r2 tan(c (u - 1/2)), c = 2 atan(pi / (2 r2)), a Cauchy density about
      pi (the light behind the fibre).
As in Cycles, each lobe's value f cos equals its pdf (weight 1 x the closure's colour
per sample), and evaluation, not sampling, restricts the light's side: R only where
N.wi >= 0 and the light's azimuth is within 90 degrees of the view's, TT only where
N.wi < 0. A sampled direction is kept on any side (the path may go into a mesh) with
the density `sample` returns, which `pdf` (evaluation's) may not give it.

Every function here is per unit colour, in the local shading frame (N = z) with the
tangent given in that frame: the integrator writes T per hit (engine.kernels.hair_tangent).
"""
from __future__ import annotations

import math

from ..jit import kernel

HALF_PI = 0.5 * math.pi
ROUGHNESS_MIN = 0.001        # Cycles' bsdf_hair_*_setup clamp, [0.001, 1]
POLE = 0.001                 # lights within this of T's direction (theta_i ~ +-pi/2): none


@kernel(allocates=False)
def clamp_roughness(r):
    return min(max(r, ROUGHNESS_MIN), 1.0)


@kernel(allocates=False)
def _split(tx, ty, tz, vx, vy, vz):
    """theta = asin(T.v) and v's unit part perpendicular to T; ok False when v lies
    along T (no azimuth)."""
    s = min(max(tx * vx + ty * vy + tz * vz, -1.0), 1.0)
    px, py, pz = vx - tx * s, vy - ty * s, vz - tz * s
    ln = math.sqrt(px * px + py * py + pz * pz)
    if not ln > 1e-12:
        return math.asin(s), 0.0, 0.0, 1.0, False
    return math.asin(s), px / ln, py / ln, pz / ln, True


@kernel(allocates=False)
def _theta_pdf(theta_r, theta_i, offset, r1, a, b):
    """The longitudinal density of the light's tilt theta_i (a, b: the atan bounds)."""
    t = 0.5 * (theta_i + theta_r) - offset
    return r1 / (2.0 * (t * t + r1 * r1) * (a - b) * math.cos(theta_i))


@kernel(allocates=False)
def _bounds(theta_r, offset, r1):
    a = math.atan((0.5 * (HALF_PI + theta_r) - offset) / r1)
    b = math.atan((0.5 * (-HALF_PI + theta_r) - offset) / r1)
    return a, b


@kernel(allocates=False)
def pdf(tx, ty, tz, offset, r1, r2, transmission, wox, woy, woz, wix, wiy, wiz):
    """Evaluation's pdf (= f cos per unit colour) of the R (transmission False) or TT
    lobe for light from wi, view wo, as Cycles' eval: 0 on the wrong side of N, and for
    R beyond 90 degrees of the view's azimuth."""
    if (wiz < 0.0) != transmission:
        return 0.0
    theta_r, lx, ly, lz, ok_r = _split(tx, ty, tz, wox, woy, woz)
    theta_i, ix, iy, iz, ok_i = _split(tx, ty, tz, wix, wiy, wiz)
    if not (ok_r and ok_i) or HALF_PI - abs(theta_i) < POLE:
        return 0.0
    cosphi = min(max(ix * lx + iy * ly + iz * lz, -1.0), 1.0)
    a, b = _bounds(theta_r, offset, r1)
    theta = _theta_pdf(theta_r, theta_i, offset, r1, a, b)
    if not transmission:
        if cosphi < 0.0:
            return 0.0
        phi = min(math.acos(cosphi) / r2, math.pi)
        return abs(math.cos(0.5 * phi) * 0.25 / r2 * theta)
    c = 2.0 * math.atan(HALF_PI / r2)
    p = math.pi - math.acos(cosphi)
    return abs(r2 / (c * (p * p + r2 * r2)) * theta)


@kernel(allocates=False)
def sample(tx, ty, tz, offset, r1, r2, transmission, wox, woy, woz, u1, u2):
    """A light direction for view wo: (wix, wiy, wiz, pdf), pdf 0 where none (Cycles'
    bsdf_hair_reflection_sample / _transmission_sample)."""
    theta_r, ly_x, ly_y, ly_z, ok = _split(tx, ty, tz, wox, woy, woz)
    if not ok:
        return 0.0, 0.0, 1.0, 0.0
    # locx = locy x T
    lx_x = ly_y * tz - ly_z * ty
    lx_y = ly_z * tx - ly_x * tz
    lx_z = ly_x * ty - ly_y * tx
    a, b = _bounds(theta_r, offset, r1)
    t = r1 * math.tan(u1 * (a - b) + b)
    theta_i = 2.0 * (t + offset) - theta_r
    if transmission:
        c = 2.0 * math.atan(HALF_PI / r2)
        p = r2 * math.tan(c * (u2 - 0.5))
        phi = p + math.pi
        phi_pdf = r2 / (c * (p * p + r2 * r2))
    else:
        phi = 2.0 * math.asin(min(max(1.0 - 2.0 * u2, -1.0), 1.0)) * r2
        # Cycles' sample reports cos(phi / 2) / (4 r2) (its eval, cos(phi / (2 r2)) /
        # (4 r2), is the density drawn): the same for RoughnessV 1, and only the MIS
        # weights see it, as its own
        phi_pdf = math.cos(0.5 * phi) * 0.25 / r2
    ci, si = math.cos(theta_i), math.sin(theta_i)
    cp, sp = math.cos(phi), math.sin(phi)
    wix = cp * ci * ly_x - sp * ci * lx_x + si * tx
    wiy = cp * ci * ly_y - sp * ci * lx_y + si * ty
    wiz = cp * ci * ly_z - sp * ci * lx_z + si * tz
    if HALF_PI - abs(theta_i) < POLE:
        return wix, wiy, wiz, 0.0
    return wix, wiy, wiz, abs(phi_pdf * _theta_pdf(theta_r, theta_i, offset, r1, a, b))
