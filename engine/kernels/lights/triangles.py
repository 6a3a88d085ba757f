"""Emissive triangles as lights (`engine.mesh_lights.EmissiveTriangles`), sampled as Cycles
samples them: uniform in solid angle (Arvo's map) from a point near the triangle, else
uniform in area (Heitz's low-distortion square-to-triangle map); two-sided emission,
sampled from the sides the material's Emission Sampling names (`sampled_side`).

Which of the two pdfs a sample has matters beyond noise where next-event estimation
alone reaches the light: light from under a smooth-shaded triangle's own plane, which
Cycles' BSDF sampling refuses (below the geometric normal) while its light sampling
takes it with the MIS weight of its own pdf."""
from __future__ import annotations

import math

from ..frame import unit
from ..jit import kernel
from ..bsdf.layered_emission import TINT, dimmed
from .pack import (EMIT_DIM, NEE_BACK_OFF, NEE_FRONT_OFF, TRI_AREA, TRI_DIM, TRI_E1,
                   TRI_E2, TRI_ENTRY, TRI_NORMAL, TRI_PRIM, TRI_RADIANCE, TRI_V0,
                   TRI_VISIBILITY)
from .spherical_triangle import sample_direction, solid_angle


# Shadow rays stop this far (relative to the sampled point's largest coordinate, over
# the cosine at the light) short of it: 8 float32 ulps, past the float32 rounding of
# a coincident copy of the emitter, which would otherwise block half of them.
REACH = 2.0 ** -21

# A point this close to a triangle's plane (|cos| at the triangle) gets none of its light:
# its cosine is rounding there (a point on a coplanar emitter), and the light it would
# carry, radiance x |cos|, is nothing; sampling and the pdf agree on it.
GRAZING = 1e-9


@kernel(allocates=False)
def square_to_triangle(u0, u1):
    """Heitz's square-to-triangle map: edge weights (b1, b2), uniform in area."""
    if u1 > u0:
        return 0.5 * u0, u1 - 0.5 * u0
    return u0 - 0.5 * u1, 0.5 * u1


@kernel(allocates=False)
def sampled_side(L, j, to_plane):
    """Whether next-event estimation samples triangle entry j from a point whose signed
    distance term to its plane is to_plane (`_corners_from`; positive: behind it, where
    its normal does not point): its material's Emission Sampling names that side, as
    Cycles decides by the sign of the distance to the plane."""
    off = L[TRI_VISIBILITY][j] & (NEE_FRONT_OFF | NEE_BACK_OFF)
    return off == 0 or (off & (NEE_BACK_OFF if to_plane > 0.0 else NEE_FRONT_OFF)) == 0


@kernel(allocates=False)
def _corners_from(L, j, px, py, pz):
    """Triangle entry j's corners less p (a, b, c), and whether Cycles samples it by
    solid angle from p: when its longest edge squared exceeds the square of its plane's
    distance to p divided by twice its area (Cycles' triangle_light_sample and
    triangle_light_pdf compare the edge with dot(N, V0 - P) / |N|^2, N the unnormalised
    normal: a heuristic of mixed units, kept as it is, since it decides the MIS weights
    of the light that only next-event estimation finds), and that distance term (signed:
    positive behind the triangle, for `sampled_side`)."""
    v0, e1, e2, nrm = L[TRI_V0], L[TRI_E1], L[TRI_E2], L[TRI_NORMAL]
    ax, ay, az = v0[j, 0] - px, v0[j, 1] - py, v0[j, 2] - pz
    bx, by, bz = ax + e1[j, 0], ay + e1[j, 1], az + e1[j, 2]
    cx, cy, cz = ax + e2[j, 0], ay + e2[j, 1], az + e2[j, 2]
    e0 = e1[j, 0] ** 2 + e1[j, 1] ** 2 + e1[j, 2] ** 2
    e_1 = e2[j, 0] ** 2 + e2[j, 1] ** 2 + e2[j, 2] ** 2
    e_2 = ((e2[j, 0] - e1[j, 0]) ** 2 + (e2[j, 1] - e1[j, 1]) ** 2
           + (e2[j, 2] - e1[j, 2]) ** 2)
    longest = max(e0, max(e_1, e_2))
    to_plane = (nrm[j, 0] * ax + nrm[j, 1] * ay + nrm[j, 2] * az) / (2.0 * L[TRI_AREA][j])
    return ax, ay, az, bx, by, bz, cx, cy, cz, longest > to_plane * to_plane, to_plane


@kernel(allocates=False)
def _spherical(ax, ay, az, bx, by, bz, cx, cy, cz):
    """The corners as unit vectors and their solid angle."""
    ax, ay, az = unit(ax, ay, az)
    bx, by, bz = unit(bx, by, bz)
    cx, cy, cz = unit(cx, cy, cz)
    return ax, ay, az, bx, by, bz, cx, cy, cz, solid_angle(ax, ay, az, bx, by, bz, cx, cy,
                                                           cz)


@kernel(allocates=False)
def sample_triangle(L, j, px, py, pz, u0, u1):
    """A point of triangle entry j seen from p (pick probability NOT included), as
    Cycles samples it: uniform in the solid angle it subtends when it is near
    (`_corners_from`; Arvo's map, spherical_triangle.py), else uniform in area (Heitz's
    map): (wix, wiy, wiz, dist, r, g, b, pdf, prim, margin), (r, g, b) its radiance
    towards p (a coat's tint dims it: bsdf.layered_emission), pdf in solid angle, prim
    the triangle's global id, which the shadow ray towards the point names
    (engine.embree.self_hits) so that it does not meet the light itself, as Cycles'
    shadow rays name ls->prim, and margin how far short of the point it stops (REACH)."""
    v0, e1, e2, nrm = L[TRI_V0], L[TRI_E1], L[TRI_E2], L[TRI_NORMAL]
    ax, ay, az, bx, by, bz, cx, cy, cz, near, to_plane = _corners_from(L, j, px, py, pz)
    pdf = 0.0
    if near:
        ax, ay, az, bx, by, bz, cx, cy, cz, omega = _spherical(ax, ay, az, bx, by, bz,
                                                               cx, cy, cz)
        wx, wy, wz = 0.0, 0.0, 1.0
        dist = 0.0
        if omega > 0.0:
            wx, wy, wz = sample_direction(ax, ay, az, bx, by, bz, cx, cy, cz, omega, u0,
                                          u1)
            # where the direction meets the triangle's plane
            den = wx * nrm[j, 0] + wy * nrm[j, 1] + wz * nrm[j, 2]
            num = ((v0[j, 0] - px) * nrm[j, 0] + (v0[j, 1] - py) * nrm[j, 1]
                   + (v0[j, 2] - pz) * nrm[j, 2])
            if den != 0.0 and num / den > 0.0:
                dist = num / den
                pdf = 1.0 / omega
        qx, qy, qz = px + wx * dist, py + wy * dist, pz + wz * dist
    else:
        b1, b2 = square_to_triangle(u0, u1)
        qx = v0[j, 0] + b1 * e1[j, 0] + b2 * e2[j, 0]
        qy = v0[j, 1] + b1 * e1[j, 1] + b2 * e2[j, 1]
        qz = v0[j, 2] + b1 * e1[j, 2] + b2 * e2[j, 2]
        tx, ty, tz = qx - px, qy - py, qz - pz
        dist = math.sqrt(tx * tx + ty * ty + tz * tz)
        if dist > 0.0:
            wx, wy, wz = tx / dist, ty / dist, tz / dist
        else:
            wx, wy, wz = 0.0, 0.0, 1.0
    cos_l = abs(wx * nrm[j, 0] + wy * nrm[j, 1] + wz * nrm[j, 2])
    if not (dist > 0.0 and cos_l > GRAZING and sampled_side(L, j, to_plane)):
        return wx, wy, wz, dist, 0.0, 0.0, 0.0, 0.0, L[TRI_PRIM][j], 0.0
    if not near:
        pdf = dist * dist / (L[TRI_AREA][j] * cos_l)
    if not pdf > 0.0:
        return wx, wy, wz, dist, 0.0, 0.0, 0.0, 0.0, L[TRI_PRIM][j], 0.0
    rad = L[TRI_RADIANCE]
    r, g, b = rad[j, 0], rad[j, 1], rad[j, 2]
    dim = L[TRI_DIM]
    if dim.shape[0] > 0 and dim[j] >= 0:      # under a tinted coat, at the angle seen
        r, g, b = dimmed(L[EMIT_DIM], dim[j], TINT, cos_l, r, g, b)
    margin = REACH * max(abs(qx), abs(qy), abs(qz)) / cos_l
    return wx, wy, wz, dist, r, g, b, pdf, L[TRI_PRIM][j], margin


@kernel(allocates=False)
def triangle_entry(L, prim):
    """The light entry of global triangle id prim, or -1."""
    entry = L[TRI_ENTRY]
    if prim >= 0 and prim < entry.shape[0]:
        return entry[prim]
    return -1


@kernel(allocates=False)
def pdf_triangle(L, j, px, py, pz, qx, qy, qz):
    """The solid-angle pdf at p of the point q on triangle entry j, as `sample_triangle`
    draws it: 1 / (its solid angle) when near, else d^3 / (A |n . (q - p)|); 0 from a
    side not sampled."""
    ax, ay, az, bx, by, bz, cx, cy, cz, near, to_plane = _corners_from(L, j, px, py, pz)
    if not sampled_side(L, j, to_plane):
        return 0.0
    tx, ty, tz = qx - px, qy - py, qz - pz
    d2 = tx * tx + ty * ty + tz * tz
    nrm = L[TRI_NORMAL]
    cos_abs_d = abs(tx * nrm[j, 0] + ty * nrm[j, 1] + tz * nrm[j, 2])
    if not (cos_abs_d > GRAZING * math.sqrt(d2) and d2 > 0.0):
        return 0.0
    if near:
        omega = _spherical(ax, ay, az, bx, by, bz, cx, cy, cz)[9]
        return 1.0 / omega if omega > 0.0 else 0.0
    return d2 * math.sqrt(d2) / (L[TRI_AREA][j] * cos_abs_d)
