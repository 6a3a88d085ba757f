"""Measure Cycles' microfiber sheen (the Sheen BSDF node, Principled's sheen) so that DRT's
sheen lobe (engine/kernels/bsdf/sheen.py) reproduces it: renders with bpy, then fits the
lobe's table (engine/bsdf/sheen_table.py). Run from the repository root:

    python tests/cycles_sheen_probe.py [raw.npz]

What is measured. Cycles' sheen (Zeltner et al. 2022) is a linearly transformed cosine
whose parameters (a, b) and albedo R are tabulated over (cos theta_o, roughness); its
f cos towards a light l, in a frame whose x axis is the view direction's azimuth, is
R z a^2 / (pi ((a x + b z)^2 + (a y)^2 + z^2)^2). Every pixel of a probe gives one such
value: 32 shapes (one per roughness node k / 31, k = 0..31) plus a white Lambertian one,
each a convex dome seen from straight above by an orthographic camera, whose normal tilts
uniformly with the distance from its centre (so every view angle down to cos 0.005 covers
many pixels), lit by a sun (angle 0, strength 1) from five directions in turn, direct
light only (max bounces 0), shadows off and a 0.01 pixel filter: each pixel is then one
noise-free evaluation at its centre. A sixth render shows the shading normals (an
emission override), from which the frame and the light's local direction follow.

The rendering needs bpy (Blender's Cycles); the fit (sheen_table.fit_from_probe) only
NumPy and SciPy. Measured numbers are in sheen_table's docstring.
"""
from __future__ import annotations

import math
import os
import sys
import tempfile

import numpy as np

NODES = 32                      # Cycles' table: 32 x 32 over (cos theta_o, roughness)
COLS, ROWS = 11, 3              # 33 domes: the 32 roughness nodes and a Lambertian one
PX = 96                         # pixels per dome diameter
MU_MIN = 0.005                  # the dome's rim: cos of the steepest normal
SUN_ANGLES = (0.0, 35.0, 70.0, 105.0, 140.0)   # degrees from the view axis, in x-z
RINGS, SEGMENTS = 96, 192


def dome_mesh(bpy, name):
    """A dome of radius 0.5 whose normal's polar angle grows linearly with the radius,
    to 89.7 degrees at the rim, with exact custom normals."""
    theta_max = math.acos(MU_MIN)
    radius = 0.5
    verts, normals, faces = [(0.0, 0.0, 0.0)], [(0.0, 0.0, 1.0)], []
    # height profile z(rho) = -int tan(theta) drho with theta = theta_max rho / radius
    k = theta_max / radius
    for i in range(1, RINGS + 1):
        rho = radius * i / RINGS
        th = k * rho
        z = math.log(math.cos(th)) / k           # -int_0^rho tan(k r) dr
        for j in range(SEGMENTS):
            ph = 2.0 * math.pi * j / SEGMENTS
            verts.append((rho * math.cos(ph), rho * math.sin(ph), z))
            normals.append((math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph),
                            math.cos(th)))
    for j in range(SEGMENTS):
        faces.append((0, 1 + j, 1 + (j + 1) % SEGMENTS))
    for i in range(RINGS - 1):
        a, b = 1 + i * SEGMENTS, 1 + (i + 1) * SEGMENTS
        for j in range(SEGMENTS):
            j1 = (j + 1) % SEGMENTS
            faces.append((a + j, b + j, b + j1, a + j1))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.shade_smooth()
    mesh.normals_split_custom_set_from_vertices(normals)
    return mesh


def build(bpy):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device, c.samples = "CPU", 4
    c.use_denoising = c.use_adaptive_sampling = False
    c.max_bounces = 0
    c.filter_width = 0.01
    scene.render.resolution_x, scene.render.resolution_y = COLS * PX, ROWS * PX
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("Black")
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = float(COLS)
    cam.data.clip_end = 100.0
    cam.location = (0.0, 0.0, 20.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    for n in range(COLS * ROWS):
        col, row = n % COLS, n // COLS
        obj = bpy.data.objects.new(f"Dome{n}", dome_mesh(bpy, f"Dome{n}"))
        obj.location = (col - (COLS - 1) / 2, (ROWS - 1) / 2 - row, 0.0)
        obj.visible_shadow = False
        scene.collection.objects.link(obj)
        mat = bpy.data.materials.new(f"M{n}")
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        out = nodes["Material Output"]
        for node in list(nodes):
            if node.bl_idname != "ShaderNodeOutputMaterial":
                nodes.remove(node)
        if n < NODES:
            bsdf = nodes.new("ShaderNodeBsdfSheen")
            bsdf.distribution = "MICROFIBER"
            bsdf.inputs["Roughness"].default_value = n / (NODES - 1)
        else:
            bsdf = nodes.new("ShaderNodeBsdfDiffuse")
            bsdf.inputs["Roughness"].default_value = 0.0
        bsdf.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        links.new(bsdf.outputs[0], out.inputs["Surface"])
        obj.data.materials.append(mat)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 1.0
    sun.data.angle = 0.0
    scene.collection.objects.link(sun)
    # the normals: an emission override showing (N + 1) / 2
    show = bpy.data.materials.new("ShowNormal")
    nodes, links = show.node_tree.nodes, show.node_tree.links
    out = nodes["Material Output"]
    for node in list(nodes):
        if node.bl_idname != "ShaderNodeOutputMaterial":
            nodes.remove(node)
    geo = nodes.new("ShaderNodeNewGeometry")
    mad = nodes.new("ShaderNodeVectorMath")
    mad.operation = "MULTIPLY_ADD"
    mad.inputs[1].default_value = (0.5, 0.5, 0.5)
    mad.inputs[2].default_value = (0.5, 0.5, 0.5)
    emit = nodes.new("ShaderNodeEmission")
    links.new(geo.outputs["Normal"], mad.inputs[0])
    links.new(mad.outputs[0], emit.inputs["Color"])
    links.new(emit.outputs[0], out.inputs["Surface"])
    return scene, sun, show


def render(bpy, scene):
    settings = scene.render.image_settings
    settings.file_format, settings.color_depth = "OPEN_EXR", "32"
    bpy.ops.render.render()
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "r.exr")
        bpy.data.images["Render Result"].save_render(filepath=path, scene=scene)
        img = bpy.data.images.load(path, check_existing=False)
        w, h = img.size
        px = np.empty(w * h * 4, np.float32)
        img.pixels.foreach_get(px)
        bpy.data.images.remove(img)
    return px.reshape(h, w, 4)[::-1, :, :3].astype(np.float64)


def measure(bpy):
    """{'normal': (h, w, 3), 'suns': (S, 3) directions towards the sun, 'images':
    (S, h, w, 3), 'cols', 'rows', 'px'}."""
    scene, sun, show = build(bpy)
    images, dirs = [], []
    for deg in SUN_ANGLES:
        a = math.radians(deg)
        # a sun lamp shines along its local -Z; towards the sun is +Z rotated by a about y
        sun.rotation_euler = (0.0, a, 0.0)
        dirs.append((math.sin(a), 0.0, math.cos(a)))
        images.append(render(bpy, scene))
    scene.view_layers[0].material_override = show
    normal = render(bpy, scene) * 2.0 - 1.0
    return dict(normal=normal, suns=np.array(dirs), images=np.array(images),
                cols=COLS, rows=ROWS, px=PX)


def main(path):
    import bpy
    data = measure(bpy)
    np.savez_compressed(path, **data)
    print("saved", path)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "/tmp/sheen_probe.npz")
