"""Anisotropic microfacet reflection (GGX or Beckmann) for the metal and specular lobes:
Cycles' Anisotropic / Rotation / Tangent of the Principled, Metallic and Glossy BSDFs.

The lobe lives in the tangent frame (X = the tangent, Y = n x X, Z = n), with the
roughness alpha_x along X and alpha_y along Y. Both distributions are "stretch
invariant" (Heitz 2014, "Understanding the Masking-Shadowing Function", sec. 5.3): the
anisotropic quantities are the isotropic ones at alpha = 1 of the stretched vectors
(alpha_x x, alpha_y y, z), so each function here calls microfacet.py / beckmann.py with
alpha 1:
  * D(h) = D_1(h_x / alpha_x, h_y / alpha_y, h_z) / (alpha_x alpha_y);
  * Lambda(w) = Lambda_1(alpha_x w_x, alpha_y w_y, w_z) (G1 and the height-correlated
    G2 follow; Beckmann's G2 uses Cycles' rational Lambda as beckmann.py does);
  * visible normals: stretch wo, sample the alpha = 1 configuration, unstretch.

Where the tangent comes from (Cycles, kernel/svm/closure.h): the node's Tangent input, or
when unlinked the Geometry node's tangent (radial about the object's Z through its
generated coordinates, engine.nodes.input_nodes), projected on the lobe's normal and
turned about it by Rotation x 2 pi. The integrator writes it, local to the shading frame,
into the row's P_TANGENT (engine.kernels.surface_hit.localize_tangent); here it becomes
the angle (cos, sin) of X in the local frame. A tangent along the normal (or none) leaves
the lobe isotropic, as Cycles without a tangent.

Roughness (Cycles): Principled and Metallic (ANISO_PRINCIPLED): aspect = sqrt(1 - 0.9 a),
a in [0, 1], alpha_x = r^2 / aspect, alpha_y = r^2 aspect; Glossy (ANISO_GLOSSY): a in
[-0.99, 0.99], alpha_x = r^2 (1 - a), alpha_y = r^2 / (1 - a) for a > 0, alpha_x =
r^2 / (1 + a), alpha_y = r^2 (1 + a) for a < 0; each alpha clamped to [ALPHA_MIN, 1]. The
multiple-scattering compensation and the layer albedos take the isotropic alpha
sqrt(alpha_x alpha_y), as Cycles' do. Cycles keeps the glass lobe isotropic; so does DRT.
"""
from __future__ import annotations

import math

from ..frame import to_local
from ..jit import kernel
from . import beckmann as bk
from . import microfacet as mf
from .params import (ANISO_GLOSSY, ANISO_PRINCIPLED, P_ANISO, P_ANISO_KIND, P_ANISO_ROT,
                     P_TANGENT)
from .state import S_ANISO, S_ALPHA_X, S_ALPHA_Y, S_TAN_C, S_TAN_S

TWO_PI = 2.0 * math.pi


# --- the tangent frame ------------------------------------------------------------------
@kernel(allocates=False)
def to_tangent(c, s, x, y):
    """(x, y) of the local frame in the tangent frame whose X is at (c, s)."""
    return c * x + s * y, c * y - s * x


@kernel(allocates=False)
def from_tangent(c, s, x, y):
    return c * x - s * y, s * x + c * y


@kernel(allocates=False)
def localize_tangent(row, nx, ny, nz):
    """The row's per-hit tangent (world space, as the program wrote it) in the local
    frame of the shading normal n, before `setup` reads it."""
    row[P_TANGENT], row[P_TANGENT + 1], row[P_TANGENT + 2] = to_local(
        row[P_TANGENT], row[P_TANGENT + 1], row[P_TANGENT + 2], nx, ny, nz)


# --- the distribution, in the tangent frame ---------------------------------------------
@kernel(allocates=False)
def D(hx, hy, hz, ax, ay, beckmann):
    """D(h) (1/sr) of the anisotropic distribution; 0 for h_z <= 0."""
    if beckmann:
        return bk.D(hx / ax, hy / ay, hz, 1.0) / (ax * ay)
    return mf.D(hx / ax, hy / ay, hz, 1.0) / (ax * ay)


@kernel(allocates=False)
def G1_over_cos(x, y, z, ax, ay, beckmann):
    """G1(w) / |w_z|."""
    if beckmann:
        return bk.G1_over_cos(ax * x, ay * y, z, 1.0)
    return mf.G1_over_cos(ax * x, ay * y, z, 1.0)


@kernel(allocates=False)
def reflection_eval(ox, oy, oz, ix, iy, iz, ax, ay, beckmann):
    """(D G2 / (4 |wo_z| |wi_z|), h) of the upper-hemisphere reflection (microfacet.py's
    `reflection_eval`, anisotropic)."""
    hx, hy, hz, ok = mf.half_vector(ox, oy, oz, ix, iy, iz)
    if not (ok and oz > 0.0 and iz > 0.0):
        return 0.0, hx, hy, hz
    d = D(hx, hy, hz, ax, ay, beckmann)
    if beckmann:
        return 0.25 * d * bk.G2_over_cos2(ax * ox, ay * oy, oz, ax * ix, ay * iy, iz,
                                          1.0), hx, hy, hz
    den = iz * mf.r_len(ax * ox, ay * oy, oz, 1.0) + oz * mf.r_len(ax * ix, ay * iy, iz, 1.0)
    if not den > 0.0:
        return 0.0, hx, hy, hz
    return d / (2.0 * den), hx, hy, hz


@kernel(allocates=False)
def reflection_pdf(ox, oy, oz, ix, iy, iz, ax, ay, beckmann):
    """pdf over wi (1/sr) of visible-normal sampled reflection: G1(wo) D / (4 wo_z)."""
    hx, hy, hz, ok = mf.half_vector(ox, oy, oz, ix, iy, iz)
    if not (ok and oz > 0.0 and iz > 0.0):
        return 0.0
    return 0.25 * G1_over_cos(ox, oy, oz, ax, ay, beckmann) * D(hx, hy, hz, ax, ay, beckmann)


@kernel(allocates=False)
def reflection_sample(ox, oy, oz, ax, ay, u0, u1, beckmann):
    """A reflected direction (wi, valid) with h ~ D_wo(h): the alpha = 1 visible normals
    of the stretched wo, unstretched."""
    if beckmann:
        sx, sy, sz = bk.sample_visible_normal(ax * ox, ay * oy, oz, 1.0, u0, u1)
    else:
        sx, sy, sz = mf.sample_visible_normal(ax * ox, ay * oy, oz, 1.0, u0, u1)
    hx, hy, hz = mf.normalize(ax * sx, ay * sy, max(sz, 0.0))
    ix, iy, iz = mf.reflect(ox, oy, oz, hx, hy, hz)
    valid = (oz > 0.0 and iz > 0.0 and hz > 0.0
             and mf.dot(ox, oy, oz, hx, hy, hz) > 0.0)
    return ix, iy, iz, valid


# --- the lobe, from the state -----------------------------------------------------------
@kernel(allocates=False)
def alphas(kind, amount, rough):
    """(alpha_x, alpha_y) of roughness `rough` and anisotropy `amount` by the node's
    mapping `kind`, each clamped; equal where the node is isotropic."""
    a2 = rough * rough
    ax = ay = a2
    if kind == ANISO_PRINCIPLED:
        a = min(max(amount, 0.0), 1.0)
        if a > 0.0:
            aspect = math.sqrt(1.0 - 0.9 * a)
            ax, ay = a2 / aspect, a2 * aspect
    elif kind == ANISO_GLOSSY:
        a = min(max(amount, -0.99), 0.99)
        if a < -1e-4:
            ax, ay = a2 / (1.0 + a), a2 * (1.0 + a)
        elif a > 1e-4:
            ax, ay = a2 * (1.0 - a), a2 / (1.0 - a)
    return mf.clamp_alpha(ax), mf.clamp_alpha(ay)


@kernel(allocates=False)
def setup(row, rough, filter_alpha, state):
    """Fill the anisotropy slots of the state from the row (its roughness `rough`,
    clamped): the tangent frame's angle and the two alphas, widened by Filter Glossy's
    `filter_alpha` as Cycles' blur widens each. Returns the material's own isotropic
    alpha sqrt(alpha_x alpha_y) for the compensation and the layering (the plain
    alpha where the lobe stays isotropic)."""
    state[S_ANISO] = 0.0
    alpha = mf.clamp_alpha(rough * rough)
    if row[P_ANISO_KIND] == 0.0:
        return alpha
    ax, ay = alphas(row[P_ANISO_KIND], row[P_ANISO], rough)
    tx = row[P_TANGENT]
    ty = row[P_TANGENT + 1]
    ln = math.sqrt(tx * tx + ty * ty)
    if ax == ay or not (ln > 1e-12 and ln < math.inf):
        return alpha
    turn = TWO_PI * row[P_ANISO_ROT]
    ct = math.cos(turn)
    st = math.sin(turn)
    state[S_TAN_C] = (tx * ct - ty * st) / ln
    state[S_TAN_S] = (tx * st + ty * ct) / ln
    state[S_ALPHA_X] = mf.clamp_alpha(max(ax, filter_alpha))
    state[S_ALPHA_Y] = mf.clamp_alpha(max(ay, filter_alpha))
    state[S_ANISO] = 1.0
    return math.sqrt(ax * ay)


@kernel(allocates=False)
def lobe_eval(state, ox, oy, oz, ix, iy, iz, beckmann):
    """`reflection_eval` of the state's lobe, local directions in, local h out."""
    c = state[S_TAN_C]
    s = state[S_TAN_S]
    tox, toy = to_tangent(c, s, ox, oy)
    tix, tiy = to_tangent(c, s, ix, iy)
    f, hx, hy, hz = reflection_eval(tox, toy, oz, tix, tiy, iz, state[S_ALPHA_X],
                                    state[S_ALPHA_Y], beckmann)
    hx, hy = from_tangent(c, s, hx, hy)
    return f, hx, hy, hz


@kernel(allocates=False)
def lobe_pdf(state, ox, oy, oz, ix, iy, iz, beckmann):
    c = state[S_TAN_C]
    s = state[S_TAN_S]
    tox, toy = to_tangent(c, s, ox, oy)
    tix, tiy = to_tangent(c, s, ix, iy)
    return reflection_pdf(tox, toy, oz, tix, tiy, iz, state[S_ALPHA_X], state[S_ALPHA_Y],
                          beckmann)


@kernel(allocates=False)
def lobe_sample(state, ox, oy, oz, u0, u1, beckmann):
    c = state[S_TAN_C]
    s = state[S_TAN_S]
    tox, toy = to_tangent(c, s, ox, oy)
    ix, iy, iz, valid = reflection_sample(tox, toy, oz, state[S_ALPHA_X], state[S_ALPHA_Y],
                                          u0, u1, beckmann)
    ix, iy = from_tangent(c, s, ix, iy)
    return ix, iy, iz, valid
