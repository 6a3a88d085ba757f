"""The diffuse lobe with roughness: Cycles' energy-preserving Oren-Nayar (Blender 4.3 and
later; Fujii's model with a multiple-scattering term, as in OpenPBR), for a Diffuse BSDF
with Roughness and a Principled BSDF with Diffuse Roughness. Sampled as the Lambertian
lobe is (cosine-weighted); only its value differs.

For roughness sigma (clamped to [0, 1]), A = 1 / (pi + sigma (pi/2 - 2/3)), B = sigma A,
and with n.l, n.v the cosines of the light and the view,

    f = colour (A + B t + m (1 - E(n.l))),   t = (l.v - n.l n.v) / max(n.l, n.v) if > 0,

where E(mu) = A pi + B G(mu) is the single-scattering albedo (G below) and the
multiple-scattering term m = Ems (1 - E(n.v)) restores the energy the single-scattering
lobe loses, Ems = rho^2 Eavg / (1 - Eavg) / (pi (1 - rho (1 - Eavg))) for albedo rho
(the colour clamped to 1) and Eavg = A pi + (2 pi - 5.6) / 3 B. For rho = 1 the lobe
reflects everything at every angle (tests/test_oren_nayar.py integrates it)."""
from __future__ import annotations

import math

from ..jit import kernel
from .params import P_BASE, P_DIFFUSE_ROUGHNESS
from .state import S_DIFFUSE, S_ON

ROUGH_MIN = 1e-5          # Cycles' diffuse_roughness_is_almost_zero: Lambert below


@kernel(allocates=False)
def g(mu):
    """Cycles' G(cos theta) of the single-scattering albedo."""
    if mu < 1e-6:
        return (0.5 * math.pi - 2.0 / 3.0) - mu
    s = math.sqrt(max(1.0 - mu * mu, 0.0))
    theta = math.acos(min(max(mu, -1.0), 1.0))
    return s * (theta - 2.0 / 3.0 - s * mu) + 2.0 / 3.0 * (s / mu) * (1.0 - s * s * s)


@kernel(allocates=False)
def setup(row, woz, state):
    """The lobe's constants for the view's cosine woz; b = 0 (Lambert) below ROUGH_MIN."""
    sigma = min(max(row[P_DIFFUSE_ROUGHNESS], 0.0), 1.0)
    state[S_ON + 1] = 0.0
    if not sigma >= ROUGH_MIN:
        return
    a = 1.0 / (math.pi + sigma * (0.5 * math.pi - 2.0 / 3.0))
    b = sigma * a
    e_avg = a * math.pi + ((2.0 * math.pi - 5.6) / 3.0) * b
    e_v = a * math.pi + b * g(max(woz, 0.0))
    state[S_ON] = a
    state[S_ON + 1] = b
    for c in range(3):
        rho = min(max(row[P_BASE + c], 0.0), 1.0)
        ems = rho * rho * (e_avg / (1.0 - e_avg)) / (math.pi * (1.0 - rho * (1.0 - e_avg)))
        state[S_ON + 2 + c] = ems * (1.0 - e_v)


@kernel(allocates=False)
def value(state, wox, woy, woz, wix, wiy, wiz):
    """f (1/sr) per channel towards wi (above the normal: wiz > 0)."""
    a, b = state[S_ON], state[S_ON + 1]
    nv = max(woz, 0.0)
    t = wox * wix + woy * wiy + woz * wiz - wiz * nv
    if t > 0.0:
        t /= max(wiz, nv) + 1e-300
    single = a + b * t
    lost = 1.0 - (a * math.pi + b * g(wiz))
    return (state[S_DIFFUSE] * (single + state[S_ON + 2] * lost),
            state[S_DIFFUSE + 1] * (single + state[S_ON + 3] * lost),
            state[S_DIFFUSE + 2] * (single + state[S_ON + 4] * lost))
