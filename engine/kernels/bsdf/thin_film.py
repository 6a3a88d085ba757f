"""Thin-film interference on the Principled BSDF's specular layer, metal and glass, as
Cycles renders its Thin Film Thickness and IOR (Belcour and Barla 2017, "A Practical
Extension to Microfacet Theory for the Modeling of Varying Iridescence"): a film of
thickness d (nm) and index n_f between the air (n = 1) and the substrate. Its reflectance
at the angle of incidence theta_1 to the microfacet is the Airy sum of the waves
reflected at the top (1 -> 2) and bottom (2 -> 3) interfaces, for each polarisation,

    R = R12 + Rs + sum_{m=1..3} C_m 2 Re(phasor^m conj S(m OPD)),
    Rs = T121^2 R23 / (1 - R12 R23),  C_m = (Rs - T121) sqrt(R12 R23)^m,
    OPD = 2 n_f d cos theta_2,

with T121 = 1 - R12, the phasor exp(i (phi23 + phi21)) of the phase shifts on reflection,
and S the spectral sensitivity (engine/bsdf/thin_film_table.py: the Fourier transform of
the colour matching functions, per scene-linear channel), which integrates the spectrum
of each term in closed form. The two polarisations are averaged and clamped to [0, 1].
Below 1 nm the film's index blends towards the air's (smoothstep in d), where the wave
optics no longer hold.

- dielectric substrate (the specular layer, the glass): R12, R23 and the phase signs
  from the polarised dielectric Fresnel equations; then Specular Tint and Specular IOR
  Level scale the result per channel by f0_c / F0 at the strength s = (1 - F) / (1 -
  F0), clamped (Cycles' artistic F0 scaling, since F may fall below F0). The glass
  reflects F_c and refracts 1 - F_c (specular_tint.glass_factor), from either side: the
  film's index is taken relative to the medium the light comes from, as in Cycles.
- metal (F82-tint): n and k estimated from F0 and the F82 value (Gulbrandsen 2014,
  "Artist Friendly Metallic Fresnel"); R23 is the F82 model with F0 recomputed for n / n_f
  and k / n_f, its phase from the complex conductor Fresnel equations (Born and Wolf
  14.4.1).

Only the Fresnel factor changes: the layering below the specular layer and the Color
passes take its reflectance at wo (Cycles' estimate for a film, no table) times the
closure weight's multiscatter darkening, and the multiple-scattering compensation keeps
the film-free average Fresnel, as in Cycles. The table is a constant
of the compiled code (24 kB).
"""
from __future__ import annotations

import math

from ...bsdf.thin_film_table import load as _load_table
from ..jit import kernel
from . import fresnel

CUTOFF = 0.10000000149011612   # nm, 0.1 in float32: films no thicker are none (Cycles'
#                                THINFILM_THICKNESS_CUTOFF, compared in float32)
_TABLE = _load_table()
_ROWS = _TABLE.shape[1]
_SCALE = 2.0 * math.pi / 60000.0


@kernel(allocates=False)
def sensitivity(c, opd):
    """(re, im) of S_c at the optical path difference opd (nm), linear between rows."""
    x = min(max(opd * _SCALE, 0.0), 1.0) * (_ROWS - 1)
    i = min(int(x), _ROWS - 1)
    j = min(i + 1, _ROWS - 1)
    t = x - i
    re = (1.0 - t) * _TABLE[c, i] + t * _TABLE[c, j]
    im = (1.0 - t) * _TABLE[3 + c, i] + t * _TABLE[3 + c, j]
    return re, im


@kernel(allocates=False)
def polarized_dielectric(cos_i, eta):
    """(R_s, R_p, cos_t, sign_s, sign_p, total): the reflectances of the two
    polarisations, the refracted cosine (negative: below the interface), the signs of the
    reflected amplitudes (the phase shifts, 0 or pi, as cosines) and whether the light is
    totally reflected."""
    e2 = eta * eta - (1.0 - cos_i * cos_i)
    if not e2 > 0.0:
        return 1.0, 1.0, 0.0, 1.0, 1.0, True
    ci = abs(cos_i)
    cos_t = -math.sqrt(e2) / eta
    r_s = (ci + eta * cos_t) / (ci - eta * cos_t)
    r_p = (cos_t + eta * ci) / (eta * ci - cos_t)
    return (r_s * r_s, r_p * r_p, cos_t, 1.0 if r_s >= 0.0 else -1.0,
            1.0 if r_p >= 0.0 else -1.0, False)


@kernel(allocates=False)
def _airy(c, r12, r23, opd, ph_re, ph_im):
    """The Airy sum in channel c for one polarisation (module docstring)."""
    t121 = 1.0 - r12
    r123 = r12 * r23
    root = math.sqrt(max(r123, 0.0))
    rs = t121 * t121 * r23 / (1.0 - r123)
    out = rs + r12
    cm = rs - t121
    acc_re, acc_im = ph_re, ph_im
    for m in range(1, 4):
        cm *= root
        s_re, s_im = sensitivity(c, m * opd)
        out += cm * 2.0 * (acc_re * s_re + acc_im * s_im)
        acc_re, acc_im = acc_re * ph_re - acc_im * ph_im, acc_re * ph_im + acc_im * ph_re
    return out


@kernel(allocates=False)
def _film_ior(thickness, ior):
    """The film's index, blended towards the air's (1) below 1 nm."""
    if thickness >= 1.0:
        return ior
    t = min(max(thickness, 0.0), 1.0)
    return 1.0 + (ior - 1.0) * (t * t * (3.0 - 2.0 * t))


@kernel(allocates=False)
def over_dielectric(c, cos_1, thickness, film_ior, eta):
    """The reflectance in channel c of the film on a dielectric of relative index eta,
    at cos theta_1 of the light to the microfacet."""
    nf = _film_ior(thickness, film_ior)
    r12_s, r12_p, cos_2, s12_s, s12_p, total = polarized_dielectric(cos_1, nf)
    if total:
        return 1.0
    r23_s, r23_p, _, s23_s, s23_p, total = polarized_dielectric(-cos_2, eta / nf)
    if total:
        return 1.0
    opd = -2.0 * nf * thickness * cos_2
    r_s = _airy(c, r12_s, r23_s, opd, -s12_s * s23_s, 0.0)
    r_p = _airy(c, r12_p, r23_p, opd, -s12_p * s23_p, 0.0)
    return min(max(0.5 * (r_s + r_p), 0.0), 1.0)


@kernel(allocates=False)
def specular_layer(c, cos_1, thickness, film_ior, eta, f0_c):
    """The specular layer's F_c with the film: `over_dielectric`, scaled towards f0_c / F0
    (Specular Tint and Level; f0_c the layer's tinted F0 in channel c). A channel totally
    reflected (F = 1) is not scaled, which is what Cycles' all-channels test gives too."""
    F = over_dielectric(c, cos_1, thickness, film_ior, eta)
    f0_real = fresnel.f0_from_ior(eta)
    if f0_real > 1e-5 and F != 1.0:
        s = min(max((F - 1.0) / (f0_real - 1.0), 0.0), 1.0)
        F *= 1.0 + (f0_c / f0_real - 1.0) * s
    return F


@kernel(allocates=False)
def _conductor_phase(cos_i, eta1, n, k):
    """exp(i phi_s), exp(i phi_p) at a dielectric (eta1) to conductor (n + ik)
    interface: (s_re, s_im, p_re, p_im)."""
    eta1_sq = eta1 * eta1
    n_sq = n * n
    k_sq = k * k
    two_nk = 2.0 * n * k
    t1 = n_sq - k_sq - eta1_sq * (1.0 - cos_i * cos_i)
    t2 = math.sqrt(t1 * t1 + two_nk * two_nk)
    u_sq = max(0.5 * (t2 + t1), 0.0)
    v_sq = max(0.5 * (t2 - t1), 0.0)
    u = math.sqrt(u_sq)
    v = math.sqrt(v_sq)
    re_s = -u_sq - v_sq + eta1_sq * cos_i * cos_i
    im_s = -2.0 * eta1 * cos_i * v
    mag_s = math.sqrt(re_s * re_s + im_s * im_s)
    re_p = ((n_sq + k_sq) * cos_i) ** 2 - eta1_sq * (u_sq + v_sq)
    im_p = 2.0 * eta1 * cos_i * (two_nk * u - (n_sq - k_sq) * v)
    mag_p = math.sqrt(re_p * re_p + im_p * im_p)
    s_re, s_im = (1.0, 0.0) if mag_s == 0.0 else (re_s / mag_s, im_s / mag_s)
    p_re, p_im = (1.0, 0.0) if mag_p == 0.0 else (re_p / mag_p, im_p / mag_p)
    return s_re, s_im, p_re, p_im


@kernel(allocates=False)
def _f82_b(f0, f82):
    """F82's b for F0 and the value f82 at cos = 1/7."""
    f = 6.0 / 7.0
    f5 = f ** 5
    return (7.0 / (f5 * f)) * (f0 + (1.0 - f0) * f5 - f82)


@kernel(allocates=False)
def metal(c, cos_1, thickness, film_ior, f0, b):
    """The F82-tint metal lobe's Fresnel in channel c (F0 f0, b: fresnel.f82_tint's; 0
    without a tint) under the film."""
    f82 = fresnel.f82_tint(f0, b, 1.0 / 7.0)
    r = min(f0, 0.999)
    sqrt_r = math.sqrt(r)
    n = (1.0 + sqrt_r) / (1.0 - sqrt_r)
    n = n + ((1.0 - r) / (1.0 + r) - n) * f82
    k = math.sqrt(max((r * (n + 1.0) ** 2 - (n - 1.0) ** 2) / (1.0 - r), 0.0))
    nf = _film_ior(thickness, film_ior)
    r12_s, r12_p, cos_2, s12_s, s12_p, total = polarized_dielectric(cos_1, nf)
    if total:
        return 1.0
    cos_3 = -cos_2
    nn = n / nf
    kk = (k / nf) ** 2
    f0_film = ((nn - 1.0) ** 2 + kk) / ((nn + 1.0) ** 2 + kk)
    r23 = fresnel.f82_tint(f0_film, _f82_b(f0_film, f82), cos_3)
    s_re, s_im, p_re, p_im = _conductor_phase(cos_3, nf, n, k)
    opd = -2.0 * nf * thickness * cos_2
    r_s = _airy(c, r12_s, r23, opd, -s12_s * s_re, -s12_s * s_im)
    r_p = _airy(c, r12_p, r23, opd, -s12_p * p_re, -s12_p * p_im)
    return min(max(0.5 * (r_s + r_p), 0.0), 1.0)


NO_FILM = (0.0, 1.0, 1.0, 0.0, 0.0, 0.0)   # `glass_choice`'s film: none


@kernel(allocates=False)
def glass(c, cos_i, thickness, film_ior, glass_ior, eta_rel, f0_c):
    """The film's F_c on a glass of index glass_ior, for light arriving at cos_i with
    the relative index eta_rel of its side: the film's index relative to the medium the
    light comes from (1 outside, the glass inside), as Cycles takes it."""
    inside = (eta_rel < 1.0) == (glass_ior > 1.0)
    nf = film_ior / (glass_ior if inside else 1.0)
    return specular_layer(c, cos_i, thickness, nf, eta_rel, f0_c)


@kernel(allocates=False)
def glass_choice(film, cos_i, eta_rel, F):
    """The reflectance by which a glass chooses between reflection and refraction: its
    Fresnel F, or under a film (film = (thickness, film IOR, glass IOR, f0 per channel),
    NO_FILM for none) the film's F_c averaged over the channels, as Cycles chooses; the
    weights then carry F_c over it (specular_tint.glass_factor)."""
    if not film[0] > 0.0:
        return F
    total = 0.0
    for c in range(3):
        total += glass(c, cos_i, film[0], film[1], film[2], eta_rel, film[3 + c])
    return total / 3.0
