"""Volume shaders (a Material Output's or World Output's Volume socket) to a homogeneous
`engine.Volume`, with Cycles' meaning of each node (intern/cycles/kernel/svm/closure.h,
read for meaning only):

Principled Volume
    scattering = Color x Density, Henyey-Greenstein with Anisotropy; absorption =
    max(1 - Color, 0) x max(1 - sqrt(Absorption Color), 0) x Density (the light the
    colour does not scatter, tinted); emission = Emission Color x Emission Strength.
    Blackbody emission is not rendered (reported).
Volume Scatter
    scattering = Color x Density (Henyey-Greenstein; other phase functions reported and
    rendered as Henyey-Greenstein).
Volume Absorption
    absorption = (1 - Color) x Density.
Volume Coefficients
    its absorption, scattering and emission coefficients as they are.
Emission
    emission = Color x Strength (radiance per metre).
Add Shader, Mix Shader
    the coefficients add, or mix by the factor (the anisotropy is the
    scattering-weighted mean).

Inputs that vary in space (a texture on Density: a heterogeneous volume) are replaced by
their average, reported: DRT renders homogeneous volumes.
"""
from __future__ import annotations

import numpy as np

from ..engine_link import engine
from .nodes.links import _link
from .nodes.shader import _constant
from .world import _WorldCtx, world_output

_ZERO = np.zeros(3)


class _Coeffs:
    def __init__(self, sa=_ZERO, ss=_ZERO, gs=0.0, em=_ZERO):
        self.sa, self.ss, self.gs, self.em = (np.asarray(sa, float), np.asarray(ss, float),
                                              float(gs), np.asarray(em, float))

    def scaled(self, f):
        return _Coeffs(self.sa * f, self.ss * f, self.gs * f, self.em * f)

    def plus(self, o):
        return _Coeffs(self.sa + o.sa, self.ss + o.ss, self.gs + o.gs, self.em + o.em)


def _scatter(color, density, g):
    ss = np.maximum(np.asarray(color, float), 0.0) * density
    return ss, float(ss.mean()) * g


def _principled(node, ctx):
    def c(name, d, color=False):
        return _constant(node, name, ctx, d, color=color)
    density = max(c("Density", 1.0), 0.0)
    color = np.maximum(np.asarray(c("Color", (0.5,) * 3, True), float), 0.0)
    ss, gs = _scatter(color, density, c("Anisotropy", 0.0))
    absorb = np.asarray(c("Absorption Color", (0.0,) * 3, True), float)
    sa = np.maximum(1.0 - color, 0.0) * np.maximum(1.0 - np.sqrt(np.maximum(absorb, 0.0)),
                                                    0.0) * density
    em = np.asarray(c("Emission Color", (1.0,) * 3, True), float) * c("Emission Strength", 0.0)
    if c("Blackbody Intensity", 0.0) > 1e-3:
        ctx.issue(f"{node.name!r}: blackbody emission is not rendered")
    return _Coeffs(sa, ss, gs, np.maximum(em, 0.0))


def _volume_scatter(node, ctx):
    phase = getattr(node, "phase", "HENYEY_GREENSTEIN")
    if phase != "HENYEY_GREENSTEIN":
        ctx.issue(f"{node.name!r}: the {phase.replace('_', ' ').title()} phase function is "
                  f"rendered as Henyey-Greenstein")
    density = max(_constant(node, "Density", ctx, 1.0), 0.0)
    color = _constant(node, "Color", ctx, (0.8,) * 3, color=True)
    ss, gs = _scatter(color, density, _constant(node, "Anisotropy", ctx, 0.0))
    return _Coeffs(ss=ss, gs=gs)


def _absorption(node, ctx):
    density = max(_constant(node, "Density", ctx, 1.0), 0.0)
    color = np.asarray(_constant(node, "Color", ctx, (0.8,) * 3, color=True), float)
    return _Coeffs(sa=np.maximum(1.0 - color, 0.0) * density)


def _coefficients(node, ctx):
    def v(name):
        return np.maximum(np.asarray(_constant(node, name, ctx, (0.0,) * 3, color=True),
                                     float), 0.0)
    ss = v("Scatter Coefficients")
    g = _constant(node, "Anisotropy", ctx, 0.0)
    return _Coeffs(v("Absorption Coefficients"), ss, float(ss.mean()) * g,
                   v("Emission Coefficients"))


def _emission(node, ctx):
    color = np.asarray(_constant(node, "Color", ctx, (1.0,) * 3, color=True), float)
    return _Coeffs(em=np.maximum(color * _constant(node, "Strength", ctx, 1.0), 0.0))


_NODES = {"ShaderNodeVolumePrincipled": _principled,
          "ShaderNodeVolumeScatter": _volume_scatter,
          "ShaderNodeVolumeAbsorption": _absorption,
          "ShaderNodeVolumeCoefficients": _coefficients,
          "ShaderNodeEmission": _emission}


def _coeffs(socket, ctx, depth=0):
    found = _link(socket)
    if found is None or depth > 32:
        return _Coeffs()
    node = found[0]
    kind = node.bl_idname
    if kind in _NODES:
        return _NODES[kind](node, ctx)
    if kind == "ShaderNodeAddShader":
        return _coeffs(node.inputs[0], ctx, depth + 1).plus(
            _coeffs(node.inputs[1], ctx, depth + 1))
    if kind == "ShaderNodeMixShader":
        f = min(max(_constant(node, "Fac", ctx, 0.5), 0.0), 1.0)
        return _coeffs(node.inputs[1], ctx, depth + 1).scaled(1.0 - f).plus(
            _coeffs(node.inputs[2], ctx, depth + 1).scaled(f))
    ctx.issue(f"its volume uses the {node.bl_label!r} node, which DRT does not render in "
              f"volumes; that part is left out")
    return _Coeffs()


def export_volume(socket, ctx) -> "engine.Volume | None":
    """The homogeneous Volume behind a Volume socket (None: nothing linked or empty)."""
    if socket is None or _link(socket) is None:
        return None
    c = _coeffs(socket, ctx)
    ss_mean = float(c.ss.mean())
    g = c.gs / ss_mean if ss_mean > 0 else 0.0
    v = engine.Volume(tuple(c.sa), tuple(c.ss), min(max(g, -1.0), 1.0), tuple(c.em))
    return None if v.is_empty() else v


class _VolumeCtx(_WorldCtx):
    """The world's context with what the node readers need of a material's."""

    def __init__(self, world, reporter):
        from .nodes import NodeCompiler
        super().__init__(world, reporter)
        self.normal = None
        self.nodes = NodeCompiler(self)


def world_volume(world, reporter) -> "engine.Volume | None":
    """The volume of the world's active World Output (None without one), filling the
    space outside every mesh; what is approximated is reported."""
    tree = getattr(world, "node_tree", None)
    out = world_output(tree) if tree is not None else None
    if out is None:
        return None
    ctx = _VolumeCtx(world, reporter)
    v = export_volume(out.inputs.get("Volume"), ctx)
    ctx.report(reporter)
    return v
