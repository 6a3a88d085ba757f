"""Cycles' microfiber sheen (kernel/closure/bsdf_sheen.h; Zeltner, Burley and Chiang,
"Practical Multiple-Scattering Sheen Using Linearly Transformed Cosines", 2022): the
Sheen BSDF node's default distribution and Principled's sheen layer.

The lobe is a linearly transformed cosine in a frame whose x axis is the azimuth of wo:
with v = M^-1 wi = (a x + b z, a y, z) for wi = (x, y, z),

    f(wo, wi) |cos theta_i| = R z a^2 / (pi |v|^4)   (z > 0),

which integrates to R over the directions the transform maps above the surface. The LTC
parameters a, b and the albedo R are tables over (cos theta_o, roughness), read as Cycles
reads its table (bilinear on uniform 32 x 32 grids over [0, 1]^2, roughness clamped to
[1e-3, 1]); DRT's table is measured from Cycles' renders (engine/bsdf/sheen_table.py).
Sampling: a cosine-weighted direction transformed by M = [[1/a, 0, -b/a], [0, 1/a, 0],
[0, 0, 1]] and normalised, whose density is exactly the lobe's shape above.

As a layer (Principled's "first layer"), everything below is dimmed by
1 - max over channels of weight tint R(wo) (Cycles' closure_layering_weight).
"""
from __future__ import annotations

import math

from ..jit import kernel
from ..warp import cosine_hemisphere
from .tables import T_SHEEN

INV_PI = 1.0 / math.pi
ROUGH_MIN = 1e-3


@kernel
def _lerp_node(v, n):
    """(i0, i1, t) of v in [0, 1] on a uniform grid of n nodes (Cycles' lookup_table_read)."""
    x = min(max(v, 0.0), 1.0) * (n - 1)
    i0 = min(int(x), n - 1)
    i1 = min(i0 + 1, n - 1)
    return i0, i1, x - i0


@kernel
def lookup(cos_o, roughness, tables):
    """(a, b, R) at cos theta_o and roughness, bilinear in the table."""
    t = tables[T_SHEEN]
    n_r, n_mu = t.shape[1], t.shape[2]
    r = min(max(roughness, ROUGH_MIN), 1.0)
    j0, j1, tj = _lerp_node(r, n_r)
    i0, i1, ti = _lerp_node(cos_o, n_mu)
    out0 = (1.0 - tj) * ((1.0 - ti) * t[0, j0, i0] + ti * t[0, j0, i1]) + \
        tj * ((1.0 - ti) * t[0, j1, i0] + ti * t[0, j1, i1])
    out1 = (1.0 - tj) * ((1.0 - ti) * t[1, j0, i0] + ti * t[1, j0, i1]) + \
        tj * ((1.0 - ti) * t[1, j1, i0] + ti * t[1, j1, i1])
    out2 = (1.0 - tj) * ((1.0 - ti) * t[2, j0, i0] + ti * t[2, j0, i1]) + \
        tj * ((1.0 - ti) * t[2, j1, i0] + ti * t[2, j1, i1])
    return out0, out1, out2


@kernel
def azimuth(ox, oy):
    """(cx, cy): the unit tangent towards wo's azimuth ((1, 0) at normal incidence)."""
    n = math.sqrt(ox * ox + oy * oy)
    if not n > 1e-12:
        return 1.0, 0.0
    return ox / n, oy / n


@kernel
def shape(ix, iy, iz, cx, cy, a, b):
    """a^2 / (pi |M^-1 wi|^4): f / R (1/sr) for wi above the surface, else 0."""
    if not iz > 0.0:
        return 0.0
    x = ix * cx + iy * cy
    y = iy * cx - ix * cy
    vx = a * x + b * iz
    vy = a * y
    len2 = vx * vx + vy * vy + iz * iz
    return INV_PI * (a / len2) * (a / len2)


@kernel
def pdf(ix, iy, iz, cx, cy, a, b):
    """Density (1/sr) of `sample`: z a^2 / (pi |M^-1 wi|^4)."""
    return iz * shape(ix, iy, iz, cx, cy, a, b)


@kernel
def sample(u1, u2, cx, cy, a, b):
    """A direction distributed as the lobe (may fall below the surface: then invalid)."""
    dx, dy, dz = cosine_hemisphere(u1, u2)
    x = (dx - dz * b) / a
    y = dy / a
    z = dz
    n = math.sqrt(x * x + y * y + z * z)
    x, y, z = x / n, y / n, z / n
    return x * cx - y * cy, x * cy + y * cx, z
