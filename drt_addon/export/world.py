"""The world's background: uniform radiance (colour x strength), or an environment map.

Read from the active World Output's Surface socket, which must come from a Background
shader (anything else: a black background, reported):
- Color unlinked: uniform radiance colour x strength (`engine.World.color`).
- Color from an Environment Texture node (its Color output) with an image, equirectangular
  projection: `engine.World.texture`, the image read once per export (pixels and colour
  space as for material textures, `images.image_texture`: 8-bit sRGB decoded after
  interpolation as Cycles does, float images such as .hdr / .exr and Non-Color data as
  they are), REPEAT extension (Cycles' Environment Texture wraps both ways),
  Linear or Closest interpolation (Cubic and Smart are read as Linear, reported), times
  the Strength. No image: Cycles' missing-image pink. Mirror-ball projection is not
  modelled: reported, and the unconnected colour is used.
- The texture's Vector: unlinked, or a Texture Coordinate node's Generated or Object
  output (for the world both are the ray direction), optionally through a Mapping node
  whose Location, Rotation and Scale are constants: the Mapping becomes the 3x3 matrix
  `engine.World.mapping` (Blender's Point and Vector types R diag(S), Texture
  diag(1/S) R^T, Normal R diag(1/S); R the XYZ Euler rotation). A translation is ignored
  (the lookup direction is normalised and Cycles adds it before: reported), as is a
  singular scale (reported). Any other vector source is reported and ignored.
- Color from a Sky Texture node: its sky as an environment map and its sun disc as a
  distant light (`world_sky`), through the node's Vector as above.
- Anything else linked to Color, or a linked Strength: the graph is evaluated along
  every texel's direction of an equirectangular map, which becomes the environment map
  (world_nodes.py).
World > Ray Visibility (`world.cycles_visibility`: camera, diffuse, glossy, transmission,
shadow) becomes `engine.World.visibility` (whose Shadow bit the engine ignores, as
Cycles does; see engine.world_light).
"""
from __future__ import annotations

import numpy as np

from ..engine_link import engine
from .errors import Reporter
from .images import image_cache, image_texture, read_pixels, textures
from .nodes.links import _link, uses_nodes
from .world_nodes import LIGHTS, bake_background
from .world_sampling import world_varies
from .world_sky import sky_world

BLACK = (0.0, 0.0, 0.0)
MISSING = tuple(textures.MISSING_RGBA[:3])


class _WorldCtx:
    """What `images.image_texture` needs: the export's image cache and a list of the
    approximations to report."""

    def __init__(self, world, reporter):
        self.name = world.name
        self.cache = image_cache(reporter)
        self.issues = []

    def issue(self, text):
        if text not in self.issues:
            self.issues.append(text)

    def report(self, reporter):
        for text in self.issues:
            reporter.warn(f"DRT: world {self.name!r}: {text}", key=("world", text))


def world_output(tree):
    """The tree's active World Output node (None without one)."""
    return next((n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputWorld"
                 and getattr(n, "is_active_output", True)), None)


def _visibility(world) -> int:
    v = getattr(world, "cycles_visibility", None)
    if v is None:
        return engine.visibility.ALL
    return engine.visibility.from_flags(v.camera, v.diffuse, v.glossy, v.transmission,
                                        v.shadow)


def export_world(world, reporter: Reporter) -> "engine.World":
    """The world's background, sampled as a light where Cycles samples it: a surface that
    varies over directions (world_sampling.py), and World > Settings > Sampling Method
    other than None (`world.cycles.sampling_method`)."""
    out = _export_background(world, reporter)
    settings = getattr(world, "cycles", None)
    if settings is not None and getattr(settings, "sampling_method", "AUTOMATIC") == "NONE":
        out.light_sampling = False
    if world is not None and not world_varies(
            world, world_output(world.node_tree) if uses_nodes(world) else None):
        out.light_sampling = False
    return out


def _export_background(world, reporter: Reporter) -> "engine.World":
    if world is None:
        return engine.World(BLACK)
    vis = _visibility(world)
    if not uses_nodes(world):
        return engine.World(tuple(world.color[:3]), visibility=vis)
    tree = world.node_tree
    out = world_output(tree)
    found = _link(out.inputs["Surface"]) if out is not None else None
    if found is None:
        return engine.World(BLACK, visibility=vis)
    node, socket = found
    if socket.type != "SHADER" or node.bl_idname not in LIGHTS:
        # a colour or value linked straight into Surface (Cycles puts an Emission of it
        # there: Color 1, Strength 1, fed the one linked), or shaders mixed or added (a
        # Light Path's Is Camera Ray picking one for the camera, as artists set it up)
        colour = socket.type != "SHADER"
        return _graph_world(world, found if colour else None, 1.0,
                            (1.0, 1.0, 1.0) if colour else BLACK, out.inputs["Surface"],
                            vis, reporter)
    color, strength = node.inputs["Color"], node.inputs["Strength"]
    s = float(strength.default_value)
    plain = tuple(c * s for c in color.default_value[:3])
    source = _link(color)
    if source is None and _link(strength) is None:
        return engine.World(plain, visibility=vis)
    return _graph_world(world, source if _link(strength) is None else None, s, plain, node,
                        vis, reporter)


def _graph_world(world, source, strength, plain, target, vis, reporter):
    """The world lit by a graph: an Environment or Sky Texture's own map where `source`
    (the (node, output) feeding the colour, strength unlinked) is one, times `strength`;
    otherwise `target` (a Background or Emission node, or the World Output's Surface
    input) compiled and baked into a map (world_nodes.py). `plain` where neither is
    modelled."""
    ctx = _WorldCtx(world, reporter)
    src, socket = source if source is not None else (None, None)
    direct = src is not None and (
        (src.bl_idname == "ShaderNodeTexEnvironment" and socket.identifier == "Color")
        or src.bl_idname == "ShaderNodeTexSky")
    if not direct:
        world_out = bake_background(world, target, vis, ctx)
    elif src.bl_idname == "ShaderNodeTexEnvironment":
        world_out = _environment(src, strength, vis, ctx)
    else:
        world_out = sky_world(src, strength, vis, _mapping(src, ctx), ctx)
    ctx.report(reporter)
    return world_out if world_out is not None else engine.World(plain, visibility=vis)


def _environment(node, strength, vis, ctx):
    """engine.World of an Environment Texture node times `strength` (None: not modelled,
    the caller uses the unconnected colour)."""
    if node.projection != "EQUIRECTANGULAR":
        ctx.issue(f"{node.name!r} uses {node.projection} projection, which DRT does not "
                  f"model; using the Background's own colour")
        return None
    if node.interpolation not in ("Linear", "Closest"):
        ctx.issue(f"{node.name!r} uses {node.interpolation} interpolation; DRT uses Linear")
    rgb = (strength,) * 3
    if node.image is None:
        return engine.World(tuple(c * strength for c in MISSING), visibility=vis)
    if read_pixels(node.image, ctx) is None:   # no pixels (reported): Cycles' pink
        return engine.World(tuple(c * strength for c in MISSING), visibility=vis)
    alpha_linked = any(o.is_linked for o in node.outputs if o.identifier == "Alpha")
    tex = image_texture(node.image, node.interpolation, "REPEAT", ctx,
                        premultiply=not alpha_linked)
    mapping = _mapping(node, ctx)
    mean = tuple(float(c) * strength for c in tex.mean_rgba()[:3])
    return engine.World(mean, texture=tex, strength=rgb, mapping=mapping, visibility=vis)


def _mapping(env_node, ctx):
    """The 3x3 matrix of an Environment or Sky Texture's Vector input (None =
    identity)."""
    sock = env_node.inputs.get("Vector")
    found = _link(sock) if sock is not None and sock.enabled else None
    if found is None:
        return None
    src, out = found
    matrix = None
    if src.bl_idname == "ShaderNodeMapping":
        matrix = _mapping_matrix(src, ctx)
        vec = _link(src.inputs["Vector"])
        if vec is None:
            return matrix
        src, out = vec
    if src.bl_idname == "ShaderNodeTexCoord" and out.identifier in ("Generated", "Object"):
        if out.identifier == "Object" and getattr(src, "object", None) is not None:
            ctx.issue(f"{src.name!r} takes Object coordinates of {src.object.name!r}, "
                      f"which DRT does not model; using the world's directions")
        return matrix
    ctx.issue(f"the Vector of {env_node.name!r} comes from {src.bl_label!r} "
              f"({out.name}), which DRT does not evaluate; using the world's directions")
    return matrix


def _mapping_matrix(node, ctx):
    """The Mapping node as a 3x3 matrix acting on directions (None if not usable)."""
    import mathutils
    kind = node.vector_type
    if kind not in ("POINT", "TEXTURE", "VECTOR", "NORMAL"):
        ctx.issue(f"{node.name!r} is of type {kind}; DRT ignores it")
        return None
    values = {}
    for name in ("Location", "Rotation", "Scale"):
        sock = node.inputs.get(name)
        if sock is None or not sock.enabled:
            continue
        if _link(sock) is not None:
            ctx.issue(f"the {name} of {node.name!r} is connected, which DRT does not "
                      f"evaluate; using its own value")
        values[name] = np.array(sock.default_value[:3], dtype=np.float64)
    rot = np.array(mathutils.Euler(values.get("Rotation", np.zeros(3)), "XYZ").to_matrix(),
                   dtype=np.float64)
    scale = values.get("Scale", np.ones(3))
    if kind in ("POINT", "TEXTURE") and np.any(values.get("Location", np.zeros(3)) != 0):
        ctx.issue(f"the Location of {node.name!r} moves the lookup off the world's "
                  f"directions, which DRT does not model; ignored")
    if kind in ("TEXTURE", "NORMAL") and np.any(scale == 0):
        m = None
    elif kind == "POINT" or kind == "VECTOR":
        m = rot @ np.diag(scale)
    elif kind == "TEXTURE":
        m = np.diag(1.0 / scale) @ rot.T
    else:
        m = rot @ np.diag(1.0 / scale)
    if m is None or not np.isfinite(m).all() or abs(np.linalg.det(m)) <= 1e-12 * max(
            np.abs(m).max(), 1e-300) ** 3:
        ctx.issue(f"{node.name!r} has a zero scale, which DRT does not model; ignored")
        return None
    return m
