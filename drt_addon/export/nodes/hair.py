"""Hair shader nodes to closures: the Hair BSDF node (Cycles' HairBsdfNode: a Reflection
or a Transmission component about the fibre's direction), rendered by
engine/kernels/bsdf/hair.py, and the Principled Hair BSDF (engine.principled_hair,
rendered by engine/kernels/bsdf/hair_chiang.py), beside the material's other lobes."""
from __future__ import annotations

from ...blender_compat import node_input
from ...engine_link import engine
from ..closures import BLACK, _Closure, _Comp, _Layers
from ..material_params import _is_tex
from .links import _link


def hair_bsdf(node, ctx, constant) -> _Closure:
    """Hair BSDF: its Color, Offset and RoughnessU / V (`constant` reads a socket, a
    linked one by its average, reported). A linked Tangent is reported: DRT shades about
    the strand's direction (a mesh's triangle edge), as Cycles does when it is unlinked."""
    component = getattr(node, "component", "Reflection")
    color = tuple(constant(node, "Color", ctx, (0.8, 0.8, 0.8), color=True))
    offset = float(constant(node, "Offset", ctx, 0.0))
    rough = (float(constant(node, "RoughnessU", ctx, 0.1)),
             float(constant(node, "RoughnessV", ctx, 1.0)))
    tangent = node_input(node, "Tangent")
    if tangent is not None and _link(tangent) is not None:
        ctx.issue(f"the Tangent of {node.name!r} is linked; DRT shades it about the strand's "
                  f"own direction (a mesh's: its triangles' second edge, as Cycles' default)")
    if component == "Transmission":
        layers = _Layers(hair_transmission=color, hair_transmission_roughness=rough,
                         hair_transmission_offset=offset)
    else:
        layers = _Layers(hair_reflection=color, hair_reflection_roughness=rough,
                         hair_reflection_offset=offset)
    return _Closure([(1.0, _Comp(base=BLACK, spec=0.0, layers=layers))])


def _from_hair_random(socket) -> bool:
    """Whether `socket` is fed by a Hair Info node's Random: what Cycles reads when the
    socket is unlinked, so it stays per strand."""
    link = _link(socket)
    return (link is not None and link[0].bl_idname == "ShaderNodeHairInfo"
            and link[1].name == "Random")


def principled_hair(node, ctx, constant, value) -> _Closure:
    """Principled Hair BSDF (Cycles' PrincipledHairBsdfNode, Chiang model): its inputs as
    the node's parametrization reads them. The colour it reads (Color, Absorption
    Coefficient or Tint) and Melanin may vary per hit (`value`: a NodeParam, which
    becomes an output of the material's program); the others are read by `constant`
    (a linked one by its average, reported). The Huang model is rendered with Chiang's,
    reported."""
    if getattr(node, "model", "CHIANG") != "CHIANG":
        ctx.issue(f"{node.name!r} uses the Huang hair model; DRT renders it with the Chiang "
                  f"model (its Aspect Ratio and lobe weights are left out)")
    mode = getattr(node, "parametrization", "COLOR")
    if mode not in ("COLOR", "ABSORPTION", "MELANIN"):
        ctx.issue(f"{node.name!r} has the parametrization {mode!r}; DRT reads its Color")
        mode = "COLOR"
    PrincipledHair = engine.PrincipledHair
    d = PrincipledHair()

    def num(name, default):
        return float(constant(node, name, ctx, default))
    programs = {}

    def per_hit(name, default, output, color):
        v = value(node, name, ctx, color, default)
        if _is_tex(v):
            programs[output] = v
            v = v.mean()
        return tuple(float(x) for x in v)[:3] if color else float(v)
    kw = {}
    if mode == "COLOR":
        kw["color"] = per_hit("Color", d.color, "hair_color", True)
    elif mode == "ABSORPTION":
        kw["absorption"] = per_hit("Absorption Coefficient", d.absorption, "hair_color", True)
    else:
        kw.update(melanin=per_hit("Melanin", d.melanin, "hair_melanin", False),
                  melanin_redness=num("Melanin Redness", d.melanin_redness),
                  tint=per_hit("Tint", d.tint, "hair_color", True),
                  random_color=num("Random Color", d.random_color))
    random = node_input(node, "Random")
    linked = random is not None and _link(random) is not None
    own = not linked or _from_hair_random(random)
    # a mesh reads the unlinked socket's value, Hair Info's Random there is 0
    random_value = 0.0 if (linked and own) else num("Random", d.random)
    hair = PrincipledHair(
        parametrization=mode, roughness=num("Roughness", d.roughness),
        radial_roughness=num("Radial Roughness", d.radial_roughness),
        coat=num("Coat", d.coat), ior=num("IOR", d.ior), offset=num("Offset", d.offset),
        random_roughness=num("Random Roughness", d.random_roughness),
        random=random_value, strand_random=own, **kw)
    layers = _Layers(principled_hair=hair, principled_hair_programs=programs)
    return _Closure([(1.0, _Comp(base=BLACK, spec=0.0, layers=layers))])
