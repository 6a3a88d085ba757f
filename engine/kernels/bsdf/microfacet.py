"""The GGX (Trowbridge-Reitz) microfacet distribution, Smith masking, and sampling of
visible normals; plus the GGX reflection lobe built from them, one direction at a time.
Its Beckmann counterpart is beckmann.py; distribution.py picks one of the two per closure.

Sources:
  * D: Trowbridge & Reitz 1975; Walter et al. 2007, "Microfacet Models for Refraction
    through Rough Surfaces", eq. 33:  D(h) = 1 / (pi a^2 cos^4 t (1 + tan^2 t / a^2)^2),
    written here as 1 / (pi a^2 (h_z^2 + (h_x^2 + h_y^2) / a^2)^2), which has no tangent
    and stays finite for every unit h. Units: 1/sr (normalised so that
    integral D(h) cos(theta_h) d(omega_h) = 1).
  * Smith G1 (Walter et al. 2007 eq. 34; Heitz 2014, "Understanding the Masking-Shadowing
    Function in Microfacet-Based BRDFs", JCGT 3(2)): G1 = 2 |z| / (|z| + sqrt(z^2 + a^2 s^2))
    with s^2 = x^2 + y^2, the same as 2 / (1 + sqrt(1 + a^2 tan^2 theta)) but defined at
    z = 0 (G1 = 0) and at the normal (G1 = 1).
  * Height-correlated G2 = 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014), here
    2 |zo| |zi| / (|zi| r_o + |zo| r_i) with r = sqrt(z^2 + a^2 s^2).
  * Visible-normal sampling: Heitz 2018, "Sampling the GGX Distribution of Visible
    Normals" (JCGT 7(4)), listing 1; pdf of the sampled normal
    D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo_z.

Directions are three floats (x, y, z), unit, in the local frame (normal = +Z), pointing
away from the surface. `alpha` is the isotropic GGX roughness (Blender/Cycles:
alpha = roughness^2), dimensionless. It is clamped to [ALPHA_MIN, 1] = [1e-4, 1]:
roughness 0 would make D a Dirac delta; at alpha = 1e-4 the lobe is ~0.01 degrees wide
(a mirror to the eye) while every quantity stays an ordinary finite function (peak
D = 1/(pi alpha^2) ~ 3e7 /sr, reflection pdf ~ 8e6 /sr), so the reflection lobes need no
separate delta code path and MIS weights stay meaningful; alpha > 1 is not a Blender
roughness. Every function is finite for wo at the normal, at grazing angles down to
wo_z = 0, and for alpha at either clamp.
"""
from __future__ import annotations

import math

from ..jit import kernel

ALPHA_MIN = 1e-4
INV_PI = 1.0 / math.pi
TWO_PI = 2.0 * math.pi


@kernel
def clamp_alpha(alpha):
    return min(max(alpha, ALPHA_MIN), 1.0)


@kernel
def r_len(x, y, z, a2):
    """sqrt(z^2 + a^2 (x^2 + y^2)): |z| (1 + 2 Lambda) of Smith's GGX Lambda."""
    s2 = x * x + y * y
    return math.sqrt(z * z + a2 * s2)


@kernel
def dot(ax, ay, az, bx, by, bz):
    return ax * bx + ay * by + az * bz


@kernel
def normalize(x, y, z):
    n = max(math.sqrt(x * x + y * y + z * z), 1e-300)
    return x / n, y / n, z / n


@kernel
def D(hx, hy, hz, alpha):
    """GGX normal distribution (1/sr) of the unit half vector h; zero for h_z <= 0."""
    if not hz > 0.0:
        return 0.0
    a = clamp_alpha(alpha)
    a2 = a * a
    s2 = hx * hx + hy * hy
    m = s2 / a2 + hz * hz
    if not m > 0.0:
        m = 1.0
    return INV_PI / (a2 * m * m)


@kernel
def G1_over_cos(x, y, z, alpha):
    """G1(w) / |w_z| = 2 / (|w_z| + r(w)), finite at w_z = 0."""
    a = clamp_alpha(alpha)
    den = abs(z) + r_len(x, y, z, a * a)
    return 2.0 / max(den, 1e-300)


@kernel
def G2_over_G1(ox, oy, oz, ix, iy, iz, alpha):
    """G2(wo, wi) / G1(wo) of the height-correlated Smith masking: the weight of a
    VNDF-sampled reflection or refraction, |wi_z| (|wo_z| + r(wo)) / (|wi_z| r(wo) +
    |wo_z| r(wi))."""
    a = clamp_alpha(alpha)
    a2 = a * a
    zo = abs(oz)
    zi = abs(iz)
    ro = r_len(ox, oy, oz, a2)
    den = zi * ro + zo * r_len(ix, iy, iz, a2)
    if not den > 0.0:
        return 0.0
    return zi * (zo + ro) / den


@kernel
def half_vector(ox, oy, oz, ix, iy, iz):
    """Normalised wo + wi and whether it is defined (wi != -wo)."""
    hx = ox + ix
    hy = oy + iy
    hz = oz + iz
    n = math.sqrt(hx * hx + hy * hy + hz * hz)
    ok = n > 1e-12
    if not ok:
        n = 1.0
    return hx / n, hy / n, hz / n, ok


@kernel
def reflection_eval(ox, oy, oz, ix, iy, iz, alpha):
    """(D G2 / (4 |wo_z| |wi_z|), h) of the upper-hemisphere GGX reflection; the value
    is zero unless wo_z, wi_z > 0. Multiply by a Fresnel term for the BRDF."""
    a = clamp_alpha(alpha)
    a2 = a * a
    hx, hy, hz, ok = half_vector(ox, oy, oz, ix, iy, iz)
    if not (ok and oz > 0.0 and iz > 0.0):
        return 0.0, hx, hy, hz
    den = iz * r_len(ox, oy, oz, a2) + oz * r_len(ix, iy, iz, a2)
    if not den > 0.0:
        return 0.0, hx, hy, hz
    return D(hx, hy, hz, a) / (2.0 * den), hx, hy, hz


@kernel
def reflection_pdf(ox, oy, oz, ix, iy, iz, alpha):
    """pdf over wi (1/sr) of VNDF-sampled reflection: G1(wo) D / (4 wo_z)."""
    hx, hy, hz, ok = half_vector(ox, oy, oz, ix, iy, iz)
    if not (ok and oz > 0.0 and iz > 0.0):
        return 0.0
    return 0.25 * G1_over_cos(ox, oy, oz, alpha) * D(hx, hy, hz, alpha)


@kernel
def sample_visible_normal(ox, oy, oz, alpha, u0, u1):
    """A microfacet normal h ~ D_wo(h) for wo_z >= 0 (Heitz 2018, listing 1)."""
    a = clamp_alpha(alpha)
    # stretch wo to the configuration with alpha = 1 (hemisphere)
    vx, vy, vz = normalize(a * ox, a * oy, max(oz, 0.0))
    lensq = vx * vx + vy * vy
    if lensq > 0.0:
        inv_len = 1.0 / math.sqrt(lensq)
        t1x, t1y, t1z = -vy * inv_len, vx * inv_len, 0.0
    else:
        t1x, t1y, t1z = 1.0, 0.0, 0.0
    # t2 = cross(vh, t1), written as numpy.cross evaluates it
    t2x = vy * t1z - vz * t1y
    t2y = vz * t1x - vx * t1z
    t2z = vx * t1y - vy * t1x
    # uniform point on the projected disk, warped onto the visible half
    r = math.sqrt(u0)
    phi = TWO_PI * u1
    p1 = r * math.cos(phi)
    p2 = r * math.sin(phi)
    s = 0.5 * (1.0 + vz)
    p2 = (1.0 - s) * math.sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2
    pz = math.sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2))
    nx = p1 * t1x + p2 * t2x + pz * vx
    ny = p1 * t1y + p2 * t2y + pz * vy
    nz = p1 * t1z + p2 * t2z + pz * vz
    # unstretch
    return normalize(a * nx, a * ny, max(nz, 0.0))


@kernel
def reflect(ox, oy, oz, hx, hy, hz):
    """Mirror wo about the unit normal h."""
    c2 = 2.0 * dot(ox, oy, oz, hx, hy, hz)
    return c2 * hx - ox, c2 * hy - oy, c2 * hz - oz


@kernel
def reflection_sample(ox, oy, oz, alpha, u0, u1):
    """Sample the GGX reflection from wo: (wi_x, wi_y, wi_z, valid)."""
    hx, hy, hz = sample_visible_normal(ox, oy, oz, alpha, u0, u1)
    ix, iy, iz = reflect(ox, oy, oz, hx, hy, hz)
    valid = (oz > 0.0 and iz > 0.0 and hz > 0.0
             and dot(ox, oy, oz, hx, hy, hz) > 0.0)
    return ix, iy, iz, valid

