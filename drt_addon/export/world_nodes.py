"""A world whose Background Color (or Strength) comes from a node graph DRT has no direct
model for (gradients, noise, colour ramps, mixes of textures), or whose Surface is a Mix
or Add Shader of Backgrounds and Emissions (`shader_radiance`): the graph is compiled into
a shader program, as a material's is (export/nodes), and evaluated once per texel of an
equirectangular map along that texel's direction, which becomes the world's environment
map, seen by escaped rays and importance-sampled as a light like an HDRI.

The world's shading context is Cycles' for a background: the position, the Generated and
Object coordinates are the ray's direction, the normal faces back along it. The map has
World > Settings > Sampling > Map Resolution texels across (Cycles' own for sampling the
world; 1024 by default) and half as many down, linearly interpolated. A graph with a
Light Path node is evaluated twice: as for camera rays, into the map the camera sees,
and as for diffuse rays, into the map that lights the scene (a common set-up: a plain
colour for the camera, an image for the light; engine.scene.World.camera_texture). Other
rays see the lighting map: a graph that tells glossy, transmission or shadow rays apart
from diffuse ones is reported. What differs is detail finer than a texel.
"""
from __future__ import annotations

import importlib

import numpy as np

from ..engine_link import engine
from .nodes import NodeCompiler
from .nodes.errors import Unsupported
from .nodes.links import _link

CTX = importlib.import_module(engine.__name__ + ".nodes.context")
CO = importlib.import_module(engine.__name__ + ".nodes.color_nodes")
CV = importlib.import_module(engine.__name__ + ".nodes.converter_nodes")
LIGHTS = ("ShaderNodeBackground", "ShaderNodeEmission")
TEXTURES = importlib.import_module(engine.__name__ + ".textures")
ENV = importlib.import_module(engine.__name__ + ".environment_map")
CHUNK = 1 << 15          # directions evaluated at once (the hit rows are ~1 KB each)


def _map_resolution(world) -> int:
    settings = getattr(world, "cycles", None)
    res = int(getattr(settings, "sample_map_resolution", 1024) or 1024)
    return int(np.clip(res, 64, 4096))


def _light_path_outputs(tree) -> set:
    """The linked outputs of the graph's Light Path nodes."""
    return {o.name for n in tree.nodes if n.bl_idname == "ShaderNodeLightPath"
            for o in n.outputs if o.is_linked}


def shader_radiance(c, sock, ctx):
    """The compiled radiance (a colour) of the world shader linked into input `sock`:
    a Background's or an Emission's Color x Strength, a Mix Shader's blend of its two
    by its Fac (clamped, as Cycles weighs closures), an Add Shader's sum, and a colour
    or value linked straight in (Cycles' conversion to an Emission of strength 1).
    Other shaders give a world no light (reported)."""
    found = _link(sock)
    if found is None:
        return c.const((0.0, 0.0, 0.0), "color")
    node, out = found
    if out.type != "SHADER":
        return c.socket(sock, "color")
    kind = node.bl_idname
    if kind in LIGHTS:
        return c.emit(CO.COL_MIX, "color", [c.const(1.0), c.socket(node.inputs["Color"],
                                                                   "color"),
                                            c.socket(node.inputs["Strength"], "color"),
                                            CO.BLEND_MODES.index("MULTIPLY"), 0])
    if kind == "ShaderNodeMixShader":
        fac = c.emit(CV.CV_CLAMP, "float", [c.socket(node.inputs[0], "float"),
                                            c.const(0.0), c.const(1.0), 0])
        return c.emit(CO.COL_MIX, "color", [fac, shader_radiance(c, node.inputs[1], ctx),
                                            shader_radiance(c, node.inputs[2], ctx),
                                            CO.BLEND_MODES.index("MIX"), 0])
    if kind == "ShaderNodeAddShader":
        return c.emit(CO.COL_MIX, "color", [c.const(1.0),
                                            shader_radiance(c, node.inputs[0], ctx),
                                            shader_radiance(c, node.inputs[1], ctx),
                                            CO.BLEND_MODES.index("ADD"), 0])
    ctx.issue(f"its {node.bl_label!r} node is no world shader and gives no light")
    return c.const((0.0, 0.0, 0.0), "color")


def bake_background(world, background, visibility, ctx):
    """engine.World whose environment map is the Background node's Color x Strength
    evaluated along every texel's direction (`background` may also be the World Output's
    Surface input, whose graph of shaders shader_radiance compiles); None when the graph
    cannot be compiled (reported; the caller uses the Background's own colour)."""
    c = NodeCompiler(ctx)
    try:
        if getattr(background, "bl_idname", "") in LIGHTS:
            color = c.socket(background.inputs["Color"], "color")
            strength = c.socket(background.inputs["Strength"], "float")
        else:
            color, strength = shader_radiance(c, background, ctx), c.const(1.0)
    except Unsupported as e:
        ctx.issue(f"its Background's graph is not evaluated ({e}); using the Background's "
                  "own colour")
        return None
    outputs = _light_path_outputs(world.node_tree)
    if outputs - {"Is Camera Ray"}:
        ctx.issue("its Light Path node is read as for a diffuse ray wherever the world "
                  "lights the scene (" + ", ".join(sorted(outputs - {"Is Camera Ray"}))
                  + " are not told apart)")
    program = c.build()
    vis = engine.visibility
    light = _bake(program, color, strength, _map_resolution(world), vis.DIFFUSE if outputs
                  else vis.CAMERA)
    camera = _bake(program, color, strength, _map_resolution(world), vis.CAMERA) \
        if outputs else None
    tex = _texture(light, f"{world.name} (nodes)")
    mean = tuple(float(x) for x in light.reshape(-1, 3).mean(axis=0))
    return engine.World(mean, texture=tex, visibility=visibility,
                        camera_texture=(None if camera is None or np.array_equal(camera, light)
                                        else _texture(camera, f"{world.name} (camera)")))


def _texture(rgb, name):
    h, w, _ = rgb.shape
    pixels = np.ones((h, w, 4), np.float32)
    pixels[:, :, :3] = rgb
    return TEXTURES.Texture(pixels, "Linear", "REPEAT", name=name)


def _bake(program, color, strength, w, ray) -> np.ndarray:
    """Color x Strength along every texel's direction of a w x w/2 map, for rays of kind
    `ray`: (h, w, 3)."""
    h = w // 2
    u, v = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    d, _ = ENV.uv_to_direction(np.stack([u.ravel(), v.ravel()], axis=1))
    rgb = np.empty((len(d), 3))
    for start in range(0, len(d), CHUNK):
        dd = d[start:start + CHUNK]
        hits = CTX.hit_rows(dd, -dd, direction=dd, ray=ray)
        for col in (CTX.H_GENERATED, CTX.H_OBJECT):
            hits[:, col:col + 3] = dd
        values = program.evaluate(color, hits).reshape(-1, 3)
        scale = program.evaluate(strength, hits).reshape(-1, 1)
        rgb[start:start + CHUNK] = values * scale
    return rgb.reshape(h, w, 3)
