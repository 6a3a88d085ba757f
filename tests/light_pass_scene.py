"""The comparison scene of tests/test_light_passes_vs_cycles.py and
docs/make_passes_docs.py, built in Blender with its defaults (Multiscatter GGX, Filter
Glossy 1, caustics on): a grey floor and back wall, a rough metal sphere, a glass cube,
a diffuse cube in a thin fog, an emissive panel the camera sees, an area lamp, a point
lamp and a world colour; light groups key (the area lamp), panel (the emissive panel)
and sky (the world), the point lamp in none. The glass cube rests on the floor, as an
artist leaves it (rays leaving the floor meet its coplanar bottom face, in DRT as in
Cycles); the fog box floats 5 cm above it."""
from __future__ import annotations

import glob
import math
import os
import tempfile

import numpy as np

GROUPS = ("key", "panel", "sky")


def _principled(bpy, name, **inputs):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    for key, value in inputs.items():
        bsdf.inputs[key].default_value = value
    return mat


def _one_node(bpy, name, node_type, output, **inputs):
    """A material whose one node (Emission, Principled Volume) feeds `output`."""
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    node = nodes.new(node_type)
    for key, value in inputs.items():
        node.inputs[key].default_value = value
    mat.node_tree.links.new(node.outputs[0], nodes["Material Output"].inputs[output])
    return mat


def _add(bpy, op, mat, **kw):
    getattr(bpy.ops.mesh, op)(**kw)
    obj = bpy.context.active_object
    obj.data.materials.append(mat)
    return obj


def empty_scene(bpy, size, samples, world_color):
    """Blender's empty factory scene at `size` and `samples` in both engines (Cycles: no
    denoising, no adaptive sampling, seed 1) under a world of one colour."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.seed = 1
    scene.drt.samples = samples
    scene.world = bpy.data.worlds.new("sky")
    scene.world.color = world_color
    if bpy.app.version < (5, 0, 0):
        scene.world.use_nodes = False
    return scene


def build(bpy, size=(64, 48), samples=64, fog=True):
    scene = empty_scene(bpy, size, samples, (0.05, 0.07, 0.1))
    grey = _principled(bpy, "grey", **{"Base Color": (0.6, 0.6, 0.6, 1.0)})
    _add(bpy, "primitive_plane_add", grey, size=8.0)
    wall = _add(bpy, "primitive_plane_add", grey, size=8.0, location=(0.0, 2.0, 4.0))
    wall.rotation_euler = (math.pi / 2, 0.0, 0.0)
    metal = _principled(bpy, "metal", **{"Base Color": (0.9, 0.6, 0.3, 1.0),
                                         "Metallic": 1.0, "Roughness": 0.3})
    _add(bpy, "primitive_uv_sphere_add", metal, radius=0.5, location=(-0.9, 0.5, 0.5))
    bpy.ops.object.shade_smooth()
    glass = _principled(bpy, "glass", **{"Base Color": (0.8, 0.9, 1.0, 1.0),
                                         "Transmission Weight": 1.0, "Roughness": 0.1})
    _add(bpy, "primitive_cube_add", glass, size=0.7, location=(0.3, -0.3, 0.35)).name = "Glass"
    red = _principled(bpy, "red", **{"Base Color": (0.7, 0.15, 0.1, 1.0)})
    _add(bpy, "primitive_cube_add", red, size=0.6, location=(1.2, 0.6, 0.3))
    panel_mat = _one_node(bpy, "panel", "ShaderNodeEmission", "Surface",
                          Color=(1.0, 0.8, 0.5, 1.0), Strength=3.0)
    panel = _add(bpy, "primitive_plane_add", panel_mat, size=0.8, location=(1.6, 1.9, 1.4))
    panel.rotation_euler = (math.pi / 2, 0.0, 0.0)
    panel.lightgroup = "panel"
    if fog:
        fog_mat = _one_node(bpy, "fog", "ShaderNodeVolumePrincipled", "Volume", Density=0.4)
        _add(bpy, "primitive_cube_add", fog_mat, size=0.9, location=(-1.3, -0.8, 0.5))
    area = bpy.data.objects.new("Area", bpy.data.lights.new("Area", "AREA"))
    area.data.energy, area.data.size = 150.0, 1.0
    area.location = (0.5, -1.5, 3.0)
    area.rotation_euler = (math.radians(25), 0.0, 0.0)
    area.lightgroup = "key"
    scene.collection.objects.link(area)
    point = bpy.data.objects.new("Point", bpy.data.lights.new("Point", "POINT"))
    point.data.energy = 40.0
    point.location = (-2.0, -1.0, 2.0)
    scene.collection.objects.link(point)
    scene.world.lightgroup = "sky"
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, -5.5, 2.2)
    cam.rotation_euler = (math.radians(75), 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    vl = scene.view_layers[0]
    for kind in ("diffuse", "glossy", "transmission"):
        for part in ("direct", "indirect", "color"):
            setattr(vl, f"use_pass_{kind}_{part}", True)
    vl.cycles.use_pass_volume_direct = vl.cycles.use_pass_volume_indirect = True
    vl.use_pass_emit = vl.use_pass_environment = True
    for name in GROUPS:
        vl.lightgroups.add(name=name)
    bpy.context.view_layer.update()
    return scene


def cycles_passes(bpy, scene, names, channels=3):
    """Render `scene` and read its passes `names` (Blender 5's File Output node, one
    OpenEXR per pass), as (h, w, channels) float arrays (RGB; 4: with alpha), row 0 at
    the top."""
    tree = bpy.data.node_groups.new("Comp", "CompositorNodeTree")
    layers = tree.nodes.new("CompositorNodeRLayers")
    layers.scene = scene
    out = tree.nodes.new("CompositorNodeOutputFile")
    folder = tempfile.mkdtemp()
    out.directory, out.file_name = folder + os.sep, "p_"
    fmt = out.format
    fmt.media_type, fmt.file_format, fmt.color_depth, fmt.exr_codec = (
        "IMAGE", "OPEN_EXR", "32", "NONE")
    for name in names:
        out.file_output_items.new("RGBA", name)
        tree.links.new(layers.outputs[name], out.inputs[name])
    scene.compositing_node_group = tree
    scene.render.use_compositing = True
    bpy.ops.render.render()
    images = {}
    for name in names:
        img = bpy.data.images.load(glob.glob(os.path.join(folder, f"p_{name}*.exr"))[0])
        px = np.empty(len(img.pixels), np.float32)
        img.pixels.foreach_get(px)
        images[name] = px.reshape(img.size[1], img.size[0], -1)[::-1, :, :channels].astype(
            float)
        bpy.data.images.remove(img)
    return images


def drt_passes(bpy, names):
    """Render the open scene with DRT and return its passes `names` as it wrote them, and
    Combined as "Image", (h, w, 3) float arrays, row 0 at the top."""
    from drt_addon import render_engine
    bpy.context.scene.render.engine = "DRT"
    bpy.ops.render.render()
    last = render_engine.last_render
    assert last["ok"], last["error"]
    out = {name: np.asarray(last["passes"][name], float)[..., :3] for name in names}
    out["Image"] = np.asarray(last["pixels"], float)[..., :3]
    return out
