"""A harness that compares shader nodes with Cycles pixel by pixel.

Each case is a small node graph feeding the Color of an Emission shader (strength 1) on
its own object, one tile of a grid seen from above by an orthographic camera; the world
is black. Emission seen directly has no light-transport noise, so what differs between
DRT and Cycles is the node's value (and antialiasing at sharp edges, the same pixel
filter in both). One render per engine serves every case; `tile_errors` measures each
tile.

A case is `(name, build)`: build(nt, probe) adds nodes to the material's tree `nt` and
returns the output socket to show. `probe.obj` is the tile's object (set its
colour, rotation...); `probe.coords(nt)` gives a Texture Coordinate node.
"""
from __future__ import annotations

import math

import numpy as np

from conftest import render_current, use_engine
from figures import AGAINST_CYCLES, record

TILE = 16                  # pixels per tile


class Probe:
    def __init__(self, obj):
        self.obj = obj

    @staticmethod
    def coords(nt):
        return nt.nodes.new("ShaderNodeTexCoord")

    @staticmethod
    def node(nt, kind, **settings):
        n = nt.nodes.new(kind)
        for k, v in settings.items():
            setattr(n, k, v)
        return n


def build_scene(bpy, cases, columns=None, shape="plane", tile=TILE):
    """A new scene holding one tile per case, `tile` pixels square; returns (scene,
    columns, rows)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    n = len(cases)
    columns = columns or int(math.ceil(math.sqrt(n)))
    rows = int(math.ceil(n / columns))
    for k, (name, build) in enumerate(cases):
        i, j = k % columns, k // columns
        x, y = 2.0 * i - (columns - 1), (rows - 1) - 2.0 * j
        if shape == "sphere":
            bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=(x, y, 0.0),
                                                 segments=48, ring_count=24)
            bpy.ops.object.shade_smooth()
        else:
            bpy.ops.mesh.primitive_plane_add(size=2.0, location=(x, y, 0.0))
        obj = bpy.context.object
        obj.name = name
        mat = bpy.data.materials.new(name)
        mat.use_nodes = True
        nt = mat.node_tree
        for node in list(nt.nodes):
            nt.nodes.remove(node)
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        emission = nt.nodes.new("ShaderNodeEmission")
        emission.inputs["Strength"].default_value = 1.0
        emission.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        nt.links.new(emission.outputs[0], out.inputs["Surface"])
        socket = build(nt, Probe(obj))
        nt.links.new(socket, emission.inputs["Color"])
        obj.data.materials.append(mat)
    cam_data = bpy.data.cameras.new("Camera")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = 2.0 * max(columns, rows)
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    cam.location = (0.0, 0.0, 10.0)
    scene.camera = cam
    scene.render.resolution_x = tile * columns
    scene.render.resolution_y = tile * rows
    if columns != rows:
        cam_data.sensor_fit = "HORIZONTAL" if columns >= rows else "VERTICAL"
    scene.render.resolution_percentage = 100
    world = bpy.data.worlds.new("World")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    return scene, columns, rows


def sun_and_top_camera(bpy, scene, sun_rotation, sun_angle, ortho_scale, height):
    """A sun of strength 3 turned by `sun_rotation` (Euler, radians) and an orthographic
    camera `height` above the origin looking down, made the scene's camera."""
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = 3.0, sun_angle
    sun.rotation_euler = sun_rotation
    scene.collection.objects.link(sun)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type, cam.data.ortho_scale = "ORTHO", ortho_scale
    cam.location = (0.0, 0.0, height)
    scene.collection.objects.link(cam)
    scene.camera = cam


def sun_and_camera(bpy, scene, energy, angle, sun_rotation, location, rotation):
    """A sun (strength, angular diameter, Euler rotation) and a perspective camera at
    `location` turned by `rotation`, made the scene's camera."""
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = energy, angle
    sun.rotation_euler = sun_rotation
    scene.collection.objects.link(sun)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location, cam.rotation_euler = location, rotation
    scene.collection.objects.link(cam)
    scene.camera = cam


def render(bpy, scene, engine, samples):
    use_engine(scene, engine, samples)
    return render_current(bpy, scene)


def unlink_probes(bpy):
    """The fallback DRT had before node programs: every Emission Color unlinked."""
    for mat in bpy.data.materials:
        for node in mat.node_tree.nodes:
            if node.bl_idname == "ShaderNodeEmission":
                for link in list(node.inputs["Color"].links):
                    mat.node_tree.links.remove(link)


def tiles(img, columns, rows, tile=TILE):
    """{index: (tile, tile, 3)} of an image rendered by build_scene (inner pixels only
    would hide edge errors, so the whole tile)."""
    out = {}
    for k in range(columns * rows):
        i, j = k % columns, k // columns
        out[k] = img[j * tile:(j + 1) * tile, i * tile:(i + 1) * tile]
    return out


def tile_errors(drt, cycles):
    """(mean difference over Cycles' mean, per-pixel mean absolute difference over
    Cycles' mean, largest difference of the 8 x 8 block means over Cycles' mean) of one
    tile; Cycles' mean is floored at 0.02 so that a black tile is judged in absolute
    terms."""
    ref = max(float(cycles.mean()), 0.02)
    mean = abs(float(drt.mean() - cycles.mean())) / ref
    mad = float(np.abs(drt - cycles).mean()) / ref
    h, w, _ = cycles.shape
    diff = (drt - cycles).mean(axis=2)[:h // 8 * 8, :w // 8 * 8]
    blocks = np.abs(diff.reshape(h // 8, 8, w // 8, 8).mean(axis=(1, 3)))
    return mean, mad, float(blocks.max()) / ref


def drt_against_cycles(bpy, scene, drt_samples, cycles_samples=None):
    """The scene rendered by Cycles (cycles_samples, by default drt_samples) and by DRT:
    image_errors(DRT's, Cycles')."""
    cycles = render(bpy, scene, "CYCLES", cycles_samples or drt_samples)
    return image_errors(render(bpy, scene, "DRT", drt_samples), cycles)


def image_errors(drt, cycles, what=AGAINST_CYCLES):
    """(|mean ratio - 1|, largest 8 x 8 block difference over the image mean), recorded
    for the docs (figures.record) as `what`."""
    h, w, _ = cycles.shape
    d = (drt - cycles).mean(axis=2).reshape(h // 8, 8, w // 8, 8).mean(axis=(1, 3))
    mean = abs(float(drt.mean()) / float(cycles.mean()) - 1.0)
    block = float(np.abs(d).max() / cycles.mean())
    record(what, mean=mean, block=block)
    return mean, block


def new_scene(bpy, size=64):
    """An empty scene of size x size pixels with a new (default) world."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("World")
    return scene


def tilted_square(bpy, make_material, world_strength):
    """A new 64 x 64 scene with a default world at world_strength and a 2 m square of
    the material make_material() returns (made in the new scene) at the origin, tilted
    20 degrees about x and -15 about y: the scene."""
    scene = new_scene(bpy, 64)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = \
        world_strength
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    square = bpy.context.object
    square.rotation_euler = (math.radians(20.0), math.radians(-15.0), 0.0)
    square.data.materials.append(make_material())
    return scene


def empty_material(bpy, name):
    """A new node material with nothing but its Material Output: (material, node tree,
    output node)."""
    mat, nt = new_material(bpy, name)
    for node in list(nt.nodes):
        nt.nodes.remove(node)
    return mat, nt, nt.nodes.new("ShaderNodeOutputMaterial")


def new_material(bpy, name):
    """A new node material (Principled BSDF into the Material Output) and its tree."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    return mat, mat.node_tree


def smooth_sphere_scene(bpy, segments, rings, material):
    """A 32 x 32 scene with a black world and a smooth-shaded UV sphere (radius 1) of a
    new grey (0.8) Principled material: (scene, sphere, node tree, Principled node)."""
    scene = new_scene(bpy, 32)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=segments, ring_count=rings)
    bpy.ops.object.shade_smooth()
    sphere = bpy.context.object
    mat, nt = new_material(bpy, material)
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    sphere.data.materials.append(mat)
    return scene, sphere, nt, bsdf
