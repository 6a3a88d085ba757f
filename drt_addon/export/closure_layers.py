"""The lobes a closure adds beyond the Principled base (coat, sheen, translucency,
hair), as engine.scene.Material fields (`_Layers`), and how mixed closures blend them:
weights and colours summed, roughness, IOR and tint averaged by weight."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .material_params import _lin, _plain

WHITE = (1.0, 1.0, 1.0)
BLACK = (0.0, 0.0, 0.0)
HAIR_PARTS = ("hair_reflection", "hair_transmission")
LAYER_FIELDS = ("coat_weight", "coat_roughness", "coat_ior", "coat_tint", "sheen_weight",
                "sheen_roughness", "sheen_tint", "sheen_layered", "translucent_color",
                "principled_hair") + \
    tuple(p + k for p in HAIR_PARTS for k in ("", "_roughness", "_offset"))


@dataclass
class _Layers:
    """A closure's lobes beyond the Principled base, as engine.scene.Material fields:
    Principled's coat and sheen (layered over the base), a Sheen BSDF node's sheen
    (sheen_layered False: beside the other closures), a Translucent BSDF's colour and a
    Hair BSDF's components (colour, RoughnessU / V, Offset) and a Principled Hair BSDF
    (engine.PrincipledHair, its weight colour included), beside the rest."""
    coat_weight: float = 0.0
    coat_roughness: float = 0.03
    coat_ior: float = 1.5
    coat_tint: tuple = WHITE
    sheen_weight: float = 0.0
    sheen_roughness: float = 0.5
    sheen_tint: tuple = WHITE
    sheen_layered: bool = True
    translucent_color: object = BLACK       # a colour, or per hit a NodeParam
    hair_reflection: tuple = BLACK
    hair_reflection_roughness: tuple = (0.1, 1.0)
    hair_reflection_offset: float = 0.0
    hair_transmission: tuple = BLACK
    hair_transmission_roughness: tuple = (0.1, 1.0)
    hair_transmission_offset: float = 0.0
    principled_hair: object = None
    principled_hair_programs: dict = None   # its per-hit inputs: {program output: NodeParam}


def _blend_hair(with_layers, ctx):
    """The Principled Hair of a mixture and its per-hit inputs: weights summed (scaled
    by the mix), the inputs of the heaviest (reported where they differ)."""
    hairs = [(c, L) for c, L in with_layers if L.principled_hair is not None]
    if not hairs:
        return None, None
    weight = tuple(float(sum(c * L.principled_hair.weight[k] for c, L in hairs))
                   for k in range(3))
    _, heaviest = max(hairs, key=lambda cL: cL[0] * max(cL[1].principled_hair.weight))
    if len({replace(L.principled_hair, weight=(1.0, 1.0, 1.0)) for _, L in hairs}) > 1 or \
            any(L.principled_hair_programs for _, L in hairs if L is not heaviest):
        ctx.issue("mixed Principled Hair BSDFs have different inputs; DRT uses the "
                  "heaviest one's")
    return (replace(heaviest.principled_hair, weight=weight),
            heaviest.principled_hair_programs)


def _blend_layers(comps, ctx):
    """The _Layers of a convex combination [(c_i, _Comp)]: weights and colours summed
    (Cycles sums the mixed closures), roughness, IOR and tint averaged by weight (exact
    when they agree; reported otherwise)."""
    with_layers = [(c, comp.layers) for c, comp in comps if comp.layers is not None]
    if not with_layers:
        return None
    if len(with_layers) == 1 and len(comps) == 1:
        return with_layers[0][1]
    out = _Layers()
    cw = [(c * L.coat_weight, L) for c, L in with_layers if L.coat_weight > 0]
    sw = [(c * L.sheen_weight, L) for c, L in with_layers if L.sheen_weight > 0]
    out.coat_weight = float(sum(w for w, _ in cw))
    out.sheen_weight = float(sum(w for w, _ in sw))

    def avg(terms, name):
        total = sum(w for w, _ in terms)
        vals = [np.asarray(getattr(L, name), float) for _, L in terms]
        if len({tuple(np.atleast_1d(v).round(6)) for v in vals}) > 1:
            ctx.issue(f"mixed shaders have different {name.replace('_', ' ')}s; DRT uses "
                      f"their weighted mean")
        return _plain(sum(w * v for (w, _), v in zip(terms, vals)) / total)
    if cw:
        for name in ("coat_roughness", "coat_ior", "coat_tint"):
            setattr(out, name, avg(cw, name))
    if sw:
        for name in ("sheen_roughness", "sheen_tint"):
            setattr(out, name, avg(sw, name))
        kinds = {L.sheen_layered for _, L in sw}
        if len(kinds) > 1:
            ctx.issue("a Principled sheen and a Sheen BSDF are mixed; DRT layers both")
        out.sheen_layered = True in kinds
    if out.coat_weight > 0 or (out.sheen_weight > 0 and out.sheen_layered):
        if any(L.coat_weight == 0 and L.sheen_weight == 0 for _, L in with_layers) or \
                len(with_layers) < len(comps):
            ctx.issue("a coated or sheened Principled BSDF is mixed with other shaders; DRT "
                      "layers the mixture's coat and sheen over all of them")
    # (per hit where one is: the program sums them)
    out.translucent_color = _lin([(c, L.translucent_color) for c, L in with_layers], ctx,
                                 "translucent colour") or BLACK
    for part in HAIR_PARTS:
        # colours summed; roughness and offset averaged by the colours' weight
        hw = [(c * max(getattr(L, part)), L) for c, L in with_layers
              if max(getattr(L, part)) > 0]
        setattr(out, part, _plain(sum(c * np.asarray(getattr(L, part), float)
                                      for c, L in with_layers)))
        if hw:
            for name in (part + "_roughness", part + "_offset"):
                setattr(out, name, avg(hw, name))
    out.principled_hair, out.principled_hair_programs = _blend_hair(with_layers, ctx)
    return out
