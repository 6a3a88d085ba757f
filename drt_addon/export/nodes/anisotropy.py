"""Anisotropic reflection of the Principled, Metallic and Glossy BSDFs (Cycles'
Anisotropic or Anisotropy, Rotation and Tangent) as a closure's `Anisotropy`, and onto
an engine Material (engine/kernels/bsdf/anisotropic.py renders it).

The tangent is always a per-hit value of the material's program: the node's linked
Tangent, or when unlinked the Geometry node's tangent (radial about the object's Z), as
Cycles links it. The amount is one value per material (a linked one: its average,
reported); Rotation may vary per hit."""
from __future__ import annotations

from dataclasses import dataclass

from ...blender_compat import node_input
from ..material_params import NodeParam, _is_tex
from .input import geometry_tangent
from .links import _link
from .shader_inputs import _constant, _input


@dataclass
class Anisotropy:
    kind: str              # 'PRINCIPLED' (Principled, Metallic) or 'GLOSSY': the mapping
    amount: float          # Anisotropic / Anisotropy
    rotation: object       # Rotation in turns: a float or a NodeParam
    tangent: NodeParam     # the direction, per hit


def read(node, ctx, amount_socket, rotation_socket, kind):
    """The node's anisotropy, or None where it is isotropic (Cycles' thresholds: the
    Principled's > 0, the Metallic's and Glossy's |a| > 1e-4)."""
    sock = node_input(node, amount_socket)
    if sock is None:
        return None
    amount = float(_constant(node, amount_socket, ctx, 0.0))
    if kind == "PRINCIPLED":
        amount = min(max(amount, 0.0), 1.0)
        isotropic = amount <= 0.0 if node.bl_idname == "ShaderNodeBsdfPrincipled" \
            else amount <= 1e-4
    else:
        amount = min(max(amount, -0.99), 0.99)
        isotropic = abs(amount) <= 1e-4
    if isotropic:
        return None
    tangent_sock = node_input(node, "Tangent")
    if tangent_sock is not None and _link(tangent_sock) is not None:
        value = ctx.nodes.convert(ctx.nodes.socket(tangent_sock, "vector"), "vector")
    else:
        value = geometry_tangent(ctx.nodes)
    rotation = _input(node, rotation_socket, ctx, False, 0.0)
    return Anisotropy(kind, amount, rotation, NodeParam(value, ctx.nodes))


def blend(comps, ctx):
    """The anisotropy of a mixture [(weight, _Comp)]: that of the closure with the most
    glossy weight, reported where another glossy closure differs."""
    glossy = [(c * comp.glossy_weight(), comp.anisotropy) for c, comp in comps]
    glossy = [(w, a) for w, a in glossy if w > 0]
    if not glossy:
        return None
    main = max(glossy, key=lambda x: x[0])[1]
    if any(a is not main for _, a in glossy):
        ctx.issue("mixed glossy closures differ in anisotropy; DRT gives all of them the "
                  "anisotropy of the one with the most weight")
    return main


def apply(m, aniso, outputs):
    """Set engine Material m's anisotropy; its per-hit values join the program's
    `outputs` ({OUTPUTS name: Value})."""
    if aniso is None:
        return
    m.anisotropy_kind = aniso.kind
    m.anisotropy = float(aniso.amount)
    outputs["tangent"] = aniso.tangent.value
    if _is_tex(aniso.rotation):
        outputs["anisotropic_rotation"] = aniso.rotation.value
        m.anisotropic_rotation = float(aniso.rotation.mean())
    else:
        m.anisotropic_rotation = float(aniso.rotation)
