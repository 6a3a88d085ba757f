"""Shader nodes (the BSDFs, Emission, Transparent, Mix and Add Shader) to closures:
`_closure` reads the shader tree behind a socket; the inputs of each BSDF are compiled
into the material's program where linked (`_input`, export.nodes.shader_inputs); a Mix
Shader's Fac is read by export.nodes.shader_mix."""
from __future__ import annotations

import numpy as np

from ...blender_compat import node_input
from ..closures import BLACK, NULL_COMP, WHITE, _Closure, _Comp, _Layers, _sum
from ..material_params import TOL, NodeParam, _is_tex, _lin, _scale
from .links import _link
from .shader_inputs import _constant, _input
from .shader_mix import _mix_factor, _plastic, lifted_mix, per_hit_emission
from . import anisotropy, hair, metallic, subsurface


# --------------------------------------------------------------------------- nodes
def _principled(node, ctx) -> _Closure:
    def val(name, default, color=False):
        return _input(node, name, ctx, color, default)

    def const(name, default):
        return _constant(node, name, ctx, default)

    comp = _Comp(base=val("Base Color", (0.8, 0.8, 0.8), True),
                 metallic=val("Metallic", 0.0), transmission=const("Transmission Weight", 0.0),
                 roughness=val("Roughness", 0.5), ior=const("IOR", 1.5),
                 spec=const("Specular IOR Level", 0.5),
                 distribution=_distribution(node, ctx), layers=_principled_layers(node, ctx))
    comp.subsurface = subsurface.principled(node, ctx, _constant, comp.ior)
    if node_input(node, "Diffuse Roughness") is not None:      # Blender 4.3 and later
        comp.diffuse_roughness = float(const("Diffuse Roughness", 0.0))
    comp.anisotropy = anisotropy.read(node, ctx, "Anisotropic", "Anisotropic Rotation",
                                      "PRINCIPLED")
    comp.thin_film = _thin_film(node, ctx)
    s = node_input(node, "Specular Tint")
    if s is not None and (s.is_linked or _tinted(s.default_value)):
        # the metal lobe's F82 tint, the specular layer's and the glass's F0 tint
        # (Cycles' meaning, engine/kernels/bsdf/specular_tint.py)
        tint = _constant(node, "Specular Tint", ctx, WHITE, color=True)
        if isinstance(tint, float):               # a pre-4.0 amount of the base colour
            tint = WHITE
        comp.specular_tint = tuple(float(x) for x in tuple(tint)[:3])
    _normal(node, ctx)
    color = val("Emission Color", (1.0, 1.0, 1.0), True)
    strength = const("Emission Strength", 0.0)
    emission = _scale(color, strength)
    alpha = val("Alpha", 1.0)
    if _is_tex(alpha):
        return _Closure([(1.0, comp)], 0.0, BLACK, emission, alpha_texture=alpha)
    a = float(np.clip(alpha, 0.0, 1.0))
    # Cycles: BSDF weight a, transparent 1 - a, emission times a
    return _Closure([(a, comp)], 1.0 - a, (1.0 - a,) * 3, _scale(emission, a))


def _thin_film(node, ctx):
    """(thickness nm, IOR) of the Principled BSDF's Thin Film (Blender 4.2 and later), or
    None: on the specular layer, the metal and the glass, as Cycles lays it
    (engine/kernels/bsdf/thin_film.py)."""
    if node_input(node, "Thin Film Thickness") is None:
        return None
    thickness = float(_constant(node, "Thin Film Thickness", ctx, 0.0))
    if not thickness > 0.10000000149011612:   # Cycles' THINFILM_THICKNESS_CUTOFF, float32
        return None
    return thickness, max(float(_constant(node, "Thin Film IOR", ctx, 1.33)), 1e-5)


def _tinted(tint) -> bool:
    """Specular Tint is not white (a colour since Blender 4.0; before, a float amount of
    the base colour, 0 for none)."""
    if isinstance(tint, float):
        return tint > 0.0
    return any(abs(x - 1.0) > TOL for x in tint[:3])


def _principled_layers(node, ctx):
    """Principled's coat and sheen (constants; a per-hit input is replaced by its
    average, reported), or None when both weights are 0."""
    def const(name, default, color=False):
        return _constant(node, name, ctx, default, color)
    coat = max(float(const("Coat Weight", 0.0)), 0.0)
    sheen = max(float(const("Sheen Weight", 0.0)), 0.0)
    if coat <= 0.0 and sheen <= 0.0:
        return None
    s = node_input(node, "Coat Normal")
    if coat > 0.0 and s is not None and _link(s) is not None:
        # the coat's own normal, per hit (engine.kernels.surface_hit.coat_frame; unlinked,
        # the kernel gives the coat the surface's normal, as Cycles does)
        ctx.coat_normal = ctx.nodes.convert(ctx.nodes.socket(s, "vector"), "vector")
    return _Layers(coat_weight=coat, coat_roughness=float(const("Coat Roughness", 0.03)),
                   coat_ior=float(const("Coat IOR", 1.5)),
                   coat_tint=tuple(const("Coat Tint", WHITE, True)), sheen_weight=sheen,
                   sheen_roughness=float(const("Sheen Roughness", 0.5)),
                   sheen_tint=tuple(const("Sheen Tint", WHITE, True)))


def _sheen(node, ctx) -> _Closure:
    """Sheen BSDF: Cycles' microfiber sheen beside the other closures."""
    _normal(node, ctx)
    if getattr(node, "distribution", "MICROFIBER") != "MICROFIBER":
        ctx.issue(f"{node.name!r} uses the {node.distribution} sheen; DRT renders the "
                  f"Microfiber one")
    color = _constant(node, "Color", ctx, (0.8,) * 3, color=True)
    layers = _Layers(sheen_weight=1.0, sheen_tint=tuple(color), sheen_layered=False,
                     sheen_roughness=float(_constant(node, "Roughness", ctx, 0.5)))
    return _Closure([(1.0, _Comp(base=BLACK, spec=0.0, layers=layers))])


def _translucent(node, ctx) -> _Closure:
    """Translucent BSDF: Lambertian transmission of its colour (per hit where linked)."""
    _normal(node, ctx)
    color = _input(node, "Color", ctx, True, (0.8,) * 3)
    color = color if _is_tex(color) else tuple(color)
    return _Closure([(1.0, _Comp(base=BLACK, spec=0.0,
                                 layers=_Layers(translucent_color=color)))])


def _scattering(node, ctx) -> _Closure:
    """Subsurface Scattering node: all of its weight walks below the surface, its Color
    the albedo (export/nodes/subsurface.py); no specular layer."""
    _normal(node, ctx)
    return _Closure([(1.0, _Comp(base=_input(node, "Color", ctx, True, (0.8,) * 3),
                                 spec=0.0,
                                 subsurface=subsurface.scattering_node(node, ctx,
                                                                       _constant)))])


def _normal(node, ctx):
    """A BSDF's linked Normal input: the material's per-hit shading normal (one per
    material: a second, different one in a mix is reported and left out)."""
    sock = node_input(node, "Normal")
    if sock is None or _link(sock) is None:
        return
    value = ctx.nodes.socket(sock, "vector")
    if not value.varying:
        ctx.issue(f"the Normal of {node.name!r} is a constant direction; DRT keeps the "
                  f"surface's normal")
        return
    if ctx.normal is None:
        ctx.normal = value
    elif ctx.normal.reg != value.reg:
        ctx.issue(f"mixed shaders have different normals; DRT uses the first one's for "
                  f"all ({node.name!r} left out)")


def _diffuse(node, ctx) -> _Closure:
    _normal(node, ctx)
    # Roughness: Oren-Nayar (kernels/bsdf/oren_nayar.py), a constant per material
    return _Closure([(1.0, _Comp(base=_input(node, "Color", ctx, True, (0.8,) * 3),
                                 spec=0.0,
                                 diffuse_roughness=float(_constant(node, "Roughness", ctx,
                                                                   0.0))))])


def _distribution(node, ctx) -> str:
    """The engine glossy_model of a node's microfacet distribution."""
    d = getattr(node, "distribution", "MULTI_GGX")
    if d in ("MULTI_GGX", "GGX", "BECKMANN"):
        return d
    ctx.issue(f"{node.name!r} uses the {d} distribution; DRT uses GGX")
    return "GGX"


def _glossy(node, ctx) -> _Closure:
    _normal(node, ctx)
    distribution = _distribution(node, ctx)
    color = _input(node, "Color", ctx, True, (0.8,) * 3)
    # Cycles' Glossy has no Fresnel term: its colour at every angle
    return _Closure([(1.0, _Comp(base=color, metallic=1.0,
                                 roughness=_input(node, "Roughness", ctx, False, 0.5),
                                 distribution=distribution, metal_fresnel="CONSTANT",
                                 anisotropy=anisotropy.read(node, ctx, "Anisotropy",
                                                            "Rotation", "GLOSSY")))])


def _metallic(node, ctx) -> _Closure:
    """Metallic BSDF: the Principled metal lobe (export/nodes/metallic.py)."""
    _normal(node, ctx)
    distribution = _distribution(node, ctx)
    s = node_input(node, "Thin Film Thickness")
    if s is not None and (s.is_linked or float(s.default_value) > 0.0):
        ctx.issue(f"{node.name!r} uses thin film, which DRT does not render (left out)")
    base, tint = metallic.metal_inputs(
        node, ctx, lambda name, default: _input(node, name, ctx, True, default),
        lambda name, default: _constant(node, name, ctx, default, color=True))
    return _Closure([(1.0, _Comp(base=base, metallic=1.0, specular_tint=tint,
                                 roughness=_input(node, "Roughness", ctx, False, 0.5),
                                 distribution=distribution,
                                 anisotropy=anisotropy.read(node, ctx, "Anisotropy",
                                                            "Rotation", "PRINCIPLED")))])


def _glass(node, ctx, refraction=False) -> _Closure:
    """Glass BSDF, or with `refraction` the Refraction BSDF (its refraction alone)."""
    _normal(node, ctx)
    # also for a smooth interface: Filter Glossy widens it into a rough lobe of this
    # distribution after blurry bounces
    distribution = _distribution(node, ctx)
    color = _input(node, "Color", ctx, True, WHITE)
    if _is_tex(color):
        ctx.issue(f"the colour of {node.name!r} is textured; DRT tints its reflection "
                  f"and refraction with the texture's average")
        color = color.mean()
    s = node_input(node, "Thin Film Thickness")
    if s is not None and (s.is_linked or float(s.default_value) > 0.0):
        ctx.issue(f"{node.name!r} uses thin film, which DRT does not render (left out)")
    comp = _Comp(base=color, transmission=1.0,
                 roughness=_input(node, "Roughness", ctx, False, 0.0),
                 ior=_constant(node, "IOR", ctx, 1.5), glass_color=color,
                 glass_reflect=tuple(float(x) for x in color),
                 distribution=distribution, refraction_only=refraction)
    return _Closure([(1.0, comp)])


def _emission(node, ctx) -> _Closure:
    color = _input(node, "Color", ctx, True, WHITE)
    strength = _input(node, "Strength", ctx, False, 1.0)      # per hit where it varies
    return _Closure([(1.0, NULL_COMP)], emission=_scale(color, strength),
                    plain_emission=True)


def _transparent(node, ctx) -> _Closure:
    color = _constant(node, "Color", ctx, WHITE, color=True)
    return _Closure([], 1.0, color)


MAX_SHADER_READS = 2048


def _add(a: _Closure, b: _Closure, ctx) -> _Closure:
    """An Add Shader of a and b: an emission added to the other's closures, or two BSDFs'
    lobes summed."""
    if a.is_emission_only() or b.is_emission_only():
        emit, other = (a, b) if a.is_emission_only() else (b, a)
        return _Closure(other.comps, other.t_weight, other.t_color,
                        _lin([(1.0, emit.emission), (1.0, other.emission)], ctx,
                             "emission"), other.alpha_texture, h_weight=other.h_weight,
                        plain_emission=emit.plain_emission or other.plain_emission)
    return _sum(a, b, ctx)


def _converted_emission(socket, out, ctx) -> _Closure:
    """A value linked into a shader socket, which Cycles turns into an Emission of
    strength 1 (ShaderGraph::connect's automatic conversion): a float feeds its Strength
    (its colour white), anything else its Color."""
    kind = "float" if out.type in ("VALUE", "INT", "BOOLEAN") else "color"
    value = ctx.nodes.socket(socket, kind)
    folded = ctx.nodes.fold(value)
    param = folded if folded is not None else NodeParam(value, ctx.nodes)
    emission = _scale(WHITE, param) if kind == "float" else param
    return _Closure([(1.0, NULL_COMP)], emission=emission, plain_emission=True)


def _closure(socket, ctx, depth=0) -> _Closure:
    """The closure feeding a shader socket."""
    found = _link(socket)
    if found is None:
        return _Closure([(1.0, NULL_COMP)])       # no closure: black
    node = found[0]
    if found[1].type != "SHADER":
        return _converted_emission(socket, found[1], ctx)
    # a tree is read node by node along every path to the output: shared sub-trees are
    # read again for each path, so a long chain of shaders feeding both inputs of the
    # next Mix would take 2^length reads; past MAX_SHADER_READS the rest is cut off
    ctx.shader_reads = getattr(ctx, "shader_reads", 0) + 1
    if depth > 32 or ctx.shader_reads > MAX_SHADER_READS:
        ctx.issue("the shader tree is too deep; rendering the rest as the viewport colour")
        return _Closure([(1.0, ctx.viewport_comp())])
    kind = node.bl_idname
    if kind == "ShaderNodeBsdfPrincipled":
        return _principled(node, ctx)
    if kind == "ShaderNodeBsdfDiffuse":
        return _diffuse(node, ctx)
    if kind == "ShaderNodeBsdfGlossy" or kind == "ShaderNodeBsdfAnisotropic":
        return _glossy(node, ctx)
    if kind == "ShaderNodeBsdfMetallic":
        return _metallic(node, ctx)
    if kind == "ShaderNodeBsdfGlass":
        return _glass(node, ctx)
    if kind == "ShaderNodeBsdfRefraction":
        return _glass(node, ctx, refraction=True)
    if kind == "ShaderNodeBsdfSheen":
        return _sheen(node, ctx)
    if kind == "ShaderNodeBsdfTranslucent":
        return _translucent(node, ctx)
    if kind == "ShaderNodeSubsurfaceScattering":
        return _scattering(node, ctx)
    if kind == "ShaderNodeBsdfHair":
        return hair.hair_bsdf(node, ctx, _constant)
    if kind == "ShaderNodeBsdfHairPrincipled":
        return hair.principled_hair(node, ctx, _constant, _input)
    if kind == "ShaderNodeEmission":
        return _emission(node, ctx)
    if kind == "ShaderNodeBsdfTransparent":
        return _transparent(node, ctx)
    if kind == "ShaderNodeHoldout":
        # a hole in the camera's alpha where it weighs (engine Material.holdout_weight)
        return _Closure([], h_weight=1.0)
    if kind == "ShaderNodeMixShader":
        fac, ior, varying = _mix_factor(node, ctx)
        a = _closure(node.inputs[1], ctx, depth + 1)
        b = _closure(node.inputs[2], ctx, depth + 1)
        if ior is not None:
            p = _plastic(a, b, ior, fac, ctx)
            if p is not None:
                ctx.issue(f"the Fresnel-driven {node.name!r} is rendered as a Principled "
                          f"specular layer of IOR {ior:.3g}")
                return p
        if varying is None:
            # a per-hit Mix below is lifted above this one (lifted_mix)
            return lifted_mix(lambda x, y: _sum(x.scaled(1.0 - fac, ctx),
                                                y.scaled(fac, ctx), ctx), a, b)
        # per hit: export_material makes a Material of each side
        mixed = _sum(a.scaled(1.0 - fac, ctx), b.scaled(fac, ctx), ctx)
        mixed.emission = per_hit_emission(a, b, varying, ctx)
        mixed.mix = (a, b, varying)
        return mixed
    if kind == "ShaderNodeAddShader":
        a = _closure(node.inputs[0], ctx, depth + 1)
        b = _closure(node.inputs[1], ctx, depth + 1)
        if not (a.is_emission_only() or b.is_emission_only()):
            ctx.issue(f"{node.name!r} adds two BSDFs; DRT renders their sum as one "
                      f"Principled BSDF (lobe weights and colours summed)")
        return lifted_mix(lambda x, y: _add(x, y, ctx), a, b)
    ctx.issue(f"it uses the {node.bl_label!r} node, which DRT does not support yet; "
              f"rendering it as a diffuse surface of its viewport colour")
    return _Closure([(1.0, ctx.viewport_comp())])
