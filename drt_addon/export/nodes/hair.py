"""Hair shader nodes to closures: the Hair BSDF node (Cycles' HairBsdfNode: a Reflection
or a Transmission component about the fibre's direction), rendered by
engine/kernels/bsdf/hair.py beside the material's other lobes."""
from __future__ import annotations

from ...blender_compat import node_input
from ..closures import BLACK, _Closure, _Comp, _Layers
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
