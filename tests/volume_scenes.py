"""Small volume scenes built with bpy at Blender's defaults, for DRT against Cycles
(tests/test_volumes_vs_cycles.py) and the docs: a grey floor and a diffuse cube seen
through a box of fog under an area lamp, in a black world, with one variation per case."""
from __future__ import annotations

import math

WIDTH, HEIGHT = 64, 48


def _new_material(bpy, name):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    return mat


def _mesh_object(bpy, scene, name, verts, faces, mat):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    if mat is not None:
        mesh.materials.append(mat)
    return obj


def cube(bpy, scene, name, lo, hi, mat):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    f = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return _mesh_object(bpy, scene, name, v, f, mat)


def volume_material(bpy, name, node_type, inputs, surface=None):
    """A material whose Volume socket is fed by a `node_type` node with `inputs`; its
    Surface unlinked (a volume-only material) unless `surface` names a BSDF node type."""
    mat = _new_material(bpy, name)
    nt = mat.node_tree
    out = nt.nodes["Material Output"]
    bsdf = nt.nodes.get("Principled BSDF")
    if surface is None:
        if bsdf is not None:
            nt.nodes.remove(bsdf)
    else:
        if bsdf is not None:
            nt.nodes.remove(bsdf)
        s = nt.nodes.new(surface)
        nt.links.new(s.outputs[0], out.inputs["Surface"])
        if surface == "ShaderNodeBsdfGlass":
            s.inputs["Roughness"].default_value = 0.0
    v = nt.nodes.new(node_type)
    for k, val in inputs.items():
        v.inputs[k].default_value = val
    nt.links.new(v.outputs[0], out.inputs["Volume"])
    return mat


def noise_density(bpy, mat, node_name, scale=2.5):
    """Drive the Density of `mat`'s node `node_name` by a Noise Texture (Generated
    coordinates, the default) through a Color Ramp from 0 at Fac 0.42 to 0.6 at 0.58:
    fog in blobs, clear between them."""
    nt = mat.node_tree
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = scale
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].position = 0.42
    ramp.color_ramp.elements[1].position = 0.58
    ramp.color_ramp.elements[1].color = (0.6, 0.6, 0.6, 1.0)
    nt.links.new(noise.outputs["Fac"], ramp.inputs["Fac"])
    nt.links.new(ramp.outputs["Color"], nt.nodes[node_name].inputs["Density"])


def build(bpy, case, size=(WIDTH, HEIGHT)):
    """A fresh file with the fog scene and the variation `case` names."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("Black")
    if bpy.app.version < (5, 0, 0):
        scene.world.use_nodes = True
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, -7.0, 2.2)
    cam.rotation_euler = (math.radians(78.0), 0.0, 0.0)
    cam.data.lens = 35.0
    scene.collection.objects.link(cam)
    scene.camera = cam
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "AREA"))
    lamp.data.size = 1.5
    lamp.data.energy = 400.0
    lamp.location = (0.6, 0.0, 3.6)
    scene.collection.objects.link(lamp)
    grey = _new_material(bpy, "Grey")
    grey.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = \
        (0.5, 0.5, 0.5, 1.0)
    _mesh_object(bpy, scene, "Floor", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)],
                 [(0, 1, 2, 3)], grey)
    red = _new_material(bpy, "Red")
    red.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = \
        (0.7, 0.15, 0.1, 1.0)
    cube(bpy, scene, "Block", (-0.9, 0.2, 0.0), (-0.1, 1.0, 0.8), red)
    fog_box = ((-2.0, -1.5, 0.01), (2.0, 2.0, 3.0))
    if case == "scatter":
        fog = volume_material(bpy, "Fog", "ShaderNodeVolumePrincipled",
                              {"Density": 0.25})
        cube(bpy, scene, "Fog", *fog_box, fog)
    elif case == "tinted":
        fog = volume_material(bpy, "Fog", "ShaderNodeVolumePrincipled",
                              {"Density": 0.4, "Color": (0.9, 0.6, 0.3, 1.0),
                               "Absorption Color": (0.2, 0.5, 0.9, 1.0), "Anisotropy": 0.5})
        cube(bpy, scene, "Fog", *fog_box, fog)
    elif case == "multiple":
        scene.cycles.volume_bounces = 4
        fog = volume_material(bpy, "Fog", "ShaderNodeVolumeScatter",
                              {"Density": 0.6, "Color": (0.9, 0.9, 0.9, 1.0)})
        cube(bpy, scene, "Fog", *fog_box, fog)
    elif case == "absorption_glass":
        glass = volume_material(bpy, "TintedGlass", "ShaderNodeVolumeAbsorption",
                                {"Density": 1.5, "Color": (0.2, 0.6, 0.9, 1.0)},
                                surface="ShaderNodeBsdfGlass")
        cube(bpy, scene, "Glass", (0.2, -1.0, 0.01), (1.4, 0.2, 1.2), glass)
    elif case == "clear_glass":       # the same glass, no volume (for comparison)
        glass = volume_material(bpy, "ClearGlass", "ShaderNodeVolumeAbsorption",
                                {"Density": 0.0}, surface="ShaderNodeBsdfGlass")
        cube(bpy, scene, "Glass", (0.2, -1.0, 0.01), (1.4, 0.2, 1.2), glass)
    elif case == "noise":
        fog = volume_material(bpy, "Fog", "ShaderNodeVolumePrincipled", {})
        noise_density(bpy, fog, "Principled Volume")
        cube(bpy, scene, "Fog", fog_box[0], (2.0, 2.0, 2.2), fog)
    elif case == "emission":
        glow = volume_material(bpy, "Glow", "ShaderNodeEmission",
                               {"Strength": 1.5, "Color": (1.0, 0.5, 0.2, 1.0)})
        cube(bpy, scene, "Glow", (0.2, -1.0, 0.3), (1.4, 0.2, 1.5), glow)
    elif case == "world":
        nt = scene.world.node_tree
        v = nt.nodes.new("ShaderNodeVolumePrincipled")
        v.inputs["Density"].default_value = 0.05
        nt.links.new(v.outputs[0], nt.nodes["World Output"].inputs["Volume"])
    elif case == "beam":
        # a spot lamp through thin fog, the beam lit fog (the area lamp dimmed to a fill)
        lamp.data.energy = 20.0
        spot = bpy.data.objects.new("Spot", bpy.data.lights.new("Spot", "SPOT"))
        spot.data.energy = 1500.0
        spot.data.spot_size = math.radians(40.0)
        spot.data.spot_blend = 0.3
        spot.location = (0.3, 0.4, 3.5)
        scene.collection.objects.link(spot)
        fog = volume_material(bpy, "Fog", "ShaderNodeVolumePrincipled", {"Density": 0.08})
        cube(bpy, scene, "Fog", *fog_box, fog)
    elif case == "noise_lamps":
        # point lamps inside fog in blobs (a heterogeneous volume), the area lamp dimmed
        # to a fill: the light is scattered mostly close to the lamps
        lamp.data.energy = 20.0
        for name, loc, power, colour in (("Warm", (0.8, 0.3, 1.2), 150.0, (1.0, 0.5, 0.2)),
                                         ("Cool", (-1.2, 1.4, 1.8), 100.0, (0.2, 0.5, 1.0))):
            point = bpy.data.objects.new(name, bpy.data.lights.new(name, "POINT"))
            point.data.energy = power
            point.data.color = colour
            point.data.shadow_soft_size = 0.05
            point.location = loc
            scene.collection.objects.link(point)
        fog = volume_material(bpy, "Fog", "ShaderNodeVolumePrincipled", {})
        noise_density(bpy, fog, "Principled Volume")
        cube(bpy, scene, "Fog", *fog_box, fog)
    elif case == "clipped_world":
        # thin fog filling the world under a grey sky, a spot beam crossing the view far
        # beyond the camera's clip end (as smoke.blend, a public file): rays that reach
        # the clip end go on through the world's volume (Cycles ends a missed ray's
        # volume segment at infinity), so the sky behind the fog is not seen, nor does
        # its light or a sun's reach anything
        lamp.data.energy = 50.0
        nt = scene.world.node_tree
        nt.nodes["Background"].inputs["Color"].default_value = (0.3, 0.3, 0.3, 1.0)
        nt.nodes["Background"].inputs["Strength"].default_value = 1.0
        v = nt.nodes.new("ShaderNodeVolumeScatter")
        v.inputs["Density"].default_value = 0.02
        nt.links.new(v.outputs[0], nt.nodes["World Output"].inputs["Volume"])
        spot = bpy.data.objects.new("Spot", bpy.data.lights.new("Spot", "SPOT"))
        spot.data.energy = 200000.0
        spot.data.spot_size = math.radians(35.0)
        spot.location = (-14.0, 30.0, 12.0)
        spot.rotation_euler = (math.radians(-35.0), math.radians(-30.0), 0.0)
        scene.collection.objects.link(spot)
        # and a sun, which gives no light at all through a volume that fills the world
        sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
        sun.data.energy = 3.0
        sun.rotation_euler = (math.radians(30.0), 0.0, math.radians(20.0))
        scene.collection.objects.link(sun)
        cam.data.clip_end = 9.0
    elif case == "camera_inside":
        fog = volume_material(bpy, "Fog", "ShaderNodeVolumePrincipled", {"Density": 0.15})
        cube(bpy, scene, "Fog", (-5.0, -8.0, -0.5), (5.0, 5.0, 5.0), fog)
    else:
        raise ValueError(case)
    return scene


CASES = ("scatter", "tinted", "multiple", "noise", "absorption_glass", "clear_glass",
         "emission", "world", "camera_inside", "beam", "noise_lamps", "clipped_world")
