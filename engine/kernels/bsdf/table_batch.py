"""Array drivers of the BSDF's table lookups (albedo.py's specular-layer albedo,
multiscatter.py's energy-compensation tables), compiled: for the tests that check the
tables and their interpolation against quadrature and closed forms. Arguments are
broadcast against each other; the result has their common shape."""
from __future__ import annotations

import numpy as np

from ..jit import kernel
from . import albedo as al
from . import multiscatter as ms
from .tables import kernel_tables


def _args(*values):
    arrays = np.broadcast_arrays(*[np.asarray(v, dtype=np.float64) for v in values])
    shape = arrays[0].shape
    return shape, [np.ascontiguousarray(a.ravel()) for a in arrays]


@kernel
def _lookup(which, a, b, c, tables):
    out = np.empty(a.shape[0])
    for k in range(a.shape[0]):
        if which == 0:
            out[k] = al.specular_albedo(a[k], b[k], c[k], tables)
        elif which == 1:
            out[k] = ms.ggx_albedo(a[k], b[k], tables)
        elif which == 2:
            out[k] = ms.glass_albedo(a[k], b[k], c[k], tables)
        elif which == 3:
            out[k] = ms.dielectric_fresnel_avg(a[k], tables)
        elif which == 4:
            out[k] = ms.layer_reflectance(a[k], b[k], c[k], tables)
        elif which == 5:
            out[k] = ms.ggx_albedo_avg(a[k], tables)
        elif which == 6:
            out[k] = ms.glass_albedo_avg(a[k], b[k], tables)
        else:
            out[k] = ms.compensation(a[k], b[k], c[k])
    return out


def _run(which, *values):
    while len(values) < 3:
        values = values + (0.0,)
    shape, (a, b, c) = _args(*values)
    return _lookup(which, a, b, c, kernel_tables()).reshape(shape)


def specular_albedo(cos_o, alpha, eta):
    """The Principled specular layer's single-scattering albedo (exact Fresnel)."""
    return _run(0, cos_o, alpha, eta)


def ggx_albedo(cos_o, alpha):
    """E(cos_o, alpha) of GGX reflection with F = 1."""
    return _run(1, cos_o, alpha)


def glass_albedo(cos_o, alpha, eta):
    """The rough dielectric's flux albedo."""
    return _run(2, cos_o, alpha, eta)


def dielectric_fresnel_avg(eta):
    """2 int F(mu) mu dmu of the dielectric Fresnel reflectance."""
    return _run(3, eta)


def layer_reflectance(cos_o, alpha, eta):
    """Cycles' estimate of a dielectric GGX layer's reflectance, F0 + (1 - F0) s."""
    return _run(4, cos_o, alpha, eta)


def ggx_albedo_avg(alpha):
    return _run(5, alpha)


def glass_albedo_avg(alpha, eta):
    return _run(6, alpha, eta)


def compensation(E, E_avg, F_ss):
    """The multiple-scattering factor 1 + F_ms (1 - E) / E."""
    return _run(7, E, E_avg, F_ss)
