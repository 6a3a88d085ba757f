"""What the Mix and Add Shaders of export.nodes.shader need besides the closures they
combine: a Mix Shader's Fac (its constant or average, a Fresnel IOR, the per-hit value),
a Fresnel-mixed pair read as one Principled specular layer (`_plastic`), and per-hit mixes
lifted above the constant mixes and Add Shaders that combine them (`lifted_mix`)."""
from __future__ import annotations

import importlib
from dataclasses import replace

import numpy as np

from ...engine_link import engine
from ..closures import BLACK, NULL_COMP, WHITE, _Closure
from ..material_params import NodeParam, _lin, _mean, _same, _scale, cv
from .links import _link
from .shader_inputs import _constant

lobes = importlib.import_module(engine.__name__ + ".kernels.bsdf.lobe_batch")


def _fresnel_average(ior):
    """Hemispherical average of Fresnel reflectance, 2 int_0^1 F(mu) mu dmu."""
    mu = (np.arange(1024) + 0.5) / 1024
    return float(2.0 * np.mean(lobes.fresnel_dielectric(mu, max(float(ior), 1e-5)) * mu))


def _mix_factor(node, ctx):
    """(constant factor, Fresnel IOR or None, the per-hit Fac Value or None) of a Mix
    Shader's Fac (constant: its value; varying: its average)."""
    sock = node.inputs[0]
    found = _link(sock)
    if found is None:
        return float(np.clip(sock.default_value, 0.0, 1.0)), None, None
    src, out = found
    if src.bl_idname == "ShaderNodeFresnel":
        ior = _constant(src, "IOR", ctx, 1.5)
        return _fresnel_average(ior), ior, ctx.nodes.socket(sock, "float")
    if src.bl_idname == "ShaderNodeLayerWeight":
        blend = float(np.clip(_constant(src, "Blend", ctx, 0.5), 0.0, 1.0 - 1e-5))
        if out.identifier == "Fresnel":
            ior = 1.0 / max(1.0 - blend, 1e-5)
            return _fresnel_average(ior), ior, ctx.nodes.socket(sock, "float")
        # Facing: 1 - |cos|^b with Cycles' remapping of Blend; cosine-weighted average
        b = 2.0 * blend if blend < 0.5 else 0.5 / (1.0 - blend)
        return 1.0 - 2.0 / (b + 2.0), None, ctx.nodes.socket(sock, "float")
    value = ctx.nodes.socket(sock, "float")
    folded = ctx.nodes.fold(value)
    if folded is not None:
        return float(np.clip(folded, 0.0, 1.0)), None, None
    return float(np.clip(ctx.nodes.mean(value), 0.0, 1.0)), None, value


def per_hit_emission(a: _Closure, b: _Closure, fac, ctx):
    """The emission of a Mix Shader whose Fac varies per hit (the program value `fac`):
    Cycles weighs both shaders' emissions at the hit by 1 - Fac and Fac, the Fac clamped
    to [0, 1] (svm_node_mix_closure), so a hit sees that sum, not the mix at the Fac's
    average (which is what the rest of the mixed closure set holds)."""
    nodes = ctx.nodes
    f = NodeParam(nodes.emit(cv.CV_MATH, "float", [fac, nodes.const(1.0), nodes.const(0.0),
                                                   cv.MATH_OPS.index("MULTIPLY_ADD"), 1]),
                  nodes)
    return _lin([(1.0, _scale(a.emission, f.scaled(-1.0, add=1.0))),
                 (1.0, _scale(b.emission, f))], ctx, "emission")


def lifted_mix(combine, a, b):
    """combine(a, b) (a constant Mix or an Add Shader of closures a and b), with a per-hit
    Mix Shader below it lifted above it: a constant combination distributes over a
    per-hit mix, combine(mix(f; A1, A2), B) = mix(f; combine(A1, B), combine(A2, B)), so
    each hit still picks one side by f (Material.mix) and shades the constant
    combination of that side. Where both have one, B's is lifted into each of A's sides
    (a chain of per-hit mixes)."""
    out = combine(a, b)
    if a.mix is not None:
        a1, a2, f = a.mix
        out.mix = (lifted_mix(combine, a1, b), lifted_mix(combine, a2, b), f)
    elif b.mix is not None:
        b1, b2, f = b.mix
        out.mix = (lifted_mix(combine, a, b1), lifted_mix(combine, a, b2), f)
    return out


def _plastic(a: _Closure, b: _Closure, ior, fac, ctx):
    """Mix(Fresnel(ior), A, B) with A one dielectric base closure and B one Glossy-like
    closure: Principled's specular layer over A's base. None if not of that form."""
    if a.alpha_texture is not None or b.alpha_texture is not None:
        return None
    if len(a.comps) != 1 or len(b.comps) != 1 or a.t_weight or b.t_weight:
        return None
    (_, ca), (_, cb) = a.comps[0], b.comps[0]
    if ca is NULL_COMP or cb is NULL_COMP:
        return None
    if _mean(ca.metallic) != 0.0 or ca.transmission != 0.0:
        return None
    if _mean(cb.metallic) != 1.0:
        return None
    mc = cb.metal_color if cb.metal_color is not None else cb.base
    if not _same(_mean(mc), WHITE):
        ctx.issue("the glossy side of a Fresnel-mixed shader is tinted; DRT's specular "
                  "layer is white")
    comp = replace(ca, spec=0.5, ior=float(ior), roughness=cb.roughness,
                   distribution=cb.distribution)
    return _Closure([(1.0, comp)], 0.0, BLACK,
                    _lin([(1.0 - fac, a.emission), (fac, b.emission)], ctx, "emission"),
                    plain_emission=a.plain_emission or b.plain_emission)
