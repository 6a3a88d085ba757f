"""Array drivers of the single lobes' kernels: each loops the scalar kernel of one lobe
(microfacet.py, dielectric.py, fresnel.py, blinn_phong.py) over arrays, compiled too.
They are how the tests' oracles (closed forms, chi-square, furnace and reciprocity
tests) reach the lobes the renderer runs, and how the energy tables
(engine/bsdf/energy_tables.py, layer_albedo.py) are integrated from those same lobes;
batch.py does the same for the whole Principled mixture.

Directions are (n, 3) float64 arrays in the local frame (normal = +Z); per-element
parameters are (n,) arrays; the public functions broadcast scalars to (n,).
"""
from __future__ import annotations

import numpy as np

from ..jit import kernel
from . import blinn_phong as bp
from . import dielectric as de
from . import fresnel as fr
from . import microfacet as mf
from .thin_film import NO_FILM


def _vec(a, n=None):
    a = np.ascontiguousarray(a, dtype=np.float64)
    return a if n is None else np.ascontiguousarray(np.broadcast_to(a, (n,)))


def _dirs(*ws):
    return [np.ascontiguousarray(np.atleast_2d(w), dtype=np.float64) for w in ws]


# --- GGX --------------------------------------------------------------------------------

@kernel
def _ggx_D(h, alpha):
    out = np.empty(h.shape[0])
    for k in range(h.shape[0]):
        out[k] = mf.D(h[k, 0], h[k, 1], h[k, 2], alpha[k])
    return out


@kernel
def _ggx_G1_over_cos(w, alpha):
    out = np.empty(w.shape[0])
    for k in range(w.shape[0]):
        out[k] = mf.G1_over_cos(w[k, 0], w[k, 1], w[k, 2], alpha[k])
    return out


@kernel
def _ggx_G2_over_G1(wo, wi, alpha):
    out = np.empty(wo.shape[0])
    for k in range(wo.shape[0]):
        out[k] = mf.G2_over_G1(wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0], wi[k, 1], wi[k, 2],
                               alpha[k])
    return out


@kernel
def _ggx_visible_normal(wo, alpha, u):
    h = np.empty(wo.shape)
    for k in range(wo.shape[0]):
        h[k, 0], h[k, 1], h[k, 2] = mf.sample_visible_normal(
            wo[k, 0], wo[k, 1], wo[k, 2], alpha[k], u[k, 0], u[k, 1])
    return h


@kernel
def _ggx_reflection_eval(wo, wi, alpha):
    f = np.empty(wo.shape[0])
    h = np.empty(wo.shape)
    for k in range(wo.shape[0]):
        f[k], h[k, 0], h[k, 1], h[k, 2] = mf.reflection_eval(
            wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0], wi[k, 1], wi[k, 2], alpha[k])
    return f, h


@kernel
def _ggx_reflection_pdf(wo, wi, alpha):
    out = np.empty(wo.shape[0])
    for k in range(wo.shape[0]):
        out[k] = mf.reflection_pdf(wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0], wi[k, 1],
                                   wi[k, 2], alpha[k])
    return out


@kernel
def _ggx_reflection_sample(wo, alpha, u):
    wi = np.empty(wo.shape)
    h = np.empty(wo.shape)
    valid = np.empty(wo.shape[0], dtype=np.bool_)
    for k in range(wo.shape[0]):
        ox, oy, oz = wo[k, 0], wo[k, 1], wo[k, 2]
        h[k, 0], h[k, 1], h[k, 2] = mf.sample_visible_normal(ox, oy, oz, alpha[k],
                                                             u[k, 0], u[k, 1])
        wi[k, 0], wi[k, 1], wi[k, 2], valid[k] = mf.reflection_sample(
            ox, oy, oz, alpha[k], u[k, 0], u[k, 1])
    return wi, h, valid


def ggx_D(h, alpha):
    """GGX D(h) (n,) in 1/sr."""
    h, = _dirs(h)
    return _ggx_D(h, _vec(alpha, len(h)))


def ggx_G1_over_cos(w, alpha):
    """Smith's G1(w) / |w_z| (n,)."""
    w, = _dirs(w)
    return _ggx_G1_over_cos(w, _vec(alpha, len(w)))


def ggx_G2_over_G1(wo, wi, alpha):
    """G2(wo, wi) / G1(wo) (n,): the weight of a VNDF-sampled reflection or refraction."""
    wo, wi = _dirs(wo, wi)
    return _ggx_G2_over_G1(wo, wi, _vec(alpha, len(wo)))


def ggx_visible_normal(wo, alpha, u):
    """Heitz's visible normals h (n, 3) of wo for the numbers u (n, 2)."""
    wo, u = _dirs(wo, u)
    return _ggx_visible_normal(wo, _vec(alpha, len(wo)), u)


def ggx_reflection_eval(wo, wi, alpha):
    """(D G2 / (4 |wo_z| |wi_z|) (n,), the half vectors (n, 3)): F = 1."""
    wo, wi = _dirs(wo, wi)
    return _ggx_reflection_eval(wo, wi, _vec(alpha, len(wo)))


def ggx_reflection_pdf(wo, wi, alpha):
    """The pdf (n,) over wi of `ggx_reflection_sample`."""
    wo, wi = _dirs(wo, wi)
    return _ggx_reflection_pdf(wo, wi, _vec(alpha, len(wo)))


def ggx_reflection_sample(wo, alpha, u):
    """(wi (n, 3), h (n, 3), valid (n,)) of VNDF-sampled GGX reflection."""
    wo, u = _dirs(wo, u)
    return _ggx_reflection_sample(wo, _vec(alpha, len(wo)), u)


# --- Fresnel ----------------------------------------------------------------------------

@kernel
def _fresnel_dielectric(cos_i, eta):
    F = np.empty(cos_i.shape[0])
    cos_t = np.empty(cos_i.shape[0])
    eta_rel = np.empty(cos_i.shape[0])
    for k in range(cos_i.shape[0]):
        F[k], cos_t[k], eta_rel[k] = fr.dielectric_full(cos_i[k], eta[k])
    return F, cos_t, eta_rel


@kernel
def _fresnel_schlick(f0, cos_theta):
    out = np.empty(f0.shape)
    for k in range(f0.shape[0]):
        for c in range(f0.shape[1]):
            out[k, c] = fr.schlick(f0[k, c], cos_theta[k])
    return out


def fresnel_dielectric_full(cos_i, eta):
    """(F, |cos_t|, eta_rel) (n,) of the exact dielectric Fresnel equations (fresnel.py)."""
    c, e = np.broadcast_arrays(np.atleast_1d(_vec(cos_i)), _vec(eta))
    return _fresnel_dielectric(np.array(c.ravel()), np.array(e.ravel()))


def fresnel_dielectric(cos_i, eta):
    """The exact dielectric reflectance F (shape of cos_i)."""
    c, e = np.broadcast_arrays(np.asarray(cos_i, np.float64), np.asarray(eta, np.float64))
    return fresnel_dielectric_full(c, e)[0].reshape(c.shape)


def fresnel_schlick(f0, cos_theta):
    """Schlick's F (n, 3) for F0 (n, 3) or (3,) and cos (n,)."""
    c = np.atleast_1d(_vec(cos_theta))
    f0 = np.ascontiguousarray(np.broadcast_to(np.asarray(f0, np.float64), (c.size, 3)))
    return _fresnel_schlick(f0, c)


def f0_from_ior(ior):
    return np.vectorize(fr.f0_from_ior, otypes=[float])(ior)


def ior_from_f0(f0):
    return np.vectorize(fr.ior_from_f0, otypes=[float])(f0)


# --- the rough and the smooth dielectric interface --------------------------------------

@kernel
def _rough_eval(wo, wi, eta, alpha, walter):
    f_r = np.empty(wo.shape[0])
    f_t = np.empty(wo.shape[0])
    for k in range(wo.shape[0]):
        f_r[k], f_t[k], _ = de.rough_eval_lobes(wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0],
                                                wi[k, 1], wi[k, 2], eta[k], alpha[k],
                                                False, walter, False)
    return f_r, f_t


@kernel
def _rough_pdf(wo, wi, eta, alpha, allow_r, allow_t, walter):
    out = np.empty(wo.shape[0])
    for k in range(wo.shape[0]):
        out[k] = de.rough_pdf(wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0], wi[k, 1], wi[k, 2],
                              eta[k], alpha[k], allow_r, allow_t, walter, False, NO_FILM)
    return out


@kernel
def _rough_sample(wo, eta, alpha, u_choice, u, allow_r, allow_t):
    """The sampled directions, with the weight f |cos| / pdf of the lobe's own eval and
    pdf (Walter's pairs: every sampled pair is one)."""
    n = wo.shape[0]
    wi = np.zeros((n, 3))
    w = np.zeros(n)
    refr = np.zeros(n, dtype=np.bool_)
    valid = np.zeros(n, dtype=np.bool_)
    pdf = np.zeros(n)
    for k in range(n):
        ox, oy, oz = wo[k, 0], wo[k, 1], wo[k, 2]
        ix, iy, iz, refr[k], ok = de.rough_sample(ox, oy, oz, eta[k], alpha[k],
                                                  u_choice[k], u[k, 0], u[k, 1],
                                                  allow_r, allow_t, False, NO_FILM)
        wi[k, 0], wi[k, 1], wi[k, 2] = ix, iy, iz
        if not ok:
            continue
        f_r, f_t, _ = de.rough_eval_lobes(ox, oy, oz, ix, iy, iz, eta[k], alpha[k], False,
                                          True, False)
        p = de.rough_pdf(ox, oy, oz, ix, iy, iz, eta[k], alpha[k], allow_r, allow_t, True,
                         False, NO_FILM)
        if p > 0.0:
            valid[k] = True
            pdf[k] = p
            w[k] = (f_r + f_t) * abs(iz) / p
    return wi, w, refr, valid, pdf


@kernel
def _smooth_sample(wo, eta, u):
    n = wo.shape[0]
    wi = np.empty((n, 3))
    w = np.empty(n)
    refr = np.empty(n, dtype=np.bool_)
    valid = np.empty(n, dtype=np.bool_)
    for k in range(n):
        wi[k, 0], wi[k, 1], wi[k, 2], w[k], refr[k], valid[k], _ = de.smooth_sample(
            wo[k, 0], wo[k, 1], wo[k, 2], eta[k], u[k], True, True, NO_FILM)
    return wi, w, refr, valid


def rough_dielectric_eval(wo, wi, eta, alpha, walter=False):
    """(f_reflect, f_refract) (n,) of the rough interface of relative IOR eta (the
    outside's over the inside's; wo below the surface sees 1 / eta). `walter`: refraction
    on Walter's pairs only, Cycles' extra pairs left out (dielectric.py)."""
    wo, wi = _dirs(wo, wi)
    n = len(wo)
    return _rough_eval(wo, wi, _vec(eta, n), _vec(alpha, n), walter)


def rough_dielectric_pdf(wo, wi, eta, alpha, allow_reflect=True, allow_refract=True,
                         walter=True):
    """The pdf (n,) over wi of `rough_dielectric_sample`."""
    wo, wi = _dirs(wo, wi)
    n = len(wo)
    return _rough_pdf(wo, wi, _vec(eta, n), _vec(alpha, n), allow_reflect, allow_refract,
                      walter)


def rough_dielectric_sample(wo, eta, alpha, u_choice, u, allow_reflect=True,
                            allow_refract=True):
    """(wi (n, 3), weight (n,), refracted (n,), valid (n,), pdf (n,)); the weight is
    f |cos| / pdf (no radiance scaling: dielectric.py)."""
    wo, u = _dirs(wo, u)
    n = len(wo)
    return _rough_sample(wo, _vec(eta, n), _vec(alpha, n), _vec(u_choice, n), u,
                         allow_reflect, allow_refract)


def smooth_dielectric_sample(wo, eta, u):
    """(wi (n, 3), weight (n,), refracted (n,), valid (n,)) of the delta interface, the
    choice made by Fresnel."""
    wo, = _dirs(wo)
    n = len(wo)
    return _smooth_sample(wo, _vec(eta, n), _vec(u, n))


# --- Blinn-Phong ------------------------------------------------------------------------

@kernel
def _blinn_phong(wo, wi, exponent):
    f = np.empty(wo.shape[0])
    p = np.empty(wo.shape[0])
    for k in range(wo.shape[0]):
        ox, oy, oz, ix, iy, iz = wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0], wi[k, 1], wi[k, 2]
        f[k] = bp.eval_f(ox, oy, oz, ix, iy, iz, exponent)
        p[k] = bp.pdf(ox, oy, oz, ix, iy, iz, exponent)
    return f, p


@kernel
def _blinn_phong_sample(wo, u, exponent):
    wi = np.empty(wo.shape)
    valid = np.empty(wo.shape[0], dtype=np.bool_)
    for k in range(wo.shape[0]):
        wi[k, 0], wi[k, 1], wi[k, 2], valid[k] = bp.sample(wo[k, 0], wo[k, 1], wo[k, 2],
                                                           u[k, 0], u[k, 1], exponent)
    return wi, valid


def blinn_phong_eval(wo, wi, exponent):
    """(f (n,), pdf (n,)) of the normalised Blinn-Phong lobe (no Fresnel factor)."""
    wo, wi = _dirs(wo, wi)
    return _blinn_phong(wo, wi, float(exponent))


def blinn_phong_sample(wo, u, exponent):
    """(wi (n, 3), valid (n,))."""
    wo, u = _dirs(wo, u)
    return _blinn_phong_sample(wo, u, float(exponent))


def blinn_phong_D(h, exponent):
    h, = _dirs(h)
    return np.array([bp.D(x, y, z, float(exponent)) for x, y, z in h])
