"""The subsurface lobe of the Principled BSDF: the part of the diffuse base that enters the
surface and walks inside it (engine/kernels/subsurface.py), as Cycles splits it
(svm/closure.h, closure/bssrdf.h):

    diffuse      base colour x (1 - Subsurface Weight)   Lambert, as before
    subsurface   clamp(base colour) x Subsurface Weight   the random walk

both under the specular layer (scaled by 1 - E_spec(wo)) and the coat and sheen. A colour
channel whose radius is below MIN_RADIUS cannot walk: its share goes back to the diffuse
lobe (Cycles' bssrdf_setup).

The lobe has no density over directions: it is not evaluated by next-event estimation at
the entry (light reaches it at the exit, where it leaves as a diffuse surface) and adds
nothing to the mixture pdf, but its selection probability is part of the mixture's
normalisation, as Cycles' BSSRDF sample weight is part of its closures' sum. When sampled
(principled.sample: kind SUBSURFACE) its weight is its colour over its probability.
"""
from __future__ import annotations

from ..jit import kernel
from .params import P_SSS_RADIUS, P_SSS_WEIGHT
from .state import S_EST_SSS, S_SSS

MIN_RADIUS = 1e-8          # Cycles' BSSRDF_MIN_RADIUS


@kernel(allocates=False)
def weight(row):
    """The material's Subsurface Weight, clamped to [0, 1]."""
    return min(max(row[P_SSS_WEIGHT], 0.0), 1.0)


@kernel(allocates=False)
def split(row, c, base, clamped, base_w, state):
    """Split channel c of the diffuse base (base colour `base`, clamped to [0, 1]
    `clamped`, dielectric base weight base_w): stores the subsurface lobe's weight and
    returns the diffuse lobe's."""
    w = weight(row)
    if w <= 0.0:
        state[S_SSS + c] = 0.0
        return base * base_w
    sss = clamped * w * base_w
    diffuse = base * (1.0 - w) * base_w
    if row[P_SSS_RADIUS + c] < MIN_RADIUS:
        state[S_SSS + c] = 0.0
        return diffuse + sss
    state[S_SSS + c] = sss
    return diffuse


@kernel(allocates=False)
def scale(state, factor_r, factor_g, factor_b):
    """Dim the lobe by the layers above it (per channel)."""
    state[S_SSS] = state[S_SSS] * factor_r
    state[S_SSS + 1] = state[S_SSS + 1] * factor_g
    state[S_SSS + 2] = state[S_SSS + 2] * factor_b


@kernel(allocates=False)
def estimate(state, floor):
    """Set the lobe's selection estimate: its channels' average, at least `floor` when
    it is present."""
    e = (state[S_SSS] + state[S_SSS + 1] + state[S_SSS + 2]) / 3.0
    state[S_EST_SSS] = max(e, floor) if e > 0.0 else 0.0


@kernel(allocates=False)
def present(state):
    return state[S_EST_SSS] > 0.0
