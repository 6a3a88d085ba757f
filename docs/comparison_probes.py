"""The scene changes and probe scenes of docs/make_comparisons.py's known differences:
setups applied to a sample scene after it is opened (`scene_setup`, `grey_world`,
`glass_under_lamp`), and small probe scenes built with bpy and saved to a .blend
(`bokeh_probe`, `rough_glass_probe`, `furnace_plastic`)."""
from __future__ import annotations

import math


def scene_setup(**changes):
    def setup(scene):
        for key, value in changes.items():
            obj, attr = key.split("__")
            setattr(getattr(scene, obj), attr, value)
    return setup


def grey_world(level):
    def setup(scene):
        bg = scene.world.node_tree.nodes["Background"]
        bg.inputs["Color"].default_value = (level, level, level, 1.0)
        bg.inputs["Strength"].default_value = 1.0
    return setup


def glass_under_lamp(scene):
    import bpy
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    light = bpy.data.lights.new("Lamp", "AREA")
    light.size = 2.0
    light.energy = 3.0 * math.pi * 4.0        # radiance 3
    obj = bpy.data.objects.new("Lamp", light)
    obj.location = (0.5, -2.0, 3.0)
    scene.collection.objects.link(obj)
    from mathutils import Vector
    obj.rotation_euler = (Vector((0.0, 0.3, 0.0)) - obj.location).to_track_quat(
        "-Z", "Y").to_euler()


def bokeh_probe(path):
    """A small bright emissive square 3 m away, far out of focus (focus 0.3 m, f/0.5,
    six blades, rotation 0): its image is the aperture polygon."""
    import bpy
    import build_samples as bs
    scene = bs.reset()
    glow = bs.principled("Glow", (0.0, 0.0, 0.0), specular=0.0, emission=(1.0, 1.0, 1.0),
                         strength=15.0)
    s = 0.06
    bs.quad("Glow", [(-s, 3.0, -s), (-s, 3.0, s), (s, 3.0, s), (s, 3.0, -s)], glow)
    cam = bs.camera(scene, (0.0, 0.0, 0.0), (math.radians(90.0), 0.0, 0.0), lens=50.0)
    cam.data.dof.use_dof = True
    cam.data.dof.focus_distance = 0.3
    cam.data.dof.aperture_fstop = 0.5
    cam.data.dof.aperture_blades = 6
    bs.render_defaults(scene, size=(48, 48), samples=4096)
    scene.cycles.use_adaptive_sampling = False
    bpy.ops.wm.save_as_mainfile(filepath=path)


def rough_glass_probe(path):
    """A rough glass sphere (GGX, roughness 0.67, IOR 1.45) before a 2 m square lamp of
    radiance 5 that it hides from the camera, black world, clamps and Filter Glossy off:
    the lamp's light through rough glass alone, 32 x 32 pixels."""
    import bpy
    import build_samples as bs
    scene = bs.reset()
    mat = bs.principled("Glass", (1.0, 1.0, 1.0), roughness=0.67)
    node = mat.node_tree.nodes["Principled BSDF"]
    node.inputs["Transmission Weight"].default_value = 1.0
    node.inputs["IOR"].default_value = 1.45
    node.distribution = "GGX"
    bs.uv_sphere("Sphere", (0.0, 0.0, 0.0), 1.0, mat, 96, 48)
    bs._area_light(scene, (0.0, 3.0, 0.0), (0.0, 0.0, 0.0), 2.0, 5.0, name="Lamp")
    bs.camera(scene, (0.0, -4.0, 0.0), (math.radians(90.0), 0.0, 0.0), lens=50.0)
    bs.render_defaults(scene, size=(32, 32), samples=1024)
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.blur_glossy = 0.0
    bpy.ops.wm.save_as_mainfile(filepath=path)


def furnace_plastic(path, roughness):
    """A Principled plastic sphere (base 0.8, default specular, single-scatter GGX) in a
    uniform white world: DRT's and Cycles' layering of diffuse under specular."""
    import bpy
    import build_samples as bs
    scene = bs.reset()
    mat = bs.principled("Plastic", (0.8, 0.8, 0.8), roughness=roughness)
    mat.node_tree.nodes["Principled BSDF"].distribution = "GGX"
    bs.uv_sphere("Sphere", (0.0, 0.0, 0.0), 1.0, mat)
    bs.camera(scene, (0.0, -4.0, 0.0), (math.radians(90.0), 0.0, 0.0), lens=50.0)
    bs.render_defaults(scene, size=(32, 32), samples=512)
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.blur_glossy = 0.0
    bs._set_world(scene, (1.0, 1.0, 1.0), 1.0)
    bpy.ops.wm.save_as_mainfile(filepath=path)
