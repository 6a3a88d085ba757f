"""A world whose Background Color (or Strength) comes from a node graph DRT has no direct
model for (gradients, noise, colour ramps, mixes of textures): the graph is compiled into
a shader program, as a material's is (export/nodes), and evaluated once per texel of an
equirectangular map along that texel's direction, which becomes the world's environment
map, seen by escaped rays and importance-sampled as a light like an HDRI.

The world's shading context is Cycles' for a background: the position, the Generated and
Object coordinates are the ray's direction, the normal faces back along it. The map has
World > Settings > Sampling > Map Resolution texels across (Cycles' own for sampling the
world; 1024 by default) and half as many down, linearly interpolated. A Light Path node
in the graph is read as for camera rays (the world one sees); where the graph gives other
rays another world (a common set-up: a plain colour for the camera, an image for the
light) the lighting follows the camera's world, which is reported. What differs is
detail finer than a texel.
"""
from __future__ import annotations

import importlib

import numpy as np

from ..engine_link import engine
from .nodes import NodeCompiler
from .nodes.errors import Unsupported

CTX = importlib.import_module(engine.__name__ + ".nodes.context")
TEXTURES = importlib.import_module(engine.__name__ + ".textures")
ENV = importlib.import_module(engine.__name__ + ".environment_map")
CHUNK = 1 << 15          # directions evaluated at once (the hit rows are ~1 KB each)


def _map_resolution(world) -> int:
    settings = getattr(world, "cycles", None)
    res = int(getattr(settings, "sample_map_resolution", 1024) or 1024)
    return int(np.clip(res, 64, 4096))


def _uses_light_path(tree) -> bool:
    return any(n.bl_idname == "ShaderNodeLightPath" and any(o.is_linked for o in n.outputs)
               for n in tree.nodes)


def bake_background(world, background, visibility, ctx):
    """engine.World whose environment map is the Background node's Color x Strength
    evaluated along every texel's direction; None when the graph cannot be compiled
    (reported; the caller uses the Background's own colour)."""
    c = NodeCompiler(ctx)
    try:
        color = c.socket(background.inputs["Color"], "color")
        strength = c.socket(background.inputs["Strength"], "float")
    except Unsupported as e:
        ctx.issue(f"its Background's graph is not evaluated ({e}); using the Background's "
                  "own colour")
        return None
    if _uses_light_path(world.node_tree):
        ctx.issue("its Light Path node is read as for camera rays: the world lights the "
                  "scene as the camera sees it")
    program = c.build()
    w = _map_resolution(world)
    h = w // 2
    u, v = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    d, _ = ENV.uv_to_direction(np.stack([u.ravel(), v.ravel()], axis=1))
    rgb = np.empty((len(d), 3))
    for start in range(0, len(d), CHUNK):
        dd = d[start:start + CHUNK]
        hits = CTX.hit_rows(dd, -dd, direction=dd, ray=engine.visibility.CAMERA)
        for col in (CTX.H_GENERATED, CTX.H_OBJECT):
            hits[:, col:col + 3] = dd
        values = program.evaluate(color, hits).reshape(-1, 3)
        scale = program.evaluate(strength, hits).reshape(-1, 1)
        rgb[start:start + CHUNK] = values * scale
    pixels = np.ones((h, w, 4), np.float32)
    pixels[:, :, :3] = rgb.reshape(h, w, 3)
    tex = TEXTURES.Texture(pixels, "Linear", "REPEAT", name=f"{world.name} (nodes)")
    mean = tuple(float(x) for x in rgb.mean(axis=0))
    return engine.World(mean, texture=tex, visibility=visibility)
