"""Blender materials to DRT's Principled parameters, with Cycles' meaning of each node.

The node tree behind the active Material Output's Surface socket is read as a weighted
set of closures, as Cycles builds it (intern/cycles/kernel/svm/closure.h), and reduced to
one `engine.Material`:

Principled BSDF
    Base Color, Metallic, Roughness (GGX alpha = roughness^2), IOR, Transmission Weight,
    Specular IOR Level and Emission Color x Emission Strength as they are. Alpha a: the
    BSDF gets weight a and a Transparent BSDF the rest (so emission is a x emission on
    average), rendered as stochastic transparency. Coat, sheen, subsurface, anisotropy,
    specular tint, thin film and diffuse roughness are not modelled: reported when used.
    The node's distribution is the material's `glossy_model`: 'MULTI_GGX' (Blender's
    default, Cycles' energy-compensated GGX) or 'GGX' (single scattering).
Diffuse BSDF
    Lambert with its colour (no specular layer). Roughness > 0 (Oren-Nayar) is reported.
Glossy BSDF
    GGX reflection of its colour with its roughness: DRT's metal lobe with F0 = colour.
    Cycles' Glossy has no Fresnel (reflectance = colour at every angle); Schlick's F0
    lobe reaches white only at grazing angles, so edges are a little brighter here.
    Multiscatter GGX (the default) and GGX are kept (Cycles' multiscatter Glossy colours
    its extra bounces by the colour itself, DRT's by Schlick's average of it); Beckmann
    and Ashikhmin-Shirley are rendered as GGX (reported).
Glass BSDF
    DRT's glass lobe with the node's IOR, roughness and distribution (Multiscatter GGX
    or GGX; Beckmann is rendered as GGX, reported); its colour tints each refraction
    (`Material.glass_color`), as Cycles' Glass does (Cycles also tints the reflection).
Refraction BSDF
    Approximated by the glass lobe (which also reflects): reported.
Emission
    Radiance = colour x strength (no 1/pi); alone it is an opaque black emitter, as in
    Cycles (an Emission shader has no BSDF).
Transparent BSDF
    A pass-through closure of its colour (`Material.alpha`, `transparent_color`).
Mix Shader
    Fac constant: closures are weighted by 1 - Fac and Fac and the mixture is reduced to
    one Principled parameter set: the lobe weights (metal, glass, dielectric base,
    transparent) mix exactly, each lobe's colour is the weighted mean of the colours of
    the closures that contribute to it (a Glossy's colour becomes the metal colour, a
    Diffuse's the base colour), roughness and IOR are means weighted by the lobes that use
    them; the distribution is that of the closure with the largest glossy weight
    (reported when they differ). Fac from a Fresnel or Layer Weight node (angle-dependent
    in Cycles): a Mix of a
    dielectric base with a Glossy BSDF becomes Principled's own Fresnel-weighted specular
    layer with that IOR (the classic "plastic" set-up, which is what that layer models);
    otherwise the factor is replaced by its average over the cosine-weighted hemisphere.
    Both approximations are reported.
Add Shader
    Emission + BSDF is exact (the emissions add, the BSDF stays). Two BSDFs are summed
    as a mix at 1/2 with their colours doubled (exact for the lobe colours, reported).
Linked inputs (any node graph, engine/nodes and export/nodes)
    The graph linked to an input is compiled into the material's shader program, which
    the engine runs at every hit (`engine.nodes`): Image, Checker and Gradient textures,
    the procedural textures with Blender's own noise (White Noise, Noise, Voronoi, Wave,
    Magic, Brick), the colour, converter, vector and input nodes, node groups and
    reroutes. A graph
    that does not depend on the hit is folded into a constant at export. Base Color,
    Metallic, Roughness, Emission Color and Strength and Alpha (and the Color of
    Diffuse, Glossy and Emission) vary per hit; other inputs (IOR, Transmission, the
    Mix Shader's Fac...) take the graph's average over the unit square of UV and
    generated coordinates when it varies (reported). A node no family translates is
    reported and its socket keeps its own value. Images: 8-bit sRGB images are decoded
    after interpolation like Cycles; float images and Non-Color data are read as they
    are; straight-alpha images have their colour premultiplied when the Alpha output is
    not used (Cycles associates alpha on load).

Anything else falls back to a diffuse surface of the material's viewport colour. Every
approximation is reported once per material, in one warning naming the material.
"""
from __future__ import annotations

import importlib
import weakref
from dataclasses import dataclass, field, replace
from typing import Optional

import bpy
import numpy as np

from ..engine_link import engine
from .errors import Reporter
from .images import image_texture as _texture, read_pixels as _read_pixels  # noqa: F401
from .nodes import NodeCompiler

textures = importlib.import_module(engine.__name__ + ".textures")
fresnel = importlib.import_module(engine.__name__ + ".bsdf.fresnel")
cv = importlib.import_module(engine.__name__ + ".nodes.converter_nodes")
ve = importlib.import_module(engine.__name__ + ".nodes.vector_nodes")

WHITE = (1.0, 1.0, 1.0)
BLACK = (0.0, 0.0, 0.0)
MISSING = tuple(textures.MISSING_RGBA[:3])
TOL = 1e-6

# Image pixels and Textures, once per export: keyed by the export's Reporter (a new one
# per export), so an edited image is read again at the next render.
_image_caches: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def uses_nodes(datablock) -> bool:
    """Blender 5 always uses the node tree (use_nodes is deprecated); 4.x has the toggle."""
    if datablock.node_tree is None:
        return False
    return bpy.app.version >= (5, 0, 0) or datablock.use_nodes


def _output_node(tree):
    outputs = [n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]
    for n in outputs:
        if getattr(n, "is_active_output", False) and n.target in ("ALL", "CYCLES"):
            return n
    for n in outputs:
        if n.target in ("ALL", "CYCLES"):
            return n
    return outputs[0] if outputs else None


def _link(socket):
    """(from node, from socket) feeding `socket`, through reroutes; None if unlinked
    (or linked only through a muted link)."""
    if not socket.is_linked:
        return None
    link = socket.links[0]
    if getattr(link, "is_muted", False):
        return None
    node, out = link.from_node, link.from_socket
    while node.bl_idname == "NodeReroute":
        if not node.inputs[0].is_linked:
            return None
        link = node.inputs[0].links[0]
        node, out = link.from_node, link.from_socket
    return node, out


def _linked_node(socket):
    found = _link(socket)
    return None if found is None else found[0]


# --------------------------------------------------------------------------- parameters
# A parameter ("Param") is a plain value (float, or an RGB 3-tuple) or a NodeParam: a
# value of the material's shader program, evaluated per hit.

class NodeParam:
    """A per-hit parameter: a register of the material's program (NodeCompiler)."""

    def __init__(self, value, nodes):
        self.value = value
        self.nodes = nodes
        self._mean = None

    @property
    def is_color(self) -> bool:
        return self.value.width == 3

    def mean(self):
        """A summary: the average over the unit square of UV and generated coordinates."""
        if self._mean is None:
            self._mean = self.nodes.mean(self.value)
        return self._mean

    def scaled(self, factor, add=0.0) -> "NodeParam":
        """factor x this + add (factor: a float or a NodeParam; add: float or triple)."""
        return NodeParam(_affine(self.nodes, self.value, factor, add), self.nodes)


def _affine(nodes, value, factor, add):
    f = factor.value if isinstance(factor, NodeParam) else nodes.const(float(factor))
    if value.width == 1 and f.width == 1:
        return nodes.emit(cv.CV_MATH, "float", [value, f, nodes.const(float(np.mean(add))),
                                                cv.MATH_OPS.index("MULTIPLY_ADD"), 0])
    if value.width == 1:
        value, f = f, value
    out = nodes.emit(ve.VEC_MATH, "vector", [value, value, value, nodes.convert(f, "float"),
                                             ve.VECTOR_OPS.index("SCALE")])
    if np.any(np.asarray(add, np.float64) != 0.0):
        a = nodes.const(tuple(np.broadcast_to(np.asarray(add, np.float64), (3,))), "vector")
        out = nodes.emit(ve.VEC_MATH, "vector", [out, a, a, a, ve.VECTOR_OPS.index("ADD")])
    return nodes.convert(out, "color")


def _is_tex(p) -> bool:
    return isinstance(p, NodeParam)


def _mean(p):
    return p.mean() if _is_tex(p) else p


def _plain(a):
    a = np.asarray(a, np.float64)
    return tuple(float(x) for x in a) if a.ndim else float(a)


def _same(a, b) -> bool:
    if a is None or b is None:
        return a is b
    if _is_tex(a) or _is_tex(b):
        return _is_tex(a) and _is_tex(b) and a.value.reg == b.value.reg
    return bool(np.allclose(np.asarray(a, float), np.asarray(b, float), atol=TOL))


def _scale(p, f):
    """p x f; f a float or a NodeParam (then p must be a Param of the same program)."""
    if _is_tex(f):
        if _is_tex(p):
            return p.scaled(f)
        if not np.any(np.asarray(p, np.float64)):
            return p
        if np.ndim(p) == 0:
            return f.scaled(float(p))
        c = f.nodes.const(tuple(p), "color")
        return NodeParam(_affine(f.nodes, c, f, 0.0), f.nodes)
    if _is_tex(p):
        if f == 0:
            return _plain(np.zeros(3)) if p.is_color else 0.0
        return p.scaled(f)
    return _plain(np.asarray(p, np.float64) * f)


def _lin(terms, ctx, what):
    """sum_i w_i p_i of Params, exact: NodeParams are summed by the program."""
    const = None
    node = None
    for w, p in terms:
        if w == 0 or p is None:
            continue
        if _is_tex(p):
            term = p.scaled(w)
            if node is None:
                node = term
            else:
                kind = "float" if node.value.width == 1 else "vector"
                a = ctx.nodes.convert(node.value, kind)
                b = ctx.nodes.convert(term.value, kind)
                if kind == "float":
                    s = ctx.nodes.emit(cv.CV_MATH, "float", [a, b, b, cv.MATH_OPS.index("ADD"),
                                                             0])
                else:
                    s = ctx.nodes.convert(ctx.nodes.emit(ve.VEC_MATH, "vector",
                                                         [a, b, b, b,
                                                          ve.VECTOR_OPS.index("ADD")]),
                                          "color")
                node = NodeParam(s, ctx.nodes)
            continue
        v = np.asarray(p, np.float64) * w
        const = v if const is None else const + v
    if node is None:
        return _plain(const) if const is not None else None
    return node.scaled(1.0, add=const if const is not None else 0.0)


# --------------------------------------------------------------------------- closures
@dataclass
class _Comp:
    """One BSDF closure as Principled parameters (Params; see the module docstring)."""
    base: object = (0.8, 0.8, 0.8)
    metallic: object = 0.0
    transmission: float = 0.0
    roughness: object = 0.5
    ior: float = 1.5
    spec: float = 0.5
    metal_color: object = None      # None: the base colour (Principled)
    glass_color: object = None      # None: sqrt(base colour) per crossing (Principled)
    distribution: str = "MULTI_GGX"  # 'MULTI_GGX' or 'GGX' (engine glossy_model)

    def glossy_weight(self):
        """Mean weight of the lobes the distribution shapes (metal, glass, specular)."""
        m, g, b = self.weights()
        return m + g + (b if self.spec > 0 else 0.0)

    def weights(self):
        """Mean lobe weights (metal, glass, dielectric base) of this closure."""
        m = float(np.clip(_mean(self.metallic), 0.0, 1.0))
        t = float(np.clip(self.transmission, 0.0, 1.0))
        return m, (1.0 - m) * t, (1.0 - m) * (1.0 - t)


NULL_COMP = _Comp(base=BLACK, spec=0.0)     # absorbs: an Emission shader's "no BSDF"


@dataclass
class _Closure:
    comps: list = field(default_factory=list)      # [(weight, _Comp)]
    t_weight: float = 0.0                            # transparent closure weight
    t_color: tuple = BLACK                           # sum of weight x transparent colour
    emission: object = BLACK                         # expected emitted radiance (Param)
    alpha_texture: object = None                     # a lone Principled's textured Alpha

    def scaled(self, f, ctx):
        if self.alpha_texture is not None and f != 1.0:
            ctx.issue("a textured Alpha inside a Mix/Add Shader is replaced by its average")
            c = self._alpha_to_constant()
            return c.scaled(f, ctx)
        return _Closure([(w * f, c) for w, c in self.comps], self.t_weight * f,
                        _plain(np.asarray(self.t_color) * f), _scale(self.emission, f),
                        self.alpha_texture)

    def _alpha_to_constant(self):
        a = float(np.clip(self.alpha_texture.mean(), 0.0, 1.0))
        return _Closure([(w * a, c) for w, c in self.comps], self.t_weight + (1.0 - a),
                        _plain(np.asarray(self.t_color) + (1.0 - a)), self.emission)

    def is_emission_only(self):
        return (all(c is NULL_COMP for _, c in self.comps) and self.t_weight == 0
                and bool(self.comps))


def _sum(a: _Closure, b: _Closure, ctx) -> _Closure:
    for c in (a, b):
        if c.alpha_texture is not None:
            ctx.issue("a textured Alpha inside a Mix/Add Shader is replaced by its average")
    a = a._alpha_to_constant() if a.alpha_texture is not None else a
    b = b._alpha_to_constant() if b.alpha_texture is not None else b
    return _Closure(a.comps + b.comps, a.t_weight + b.t_weight,
                    _plain(np.asarray(a.t_color) + np.asarray(b.t_color)),
                    _lin([(1.0, a.emission), (1.0, b.emission)], ctx, "emission"))


class _Ctx:
    """Per-material state: the material, what could not be represented (reported once
    per material) and the export's image cache."""

    def __init__(self, mat, reporter):
        self.mat = mat
        self.name = mat.name
        self.issues = []
        self.cache = _image_caches.setdefault(reporter, {}) if reporter is not None else {}
        self.nodes = NodeCompiler(self)

    def issue(self, text):
        if text not in self.issues:
            self.issues.append(text)

    def viewport_comp(self):
        m = self.mat
        return _Comp(base=tuple(m.diffuse_color[:3]), metallic=float(m.metallic),
                     roughness=float(m.roughness), spec=0.5)


# --------------------------------------------------------------------------- inputs
def _default(sock, color):
    v = sock.default_value
    if color:
        return tuple(float(x) for x in tuple(v)[:3])
    try:
        return float(v)
    except TypeError:
        return float(tuple(v)[0])


def _input(node, name, ctx, color, default, texturable=True):
    """The value of input `name` of `node`: its own value when unlinked; else the node
    graph linked to it, compiled into the material's program (engine.nodes): a constant
    when the graph does not depend on the hit (folded now), otherwise a NodeParam that
    the program evaluates at every hit (texturable inputs), or its average (reported)."""
    sock = node.inputs.get(name)
    if sock is None:
        return default
    if _link(sock) is None:
        return _default(sock, color)
    value = ctx.nodes.socket(sock, "color" if color else "float")
    folded = ctx.nodes.fold(value)
    if folded is not None:
        return folded
    param = NodeParam(value, ctx.nodes)
    if not texturable:
        ctx.issue(f"the input '{name}' of {node.name!r} varies per hit, which DRT does not "
                  f"render there; using its average")
        return param.mean()
    return param


def _constant(node, name, ctx, default, color=False):
    return _input(node, name, ctx, color, default, texturable=False)


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
                 distribution=_distribution(node, ctx))
    ignored = []
    for sock, what in (("Coat Weight", "coat"), ("Sheen Weight", "sheen"),
                       ("Subsurface Weight", "subsurface"), ("Anisotropic", "anisotropy"),
                       ("Thin Film Thickness", "thin film"),
                       ("Diffuse Roughness", "diffuse roughness")):
        s = node.inputs.get(sock)
        if s is not None and (s.is_linked or float(s.default_value) > 0.0):
            ignored.append(what)
    s = node.inputs.get("Specular Tint")
    if s is not None and (s.is_linked or any(abs(x - 1.0) > TOL for x in s.default_value[:3])):
        ignored.append("specular tint")
    for sock in ("Normal", "Tangent"):
        s = node.inputs.get(sock)
        if s is not None and s.is_linked:
            ignored.append(f"the {sock.lower()} input")
    if ignored:
        ctx.issue(f"{node.name!r} uses {', '.join(ignored)}, which DRT does not render "
                  f"(left out)")
    color = val("Emission Color", (1.0, 1.0, 1.0), True)
    strength = const("Emission Strength", 0.0)
    emission = _scale(color, strength)
    alpha = val("Alpha", 1.0)
    if _is_tex(alpha):
        return _Closure([(1.0, comp)], 0.0, BLACK, emission, alpha_texture=alpha)
    a = float(np.clip(alpha, 0.0, 1.0))
    # Cycles: BSDF weight a, transparent 1 - a, emission times a
    return _Closure([(a, comp)], 1.0 - a, (1.0 - a,) * 3, _scale(emission, a))


def _diffuse(node, ctx) -> _Closure:
    r = _constant(node, "Roughness", ctx, 0.0)
    if r > 0.0:
        ctx.issue(f"{node.name!r} has roughness {r:g} (Oren-Nayar); DRT renders it Lambertian")
    return _Closure([(1.0, _Comp(base=_input(node, "Color", ctx, True, (0.8,) * 3),
                                 spec=0.0))])


def _distribution(node, ctx) -> str:
    """The engine glossy_model of a node's microfacet distribution."""
    d = getattr(node, "distribution", "MULTI_GGX")
    if d in ("MULTI_GGX", "GGX"):
        return d
    ctx.issue(f"{node.name!r} uses the {d} distribution; DRT uses GGX")
    return "GGX"


def _glossy(node, ctx) -> _Closure:
    distribution = _distribution(node, ctx)
    s = node.inputs.get("Anisotropy")
    if s is not None and (s.is_linked or float(s.default_value) != 0.0):
        ctx.issue(f"{node.name!r} is anisotropic; DRT renders it isotropic")
    color = _input(node, "Color", ctx, True, (0.8,) * 3)
    return _Closure([(1.0, _Comp(base=color, metallic=1.0,
                                 roughness=_input(node, "Roughness", ctx, False, 0.5),
                                 distribution=distribution))])


def _glass(node, ctx, refraction=False) -> _Closure:
    if refraction:
        ctx.issue(f"{node.name!r} (Refraction BSDF) is rendered as glass, which also "
                  f"reflects")
    distribution = _distribution(node, ctx)
    color = _input(node, "Color", ctx, True, WHITE)
    if _is_tex(color):
        ctx.issue(f"the colour of {node.name!r} is textured; DRT tints its refraction "
                  f"with the texture's average")
        color = color.mean()
    s = node.inputs.get("Thin Film Thickness")
    if s is not None and (s.is_linked or float(s.default_value) > 0.0):
        ctx.issue(f"{node.name!r} uses thin film, which DRT does not render (left out)")
    comp = _Comp(base=color, transmission=1.0,
                 roughness=_input(node, "Roughness", ctx, False, 0.0),
                 ior=_constant(node, "IOR", ctx, 1.5), glass_color=color,
                 distribution=distribution)
    return _Closure([(1.0, comp)])


def _emission(node, ctx) -> _Closure:
    color = _input(node, "Color", ctx, True, WHITE)
    strength = _constant(node, "Strength", ctx, 1.0)
    return _Closure([(1.0, NULL_COMP)], emission=_scale(color, strength))


def _transparent(node, ctx) -> _Closure:
    color = _constant(node, "Color", ctx, WHITE, color=True)
    return _Closure([], 1.0, color)


def _fresnel_average(ior):
    """Hemispherical average of Fresnel reflectance, 2 int_0^1 F(mu) mu dmu."""
    mu = (np.arange(1024) + 0.5) / 1024
    return float(2.0 * np.mean(fresnel.dielectric(mu, max(float(ior), 1e-5)) * mu))


def _mix_factor(node, ctx):
    """(constant factor, Fresnel IOR or None) of a Mix Shader's Fac."""
    sock = node.inputs[0]
    found = _link(sock)
    if found is None:
        return float(np.clip(sock.default_value, 0.0, 1.0)), None
    src, out = found
    if src.bl_idname == "ShaderNodeFresnel":
        ior = _constant(src, "IOR", ctx, 1.5)
        return _fresnel_average(ior), ior
    if src.bl_idname == "ShaderNodeLayerWeight":
        blend = float(np.clip(_constant(src, "Blend", ctx, 0.5), 0.0, 1.0 - 1e-5))
        if out.identifier == "Fresnel":
            ior = 1.0 / max(1.0 - blend, 1e-5)
            return _fresnel_average(ior), ior
        # Facing: 1 - |cos|^b with Cycles' remapping of Blend; cosine-weighted average
        b = 2.0 * blend if blend < 0.5 else 0.5 / (1.0 - blend)
        ctx.issue(f"the Fac of {node.name!r} is Layer Weight's Facing, which depends on the "
                  f"view angle; DRT uses its hemispherical average")
        return 1.0 - 2.0 / (b + 2.0), None
    value = ctx.nodes.socket(sock, "float")
    folded = ctx.nodes.fold(value)
    if folded is not None:
        return float(np.clip(folded, 0.0, 1.0)), None
    mean = float(np.clip(ctx.nodes.mean(value), 0.0, 1.0))
    ctx.issue(f"the Fac of {node.name!r} varies per hit ({src.bl_label!r}); DRT mixes the "
              f"shaders by its average {mean:.3f}")
    return mean, None


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
                    _lin([(1.0 - fac, a.emission), (fac, b.emission)], ctx, "emission"))


def _closure(socket, ctx, depth=0) -> _Closure:
    """The closure feeding a shader socket."""
    found = _link(socket)
    if found is None:
        return _Closure([(1.0, NULL_COMP)])       # no closure: black
    node = found[0]
    if depth > 32:
        ctx.issue("the shader tree is too deep; rendering the rest as the viewport colour")
        return _Closure([(1.0, ctx.viewport_comp())])
    kind = node.bl_idname
    if kind == "ShaderNodeBsdfPrincipled":
        return _principled(node, ctx)
    if kind == "ShaderNodeBsdfDiffuse":
        return _diffuse(node, ctx)
    if kind == "ShaderNodeBsdfGlossy" or kind == "ShaderNodeBsdfAnisotropic":
        return _glossy(node, ctx)
    if kind == "ShaderNodeBsdfGlass":
        return _glass(node, ctx)
    if kind == "ShaderNodeBsdfRefraction":
        return _glass(node, ctx, refraction=True)
    if kind == "ShaderNodeEmission":
        return _emission(node, ctx)
    if kind == "ShaderNodeBsdfTransparent":
        return _transparent(node, ctx)
    if kind == "ShaderNodeMixShader":
        fac, ior = _mix_factor(node, ctx)
        a = _closure(node.inputs[1], ctx, depth + 1)
        b = _closure(node.inputs[2], ctx, depth + 1)
        if ior is not None:
            p = _plastic(a, b, ior, fac, ctx)
            if p is not None:
                ctx.issue(f"the Fresnel-driven {node.name!r} is rendered as a Principled "
                          f"specular layer of IOR {ior:.3g}")
                return p
            ctx.issue(f"the Fac of {node.name!r} depends on the view angle (Fresnel); DRT "
                      f"uses its hemispherical average {fac:.3f}")
        return _sum(a.scaled(1.0 - fac, ctx), b.scaled(fac, ctx), ctx)
    if kind == "ShaderNodeAddShader":
        a = _closure(node.inputs[0], ctx, depth + 1)
        b = _closure(node.inputs[1], ctx, depth + 1)
        if a.is_emission_only() or b.is_emission_only():
            emit, other = (a, b) if a.is_emission_only() else (b, a)
            if other.alpha_texture is not None:
                return _Closure(other.comps, other.t_weight, other.t_color,
                                _lin([(1.0, emit.emission), (1.0, other.emission)], ctx,
                                     "emission"), other.alpha_texture)
            return _Closure(other.comps, other.t_weight, other.t_color,
                            _lin([(1.0, emit.emission), (1.0, other.emission)], ctx,
                                 "emission"))
        ctx.issue(f"{node.name!r} adds two BSDFs; DRT renders their sum as one Principled "
                  f"BSDF (lobe weights and colours summed)")
        return _sum(a, b, ctx)
    ctx.issue(f"it uses the {node.bl_label!r} node, which DRT does not support yet; "
              f"rendering it as a diffuse surface of its viewport colour")
    return _Closure([(1.0, ctx.viewport_comp())])


# --------------------------------------------------------------------------- reduction
def _reduce(cl: _Closure, ctx, name) -> "engine.Material":
    """One Material from a closure set (see the module docstring)."""
    W = float(sum(w for w, _ in cl.comps))
    T = float(cl.t_weight)
    total = W + T
    if total <= 0.0:
        # Nothing but emission can come out (e.g. every weight mixed to zero).
        return engine.Material(name, BLACK, specular_ior_level=0.0,
                               emission=tuple(_mean(cl.emission)))
    alpha = W / total
    t_color = _plain(np.asarray(cl.t_color) * (total / T)) if T > 0 else WHITE
    if W <= 0.0:
        if max(_mean(cl.emission)) > 0:
            ctx.issue("emission on a fully transparent shader is not rendered")
        return engine.Material(name, BLACK, specular_ior_level=0.0, alpha=0.0,
                               transparent_color=t_color)
    comps = [(w / W, c) for w, c in cl.comps if w > 0]
    p = _blend(comps, ctx)
    if abs(total - 1.0) > 1e-9:
        # closures summed past 1 (Add Shader): the opaque part keeps its full weight
        for k in ("base", "metal_color", "glass_color"):
            if p[k] is not None:
                p[k] = _scale(p[k], total)
    emission = _scale(cl.emission, 1.0 / alpha)        # emitted by the opaque part
    alpha_tex = cl.alpha_texture
    if alpha_tex is not None:
        alpha = 1.0
    m = engine.Material(name)
    _set(m, "base_color", p["base"])
    _set(m, "metallic", p["metallic"])
    _set(m, "roughness", p["roughness"])
    _set(m, "emission", emission)
    m.ior = float(p["ior"])
    m.transmission = float(p["transmission"])
    m.glossy_model = p["distribution"]
    m.specular_ior_level = float(p["spec"])
    if p["metal_color"] is not None:
        mc = p["metal_color"]
        if _is_tex(mc):
            ctx.issue("the metal colour is textured and differs from the base colour; "
                      "DRT uses its average")
            mc = mc.mean()
        m.metal_color = tuple(mc)
    if p["glass_color"] is not None:
        m.glass_color = tuple(_mean(p["glass_color"]))
    m.alpha = float(alpha)
    m.transparent_color = tuple(t_color)
    if alpha_tex is not None:
        m.alpha_texture = alpha_tex
        m.alpha = float(np.clip(alpha_tex.mean(), 0.0, 1.0))
    return m


def _set(m, attr, value):
    if _is_tex(value):
        value.nodes.b.output(attr, value.value)
        mean = value.mean()
        setattr(m, attr, tuple(mean) if isinstance(mean, tuple) else float(mean))
    else:
        setattr(m, attr, tuple(value) if isinstance(value, tuple) else float(value))


def _blend(comps, ctx) -> dict:
    """Principled parameters of a convex combination [(c_i, _Comp)] of closures."""
    if len(comps) == 1:
        c = comps[0][1]
        return dict(base=c.base, metallic=c.metallic, transmission=c.transmission,
                    roughness=c.roughness, ior=c.ior, spec=c.spec,
                    metal_color=None if c.metal_color is None or _same(c.metal_color, c.base)
                    else c.metal_color,
                    glass_color=c.glass_color, distribution=c.distribution)
    lw = [(c, comp, *comp.weights()) for c, comp in comps]
    Wm = sum(c * m for c, _, m, _, _ in lw)
    Wg = sum(c * g for c, _, _, g, _ in lw)
    Wb = sum(c * b for c, _, _, _, b in lw)
    metallic = _lin([(c, comp.metallic) for c, comp in comps], ctx, "metallic")
    transmission = Wg / (1.0 - Wm) if Wm < 1.0 - 1e-12 else 0.0
    metal_cols = [(c * m, comp.metal_color if comp.metal_color is not None else comp.base)
                  for c, comp, m, _, _ in lw]
    metal_avg = _scale(_lin(metal_cols, ctx, "metal colour"), 1.0 / Wm) if Wm > 0 else None
    if Wb > 0:
        base = _scale(_lin([(c * b, comp.base) for c, comp, _, _, b in lw], ctx, "base colour"),
                      1.0 / Wb)
    elif Wm > 0:
        base = metal_avg
    else:
        base = _scale(_lin([(c * g, comp.base) for c, comp, _, g, _ in lw], ctx,
                           "base colour"), 1.0 / max(Wg, 1e-300))
    metal_color = None
    if Wm > 0 and not _same(metal_avg, base):
        metal_color = metal_avg
    glass_color = None
    if Wg > 0:
        principled = all(comp.glass_color is None and _same(comp.base, base)
                         for _, comp, _, g, _ in lw if g > 0)
        if not principled:
            tints = [(c * g, np.asarray(comp.glass_color) if comp.glass_color is not None
                      else np.sqrt(np.clip(np.asarray(_mean(comp.base)), 0.0, 1.0)))
                     for c, comp, _, g, _ in lw if g > 0]
            glass_color = _plain(sum(w * t for w, t in tints) / Wg)
    # the dielectric base lobe's specular layer: level weighted by the base lobes
    spec = (sum(c * b * comp.spec for c, comp, _, _, b in lw) / Wb) if Wb > 0 else 0.5
    # roughness and IOR: weighted by the lobes that use them
    rough_w = [(c * (m + g + (b if comp.spec > 0 else 0.0)), comp) for c, comp, m, g, b in lw]
    total_r = sum(w for w, _ in rough_w)
    if total_r > 0:
        roughness = _scale(_lin([(w, comp.roughness) for w, comp in rough_w], ctx,
                                "roughness"), 1.0 / total_r)
    else:
        roughness = 0.5
    ior_w = [(c * (g + (b if comp.spec > 0 else 0.0)), comp.ior) for c, comp, m, g, b in lw]
    total_i = sum(w for w, _ in ior_w)
    iors = {round(i, 6) for w, i in ior_w if w > 0}
    if len(iors) > 1:
        ctx.issue("closures with different IORs are mixed; DRT uses their weighted mean")
    ior = sum(w * i for w, i in ior_w) / total_i if total_i > 0 else 1.5
    if Wb > 0 and Wm > 0 and not _same(metal_avg, base):
        pass   # exact: the metal lobe keeps its own colour (Material.metal_color)
    # the microfacet distribution: the one of the closure with the most glossy weight
    glossy = [(c * comp.glossy_weight(), comp.distribution) for c, comp in comps]
    distribution = max(glossy, key=lambda x: x[0])[1]
    if len({d for w, d in glossy if w > 0}) > 1:
        ctx.issue(f"closures with different microfacet distributions are mixed; DRT uses "
                  f"{distribution} for all")
    return dict(base=base, metallic=metallic, transmission=float(np.clip(transmission, 0, 1)),
                roughness=roughness, ior=ior, spec=spec, metal_color=metal_color,
                glass_color=glass_color, distribution=distribution)


# --------------------------------------------------------------------------- entry points
def _all_nodes(tree, seen=None):
    """The nodes of a tree and of the node groups in it (each group once)."""
    seen = set() if seen is None else seen
    for n in tree.nodes:
        yield n
        sub = getattr(n, "node_tree", None) if n.bl_idname == "ShaderNodeGroup" else None
        if sub is not None and sub.name_full not in seen:
            seen.add(sub.name_full)
            yield from _all_nodes(sub, seen)


UV_READERS = {"ShaderNodeTexImage", "ShaderNodeUVMap", "ShaderNodeTexCoord"}


def material_uv_maps(mat) -> Optional[set]:
    """The UV maps a material's nodes may read ('' = the mesh's default map), or None
    when no node reads UVs (its meshes then need no UVs)."""
    if mat is None or not uses_nodes(mat):
        return None
    nodes = list(_all_nodes(mat.node_tree))
    if not any(n.bl_idname in UV_READERS for n in nodes):
        return None
    names = {n.uv_map for n in nodes if n.bl_idname == "ShaderNodeUVMap" and n.uv_map}
    return names or {""}


def export_material(mat, reporter: Reporter) -> "engine.Material":
    """`mat` (None: an empty slot) as an engine Material, with Cycles' meaning; what is
    approximated is reported once, in one warning naming the material."""
    if mat is None:
        return engine.Material("none")
    name = mat.name
    ctx = _Ctx(mat, reporter)
    fallback = engine.Material(name, tuple(mat.diffuse_color[:3]), metallic=float(mat.metallic),
                               roughness=float(mat.roughness), specular_ior_level=0.5,
                               glossy_model="MULTI_GGX")
    if not uses_nodes(mat):
        return fallback
    out = _output_node(mat.node_tree)
    if out is None:
        ctx.issue("it has no Material Output node; using its viewport colour")
        result = fallback
    else:
        vol = out.inputs.get("Volume")
        if vol is not None and _link(vol) is not None:
            ctx.issue("its volume shader is not rendered")
        disp = out.inputs.get("Displacement")
        if disp is not None and _link(disp) is not None:
            ctx.issue("its displacement is not rendered")
        result = _reduce(_closure(out.inputs["Surface"], ctx), ctx, name)
        if ctx.nodes.b.outputs:
            result.shader = ctx.nodes.build()
    if ctx.issues and reporter is not None:
        reporter.warn(f"DRT: material {name!r}: " + "; ".join(ctx.issues),
                      key=(name, "material"))
    return result
