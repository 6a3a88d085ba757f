"""Texture nodes to program operations (engine.nodes.texture_nodes): Image, Environment,
Checker, Gradient. An unlinked Vector reads the node's default coordinates, as in Cycles:
the UV map for Image, Generated for the procedural textures, the position for
Environment (in a world, the ray's direction)."""
from __future__ import annotations

import importlib
import math

from ...engine_link import engine
from ..images import image_texture, read_pixels
from .errors import Unsupported
from .input import hit3

X = importlib.import_module(engine.__name__ + ".nodes.texture_nodes")
CV = importlib.import_module(engine.__name__ + ".nodes.converter_nodes")
C = importlib.import_module(engine.__name__ + ".nodes.context")
textures = importlib.import_module(engine.__name__ + ".textures")

MISSING = tuple(textures.MISSING_RGBA[:3])


def coordinates(c, node, default_field):
    sock = node.inputs.get("Vector")
    if sock is not None and sock.is_linked:
        return c.socket(sock, "vector")
    return hit3(c, default_field)


def _image(c, node, out):
    alpha_out = out.identifier == "Alpha"
    if node.projection != "FLAT":
        c.ctx.issue(f"{node.name!r} uses {node.projection} projection; DRT reads it as FLAT")
    if node.interpolation not in ("Linear", "Closest"):
        c.ctx.issue(f"{node.name!r} uses {node.interpolation} interpolation; DRT uses Linear")
    image = node.image
    alpha_linked = any(o.is_linked for o in node.outputs if o.identifier == "Alpha")
    if image is None:                     # no image: Cycles' colour, unfiltered
        return c.const(1.0) if alpha_out else c.const(MISSING, "color")
    tex = image_texture(image, node.interpolation, node.extension, c.ctx,
                        premultiply=not alpha_linked)
    if alpha_linked and not alpha_out and read_pixels(image, c.ctx) is None:
        # Cycles divides the colour of an image whose Alpha is used by its alpha
        # (svm/image.h, NODE_IMAGE_ALPHA_UNASSOCIATE): a missing image's clipped tent
        # of pink over the same tent of alpha is pink again. (Where the tent is 0,
        # half a texel and more outside the UV square, Cycles' colour is 0; DRT's pink.)
        return c.const(MISSING, "color")
    uv = coordinates(c, node, C.H_UV)
    op = X.TEX_IMAGE_ALPHA if alpha_out else X.TEX_IMAGE_COLOR
    return c.emit(op, "float" if alpha_out else "color", [uv], varying=True, image=tex)


def _math(c, op, a, b=None, d=None):
    zero = c.const(0.0)
    return c.emit(CV.CV_MATH, "float", [a, zero if b is None else b,
                                        zero if d is None else d, CV.MATH_OPS.index(op), 0])


def _environment(c, node, out):
    """An Environment Texture read by direction (Cycles' direction_to_equirectangular:
    u = 1/2 - atan2(y, x) / 2 pi, v = 1 - acos(z / |d|) / pi), as a world's node graph
    uses it; a plain one straight into a Background is the world's own map
    (export/world.py)."""
    if node.projection != "EQUIRECTANGULAR":
        raise Unsupported(f"the {node.projection} projection of {node.name!r}")
    alpha_out = out.identifier == "Alpha"
    if node.image is None or read_pixels(node.image, c.ctx) is None:
        return c.const(1.0) if alpha_out else c.const(MISSING, "color")
    if node.interpolation not in ("Linear", "Closest"):
        c.ctx.issue(f"{node.name!r} uses {node.interpolation} interpolation; DRT uses Linear")
    tex = image_texture(node.image, node.interpolation, "REPEAT", c.ctx,
                        premultiply=not any(o.is_linked for o in node.outputs
                                            if o.identifier == "Alpha"))
    d = coordinates(c, node, C.H_P)           # Cycles' default: the position (a world's:
    x, y, z = (c.emit(CV.CV_SEPARATE, "float", [d, k]) for k in range(3))   # the direction)
    length = _math(c, "SQRT", _math(c, "MULTIPLY_ADD", x, x,
                                    _math(c, "MULTIPLY_ADD", y, y, _math(c, "MULTIPLY", z, z))))
    u = _math(c, "MULTIPLY_ADD", _math(c, "ARCTAN2", y, x), c.const(-0.5 / math.pi),
              c.const(0.5))
    v = _math(c, "MULTIPLY_ADD", _math(c, "ARCCOSINE", _math(c, "DIVIDE", z, length)),
              c.const(-1.0 / math.pi), c.const(1.0))
    uv = c.emit(CV.CV_COMBINE, "vector", [u, v, c.const(0.0)])
    op = X.TEX_IMAGE_ALPHA if alpha_out else X.TEX_IMAGE_COLOR
    return c.emit(op, "float" if alpha_out else "color", [uv], varying=True, image=tex)


def _checker(c, node, out):
    co = coordinates(c, node, C.H_GENERATED)
    scale = c.input(node, "Scale", "float")
    if out.identifier == "Fac":
        return c.emit(X.TEX_CHECKER_FAC, "float", [co, scale])
    return c.emit(X.TEX_CHECKER_COLOR, "color",
                  [co, c.input(node, "Color1", "color"), c.input(node, "Color2", "color"),
                   scale])


def _gradient(c, node, out):
    if node.gradient_type not in X.GRADIENT_TYPES:
        raise Unsupported(f"gradient type {node.gradient_type}")
    co = coordinates(c, node, C.H_GENERATED)
    fac = c.emit(X.TEX_GRADIENT, "float", [co, X.GRADIENT_TYPES.index(node.gradient_type)])
    return fac if out.identifier == "Fac" else c.convert(fac, "color")


TRANSLATORS = {
    "ShaderNodeTexImage": _image,
    "ShaderNodeTexEnvironment": _environment,
    "ShaderNodeTexChecker": _checker,
    "ShaderNodeTexGradient": _gradient,
}
