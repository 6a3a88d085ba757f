"""Builds DRT's sample scenes with bpy, deterministically.

    python sample_blends/build_samples.py [--out-dir sample_blends] [NAME ...]

Each scene is a function below; its .blend is written next to this script. Scenes use
Principled BSDFs (with Specular IOR Level 0 where a scene is meant to be purely diffuse)
and keep Blender's defaults elsewhere, so they render the same in Cycles and DRT.
"""
from __future__ import annotations

import argparse
import math
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.frame_set(1)
    return scene


def principled(name, color, roughness=0.5, specular=0.5, metallic=0.0, emission=None,
               strength=0.0):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Specular IOR Level"].default_value = specular
    bsdf.inputs["Metallic"].default_value = metallic
    if emission is not None:
        bsdf.inputs["Emission Color"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    mat.diffuse_color = (*color, 1.0)
    return mat


def mesh_object(name, verts, faces, material):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.validate()
    obj = bpy.data.objects.new(name, mesh)
    obj.data.materials.append(material)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def quad(name, corners, material):
    return mesh_object(name, corners, [(0, 1, 2, 3)], material)


def cuboid(name, lo, hi, material, rotation_z=0.0):
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    verts = [(x - cx, y - cy, z) for (x, y, z) in
             [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
              (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    obj = mesh_object(name, verts, faces, material)
    obj.location = (cx, cy, 0.0)
    obj.rotation_euler = (0.0, 0.0, rotation_z)
    return obj


def camera(scene, location, rotation, lens=35.0):
    data = bpy.data.cameras.new("Camera")
    data.lens = lens
    obj = bpy.data.objects.new("Camera", data)
    obj.location = location
    obj.rotation_euler = rotation
    scene.collection.objects.link(obj)
    scene.camera = obj
    return obj


def render_defaults(scene, size=(256, 256), samples=64):
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.device = "CPU"
    if hasattr(scene, "drt"):
        scene.drt.samples = samples
    world = bpy.data.worlds.new("World")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world


def cornell_box():
    """The Cornell box: a 2 m room, two blocks, one square area light under the ceiling."""
    scene = reset()
    white = principled("White", (0.73, 0.73, 0.73), specular=0.0)
    red = principled("Red", (0.65, 0.05, 0.05), specular=0.0)
    green = principled("Green", (0.12, 0.45, 0.15), specular=0.0)
    quad("Floor", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], white)
    quad("Ceiling", [(-1, -1, 2), (-1, 1, 2), (1, 1, 2), (1, -1, 2)], white)
    quad("Back", [(-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2)], white)
    quad("Left", [(-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2)], red)
    quad("Right", [(1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0)], green)
    cuboid("TallBlock", (-0.6, -0.1, 0.0), (-0.05, 0.45, 1.2), white, math.radians(17))
    cuboid("ShortBlock", (0.1, -0.6, 0.0), (0.65, -0.05, 0.6), white, math.radians(-17))
    light = bpy.data.lights.new("Light", "AREA")
    light.shape = "SQUARE"
    light.size = 0.5
    light.energy = 60.0
    lobj = bpy.data.objects.new("Light", light)
    lobj.location = (0.0, 0.0, 1.98)
    scene.collection.objects.link(lobj)
    camera(scene, (0.0, -3.9, 1.0), (math.radians(90), 0.0, 0.0), lens=35.0)
    render_defaults(scene)
    return scene


# --- Light unit scenes: one light over a diffuse plane, direct light only -------------
#
# A grey Principled plane (Specular IOR Level 0, roughness 0.5: purely Lambertian in both
# engines) fills the view of a camera 4 m above it, looking straight down; one light of
# the type under test lights it, placed outside the camera's view (or invisible to
# camera rays), so the image is the light's irradiance on the plane times albedo / pi.
# Diffuse bounces are 0, so the image is direct light only. 48 x 48 pixels.

LIGHT_PLANE_ALBEDO = (0.8, 0.8, 0.8)


def _aim(obj, target):
    """Point the object's -Z axis at `target` (Blender lights emit along -Z)."""
    from mathutils import Vector
    direction = Vector(target) - obj.location
    obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()


def _light_plane_scene(kind, location, target=(0.0, 0.0, 0.0), **props):
    scene = reset()
    grey = principled("Grey", LIGHT_PLANE_ALBEDO, roughness=0.5, specular=0.0)
    quad("Plane", [(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)], grey)
    camera(scene, (0.0, 0.0, 4.0), (0.0, 0.0, 0.0), lens=50.0)
    light = bpy.data.lights.new("Light", kind)
    for key, value in props.items():
        setattr(light, key, value)
    obj = bpy.data.objects.new("Light", light)
    obj.location = location
    scene.collection.objects.link(obj)
    _aim(obj, target)
    render_defaults(scene, size=(48, 48), samples=256)
    scene.cycles.diffuse_bounces = 0
    scene.cycles.use_adaptive_sampling = False
    return scene


def light_point():
    """A point light of radius 0, 100 W, 1 m above the plane."""
    return _light_plane_scene("POINT", (0.4, 0.3, 1.0), energy=100.0, shadow_soft_size=0.0)


def light_point_radius():
    """A point light of radius 0.3 m (Blender's default soft falloff), out of view."""
    return _light_plane_scene("POINT", (1.9, 0.0, 1.0), energy=300.0, shadow_soft_size=0.3)


def light_point_sphere():
    """As light_point_radius, with soft falloff off: a true sphere light."""
    return _light_plane_scene("POINT", (1.9, 0.0, 1.0), energy=300.0, shadow_soft_size=0.3,
                              use_soft_falloff=False)


def light_spot():
    """A spot light, cone 60 degrees with blend 0.4, aimed off-centre so both the cone's
    edge and its smooth blend cross the image."""
    return _light_plane_scene("SPOT", (0.3, 0.0, 1.5), target=(0.5, 0.2, 0.0), energy=200.0,
                              shadow_soft_size=0.0, spot_size=math.radians(60.0),
                              spot_blend=0.4)


def _sun(angle):
    # 30 degrees off the vertical: the irradiance on the plane is 3 cos(30 deg).
    target = (1.0 - 2.0 * math.tan(math.radians(30.0)), 0.0, 0.0)
    return _light_plane_scene("SUN", (1.0, 0.0, 2.0), target=target, energy=3.0, angle=angle)


def light_sun():
    """A sun of strength 3 W/m^2, angle 0, 30 degrees off the vertical."""
    return _sun(0.0)


def light_sun_angle():
    """As light_sun with an angular diameter of 10 degrees."""
    return _sun(math.radians(10.0))


def _area(shape, **props):
    props.setdefault("energy", 150.0)
    return _light_plane_scene("AREA", (1.9, 0.0, 0.9), target=(0.0, 0.0, 0.0), shape=shape,
                              **props)


def light_area_square():
    """A 0.5 m square area light, out of view, aimed at the centre of the plane."""
    return _area("SQUARE", size=0.5)


def light_area_rectangle():
    """A 0.8 x 0.3 m rectangular area light."""
    return _area("RECTANGLE", size=0.8, size_y=0.3)


def light_area_disk():
    """A disk area light of 0.5 m diameter."""
    return _area("DISK", size=0.5)


def light_area_ellipse():
    """An ellipse area light of 0.8 x 0.3 m."""
    return _area("ELLIPSE", size=0.8, size_y=0.3)


def light_area_unnormalized():
    """A 0.5 m square area light with `normalize` off (power not divided by the area)."""
    return _area("SQUARE", size=0.5, energy=10.0, normalize=False)


def light_exposure_color():
    """A point light with exposure 1.5 and an orange colour: S = colour x energy x 2^1.5."""
    return _light_plane_scene("POINT", (0.4, 0.3, 1.0), energy=40.0, shadow_soft_size=0.0,
                              exposure=1.5, color=(1.0, 0.55, 0.2))


def light_point_unnormalized():
    """A point light of radius 0 with `normalize` off (Blender 4.4+ has it on every light
    type)."""
    return _light_plane_scene("POINT", (0.4, 0.3, 1.0), energy=25.0, shadow_soft_size=0.0,
                              normalize=False)


def light_sun_angle_unnormalized():
    """A 10 degree sun with `normalize` off: `energy` is then its radiance."""
    target = (1.0 - 2.0 * math.tan(math.radians(30.0)), 0.0, 0.0)
    return _light_plane_scene("SUN", (1.0, 0.0, 2.0), target=target, energy=100.0,
                              angle=math.radians(10.0), normalize=False)


def light_temperature():
    """A point light coloured by a 3000 K blackbody temperature."""
    return _light_plane_scene("POINT", (0.4, 0.3, 1.0), energy=100.0, shadow_soft_size=0.0,
                              use_temperature=True, temperature=3000.0)


LIGHT_SCENES = {f.__name__: f for f in (
    light_point, light_point_radius, light_point_sphere, light_spot, light_sun,
    light_sun_angle, light_area_square, light_area_rectangle, light_area_disk,
    light_area_ellipse, light_area_unnormalized, light_exposure_color,
    light_point_unnormalized, light_sun_angle_unnormalized, light_temperature)}

SCENES = {"cornell_box": cornell_box, **LIGHT_SCENES}



# --- Motion blur scenes: something moves within the frame's shutter -------------------
#
# A grey floor, one area light, a black world, direct light only (diffuse bounces 0),
# 64 x 48 pixels. Motion blur is on with a shutter of 0.5 frames, position CENTER; the
# frame rendered is 1 and the animation is keyed at frames 0 and 2 with linear
# interpolation, so the motion is uniform over any shutter position.

MOTION_FRAME = 1
MOTION_SHUTTER = 0.5
MOTION_CUBE_SPEED = 2.0           # metres per frame, along +X
MOTION_CUBE_SIZE = 0.5
MOTION_TORUS_SPIN = 200.0         # degrees per frame about the world Z axis


def _linear_keys(obj):
    """Linear interpolation for every keyframe of `obj` (layered actions in 4.4+)."""
    action = obj.animation_data.action
    fcurves = getattr(action, "fcurves", None)
    if fcurves is None:
        from bpy_extras import anim_utils
        fcurves = anim_utils.action_get_channelbag_for_slot(
            action, obj.animation_data.action_slot).fcurves
    for fc in fcurves:
        for key in fc.keyframe_points:
            key.interpolation = "LINEAR"


def _motion_stage():
    scene = reset()
    grey = principled("Floor", (0.1, 0.1, 0.1), specular=0.0)
    quad("Floor", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)], grey)
    light = bpy.data.lights.new("Light", "AREA")
    light.shape = "SQUARE"
    light.size = 1.0
    light.energy = 150.0
    lobj = bpy.data.objects.new("Light", light)
    lobj.location = (1.0, -1.5, 3.0)
    scene.collection.objects.link(lobj)
    _aim(lobj, (0.0, 0.0, 0.0))
    cam = camera(scene, (0.0, -3.2, 2.4), (0.0, 0.0, 0.0), lens=50.0)
    _aim(cam, (0.0, 0.0, 0.4))
    render_defaults(scene, size=(64, 48), samples=256)
    scene.cycles.diffuse_bounces = 0
    scene.cycles.use_adaptive_sampling = False
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = MOTION_SHUTTER
    scene.render.motion_blur_position = "CENTER"
    return scene


def motion_cube():
    """A red 0.5 m cube sliding along +X at 2 m per frame: 1 m within the shutter."""
    scene = _motion_stage()
    red = principled("Red", (0.8, 0.1, 0.05), specular=0.0)
    h = MOTION_CUBE_SIZE / 2
    cube = cuboid("Cube", (-h, -h, 0.0), (h, h, MOTION_CUBE_SIZE), red)
    for frame in (MOTION_FRAME - 1, MOTION_FRAME + 1):
        cube.location.x = (frame - MOTION_FRAME) * MOTION_CUBE_SPEED
        cube.keyframe_insert("location", index=0, frame=frame)
    _linear_keys(cube)
    scene.frame_set(MOTION_FRAME)
    return scene


def _torus(name, major, minor, material, segments=32, rings=12):
    verts, faces = [], []
    for i in range(segments):
        a = 2 * math.pi * i / segments
        for j in range(rings):
            b = 2 * math.pi * j / rings
            r = major + minor * math.cos(b)
            verts.append((r * math.cos(a), r * math.sin(a), minor * math.sin(b)))
    for i in range(segments):
        for j in range(rings):
            i2, j2 = (i + 1) % segments, (j + 1) % rings
            faces.append((i * rings + j, i2 * rings + j, i2 * rings + j2, i * rings + j2))
    obj = mesh_object(name, verts, faces, material)
    for poly in obj.data.polygons:
        poly.use_smooth = True
    return obj


def motion_torus():
    """An upright yellow torus spinning about the vertical at 200 degrees per frame:
    100 degrees within the shutter."""
    scene = _motion_stage()
    yellow = principled("Yellow", (0.8, 0.6, 0.1), specular=0.0)
    torus = _torus("Torus", 0.5, 0.17, yellow)
    torus.location = (0.0, 0.0, 0.72)
    for frame in (MOTION_FRAME - 1, MOTION_FRAME + 1):
        spin = math.radians((frame - MOTION_FRAME) * MOTION_TORUS_SPIN)
        torus.rotation_euler = (math.radians(90.0), 0.0, spin)
        torus.keyframe_insert("rotation_euler", frame=frame)
    _linear_keys(torus)
    scene.frame_set(MOTION_FRAME)
    return scene


MOTION_SCENES = {f.__name__: f for f in (motion_cube, motion_torus)}
SCENES.update(MOTION_SCENES)


# --- Comparison scenes: one area of the renderer each, against Cycles ------------------
#
# 64 x 64 pixels, Principled BSDF only, compared in tests/test_scenes_vs_cycles.py and
# docs/comparisons.md. Every setting is Blender's default, as a user would have it:
# Multiscatter GGX on the Principled BSDFs, the default light paths (12 bounces: 4
# diffuse, 4 glossy, 12 transmission; full global illumination) and clamps (direct off,
# indirect 10) in both Cycles' and DRT's settings, and Cycles' Filter Glossy 1 and both
# Caustics switches on, which DRT reads from the Cycles settings. Only the sampling is
# set: a fixed sample count (Cycles 1024, DRT 512), no adaptive sampling, no denoising.
# The lamps of metals, glossy_dielectric, dof and instances are large and dim
# (radiance 3), so the clamp hardly acts there; mirror_caustic's small bright lamp
# tests it.

COMPARISON_SIZE = (64, 64)
STRIPE_COLORS = [(0.8, 0.15, 0.1), (0.85, 0.85, 0.85), (0.1, 0.3, 0.8), (0.15, 0.6, 0.15)]


def uv_sphere(name, center, radius, material, segments=48, rings=24):
    """A smooth-shaded UV sphere (segments x rings, poles on Z)."""
    verts = [(0.0, 0.0, radius)]
    for i in range(1, rings):
        th = math.pi * i / rings
        for j in range(segments):
            ph = 2.0 * math.pi * j / segments
            verts.append((radius * math.sin(th) * math.cos(ph),
                          radius * math.sin(th) * math.sin(ph), radius * math.cos(th)))
    verts.append((0.0, 0.0, -radius))
    faces = [(0, 1 + j, 1 + (j + 1) % segments) for j in range(segments)]
    for i in range(rings - 2):
        a, b = 1 + i * segments, 1 + (i + 1) * segments
        for j in range(segments):
            k = (j + 1) % segments
            faces.append((a + j, b + j, b + k, a + k))
    last, a = len(verts) - 1, 1 + (rings - 2) * segments
    faces += [(a + j, last, a + (j + 1) % segments) for j in range(segments)]
    obj = mesh_object(name, verts, faces, material)
    obj.data.polygons.foreach_set("use_smooth", [True] * len(obj.data.polygons))
    obj.data.update()
    obj.location = center
    return obj


def _area_light(scene, location, target, size, radiance, name="Light"):
    """A square area light of `size` metres aimed at `target`, of the given radiance
    (energy = radiance x pi x area, Cycles' meaning)."""
    light = bpy.data.lights.new(name, "AREA")
    light.shape = "SQUARE"
    light.size = size
    light.energy = radiance * math.pi * size * size
    obj = bpy.data.objects.new(name, light)
    obj.location = location
    scene.collection.objects.link(obj)
    _aim(obj, target)
    return obj


def _multi_material_mesh(name, quads, materials, indices):
    """One mesh object of quads (4 corners each), quad k using materials[indices[k]]."""
    verts = [v for q in quads for v in q]
    faces = [tuple(range(4 * k, 4 * k + 4)) for k in range(len(quads))]
    obj = mesh_object(name, verts, faces, materials[0])
    for mat in materials[1:]:
        obj.data.materials.append(mat)
    obj.data.polygons.foreach_set("material_index", list(indices))
    obj.data.update()
    return obj


def _stripes(name, x0, x1, z0, z1, y, colors, n):
    """A wall in the plane y of n vertical stripes cycling through diffuse `colors`."""
    mats = [principled(f"{name}{i}", c, specular=0.0) for i, c in enumerate(colors)]
    quads = []
    for i in range(n):
        a, b = x0 + (x1 - x0) * i / n, x0 + (x1 - x0) * (i + 1) / n
        quads.append([(a, y, z0), (b, y, z0), (b, y, z1), (a, y, z1)])
    return _multi_material_mesh(name, quads, mats, [i % len(mats) for i in range(n)])


def _checker(name, x0, x1, y0, y1, z, colors, n):
    """A floor at height z of n x n squares alternating two diffuse colours."""
    mats = [principled(f"{name}{i}", c, specular=0.0) for i, c in enumerate(colors)]
    quads, index = [], []
    for i in range(n):
        for j in range(n):
            a, b = x0 + (x1 - x0) * i / n, x0 + (x1 - x0) * (i + 1) / n
            c, d = y0 + (y1 - y0) * j / n, y0 + (y1 - y0) * (j + 1) / n
            quads.append([(a, c, z), (b, c, z), (b, d, z), (a, d, z)])
            index.append((i + j) % 2)
    return _multi_material_mesh(name, quads, mats, index)


def _set_world(scene, color, strength=1.0):
    bg = scene.world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*color, 1.0)
    bg.inputs["Strength"].default_value = strength


def _comparison_defaults(scene):
    """64 x 64 pixels, DRT 512 and Cycles 1024 samples without adaptive sampling; every
    other setting stays Blender's default (Filter Glossy 1, caustics on, clamps)."""
    render_defaults(scene, size=COMPARISON_SIZE, samples=512)
    scene.cycles.samples = 1024
    scene.cycles.use_adaptive_sampling = False


def metals():
    """Three metal spheres (gold, copper, silver at roughness 0.1, 0.3, 0.6; Principled
    metallic 1) on a grey floor before a striped wall that they reflect, under a 2 m
    square area light."""
    scene = reset()
    floor = principled("Floor", (0.5, 0.5, 0.5), specular=0.0)
    quad("Floor", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)], floor)
    _stripes("Wall", -4.0, 4.0, 0.0, 4.0, 2.0, STRIPE_COLORS, 12)
    for x, rough, color in ((-1.15, 0.1, (1.0, 0.78, 0.34)), (0.0, 0.3, (0.95, 0.64, 0.54)),
                            (1.15, 0.6, (0.95, 0.95, 0.95))):
        mat = principled(f"Metal{rough}", color, roughness=rough, metallic=1.0)
        uv_sphere(f"Sphere{rough}", (x, 0.0, 0.5), 0.5, mat)
    _area_light(scene, (0.0, -2.5, 3.0), (0.0, 0.5, 0.0), 2.0, 3.0)
    camera(scene, (0.0, -4.2, 1.25), (math.radians(82.0), 0.0, 0.0), lens=50.0)
    _comparison_defaults(scene)
    return scene


def glossy_dielectric():
    """Plastic: Principled spheres with the default specular layer (IOR 1.5, Specular
    IOR Level 0.5) over red, green and blue diffuse base colours at roughness 0.15, 0.35
    and 0.7, on a grey plastic floor (roughness 0.25) before a striped wall, under a 2 m
    square area light."""
    scene = reset()
    floor = principled("Floor", (0.5, 0.5, 0.5), roughness=0.25)
    quad("Floor", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)], floor)
    _stripes("Wall", -4.0, 4.0, 0.0, 4.0, 2.0, STRIPE_COLORS, 12)
    for x, rough, color in ((-1.15, 0.15, (0.7, 0.08, 0.05)), (0.0, 0.35, (0.1, 0.55, 0.12)),
                            (1.15, 0.7, (0.08, 0.15, 0.7))):
        mat = principled(f"Plastic{rough}", color, roughness=rough)
        uv_sphere(f"Sphere{rough}", (x, 0.0, 0.5), 0.5, mat)
    _area_light(scene, (0.0, -2.5, 3.0), (0.0, 0.5, 0.0), 2.0, 3.0)
    camera(scene, (0.0, -4.2, 1.25), (math.radians(82.0), 0.0, 0.0), lens=50.0)
    _comparison_defaults(scene)
    return scene


def glass():
    """Glass (Principled, transmission 1, IOR 1.45) over a checker floor before a
    striped wall: a smooth sphere (roughness 0) with a pale blue base colour (Cycles
    tints each crossing by its square root) and a clear rough slab (roughness 0.3). Lit
    by a uniform sky (world colour x strength) alone: no lamps."""
    scene = reset()
    _checker("Floor", -2.0, 2.0, -2.0, 2.0, 0.0, [(0.8, 0.8, 0.8), (0.15, 0.15, 0.15)], 8)
    _stripes("Wall", -4.0, 4.0, 0.0, 4.0, 2.0, STRIPE_COLORS, 12)
    smooth = principled("GlassSmooth", (0.7, 0.85, 1.0), roughness=0.0)
    rough = principled("GlassRough", (1.0, 1.0, 1.0), roughness=0.3)
    for mat in (smooth, rough):
        bsdf = mat.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Transmission Weight"].default_value = 1.0
        bsdf.inputs["IOR"].default_value = 1.45
    uv_sphere("Sphere", (-0.6, 0.0, 0.55), 0.5, smooth)
    cuboid("Slab", (0.25, -0.45, 0.15), (1.05, 0.35, 0.45), rough, math.radians(20))
    camera(scene, (0.0, -3.2, 1.7), (math.radians(70.0), 0.0, 0.0), lens=50.0)
    _comparison_defaults(scene)
    _set_world(scene, (0.8, 0.9, 1.0), 1.0)
    return scene


def dof():
    """Depth of field: a 50 mm lens at f/0.4 (aperture radius 62.5 mm) with six blades,
    focused at 1.2 m (focus distance) on a block, a plastic sphere nearer (0.7 m) and one
    farther (2.1 m), a fine checker floor and a striped wall at 4.5 m; a 1.5 m square
    area light."""
    scene = reset()
    _checker("Floor", -2.0, 2.0, -0.5, 4.0, 0.0, [(0.85, 0.85, 0.85), (0.05, 0.05, 0.05)], 16)
    _stripes("Wall", -2.5, 2.5, 0.0, 2.5, 4.0, STRIPE_COLORS, 24)
    near = principled("Near", (0.75, 0.12, 0.08), roughness=0.35)
    uv_sphere("Near", (-0.22, 0.2, 0.12), 0.12, near)
    mid = principled("Mid", (0.85, 0.85, 0.8), roughness=0.5, specular=0.0)
    cuboid("Mid", (-0.1, 0.6, 0.0), (0.15, 0.85, 0.35), mid, math.radians(30))
    far = principled("Far", (0.1, 0.3, 0.8), roughness=0.35)
    uv_sphere("Far", (0.55, 1.6, 0.25), 0.25, far)
    _area_light(scene, (0.0, -1.0, 2.2), (0.0, 1.5, 0.0), 1.5, 3.0)
    cam = camera(scene, (0.0, -0.5, 0.45), (math.radians(82.0), 0.0, 0.0), lens=50.0)
    cam.data.dof.use_dof = True
    cam.data.dof.focus_distance = 1.2
    cam.data.dof.aperture_fstop = 0.4
    cam.data.dof.aperture_blades = 6
    cam.data.dof.aperture_rotation = 0.0
    _comparison_defaults(scene)
    return scene


def instances():
    """Instancing: a collection (a plastic block with a diffuse ball on it) that is not in
    the scene itself, instanced by 36 empties on a 6 x 6 grid with varied rotations and
    scales (two mirrored: negative X scale), and a row of 8 posts made by an Array
    modifier; a grey floor and a 2 m square area light."""
    scene = reset()
    floor = principled("Floor", (0.5, 0.5, 0.5), specular=0.0)
    quad("Floor", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)], floor)
    tile = bpy.data.collections.new("Tile")
    block = principled("Block", (0.7, 0.25, 0.1), roughness=0.4)
    ball = principled("Ball", (0.2, 0.5, 0.8), specular=0.0)
    for obj in (cuboid("TileBlock", (-0.12, -0.08, 0.0), (0.12, 0.08, 0.16), block),
                uv_sphere("TileBall", (0.06, 0.0, 0.24), 0.08, ball, 24, 12)):
        scene.collection.objects.unlink(obj)
        tile.objects.link(obj)
    for i in range(6):
        for j in range(6):
            e = bpy.data.objects.new(f"Inst{i}{j}", None)
            e.instance_type = "COLLECTION"
            e.instance_collection = tile
            e.location = (-1.25 + 0.5 * i, -0.6 + 0.45 * j, 0.0)
            e.rotation_euler = (0.0, 0.0, math.radians(17.0 * (i * 6 + j)))
            s = 0.8 + 0.08 * ((i + 2 * j) % 5)
            e.scale = (-s if (i, j) in ((1, 2), (4, 4)) else s, s, s)
            scene.collection.objects.link(e)
    white = principled("Post", (0.8, 0.8, 0.8), roughness=0.5, specular=0.0)
    post = cuboid("Posts", (-0.05, -0.05, 0.0), (0.05, 0.05, 0.5), white)
    post.location = (-1.75, 2.2, 0.0)
    arr = post.modifiers.new("Array", "ARRAY")
    arr.count = 8
    arr.relative_offset_displace = (5.0, 0.0, 0.0)
    _area_light(scene, (-1.0, -1.5, 3.0), (0.0, 0.8, 0.0), 2.0, 3.0)
    camera(scene, (0.0, -2.3, 2.4), (math.radians(48.0), 0.0, 0.0), lens=35.0)
    _comparison_defaults(scene)
    return scene


def world_light():
    """A diffuse sphere and block on a diffuse floor lit only by a uniform world
    background (colour (0.5, 0.7, 1.0) x strength 1.5); no lamps."""
    scene = reset()
    floor = principled("Floor", (0.6, 0.6, 0.6), specular=0.0)
    quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], floor)
    orange = principled("Orange", (0.8, 0.35, 0.1), specular=0.0)
    uv_sphere("Sphere", (-0.45, 0.0, 0.5), 0.5, orange)
    white = principled("White", (0.75, 0.75, 0.75), specular=0.0)
    cuboid("Block", (0.2, -0.3, 0.0), (0.8, 0.3, 0.8), white, math.radians(25))
    camera(scene, (0.0, -3.6, 2.6), (math.radians(55.0), 0.0, 0.0), lens=40.0)
    _comparison_defaults(scene)
    _set_world(scene, (0.5, 0.7, 1.0), 1.5)
    return scene


def ray_visibility():
    """Blender's defaults throughout (Filter Glossy 1, caustics on): a diffuse floor
    with three objects under four lamps hidden from the camera although in view: a point
    lamp (100 W, radius 0.05, Soft Falloff off), a spot, a sun and a disk lamp; the
    sphere casts no shadow, the block is hidden from the camera (its shadow stays) and
    the cylinder is invisible to diffuse rays (no light bounces off it)."""
    scene = reset()
    _comparison_defaults(scene)
    _set_world(scene, (0.02, 0.02, 0.02))
    floor = principled("Floor", (0.6, 0.6, 0.6), specular=0.0)
    quad("Floor", [(-5, -5, 0), (5, -5, 0), (5, 5, 0), (-5, 5, 0)], floor)
    orange = principled("Orange", (0.8, 0.35, 0.1), specular=0.0)
    sphere = uv_sphere("Sphere", (-0.9, 0.3, 0.5), 0.5, orange)
    sphere.visible_shadow = False
    white = principled("White", (0.75, 0.75, 0.75), specular=0.0)
    block = cuboid("Block", (0.3, 0.2, 0.0), (0.9, 0.8, 0.7), white, math.radians(20))
    block.visible_camera = False
    green = principled("Green", (0.15, 0.6, 0.15), specular=0.0)
    post = cuboid("Post", (-0.2, 1.2, 0.0), (0.2, 1.6, 1.4), green)
    post.visible_diffuse = False
    lamps = []
    point = bpy.data.lights.new("Point", "POINT")
    point.energy, point.shadow_soft_size, point.use_soft_falloff = 100.0, 0.05, False
    lamps.append((point, (0.2, -0.4, 0.6), None))
    spot = bpy.data.lights.new("Spot", "SPOT")
    spot.energy, spot.shadow_soft_size = 150.0, 0.1
    spot.spot_size, spot.spot_blend = math.radians(50.0), 0.3
    lamps.append((spot, (-1.5, -0.5, 2.0), (-0.9, 0.3, 0.0)))
    sun = bpy.data.lights.new("Sun", "SUN")
    sun.energy = 1.0
    lamps.append((sun, (2.0, -1.0, 3.0), (0.0, 0.0, 0.0)))
    disk = bpy.data.lights.new("Disk", "AREA")
    disk.shape, disk.size, disk.energy = "DISK", 0.5, 40.0
    lamps.append((disk, (1.3, -0.2, 1.1), (1.3, 0.4, 0.0)))
    for light, location, target in lamps:
        obj = bpy.data.objects.new(light.name, light)
        obj.location = location
        scene.collection.objects.link(obj)
        obj.visible_camera = False
        if target is not None:
            _aim(obj, target)
    camera(scene, (0.0, -4.0, 2.2), (math.radians(65.0), 0.0, 0.0), lens=32.0)
    return scene


def mirror_caustic():
    """Blender's defaults: a small area lamp lights a tilted metal plate (roughness 0.1,
    Multiscatter GGX) that throws its reflection onto a diffuse floor and wall (a
    reflective caustic, which Filter Glossy blurs); the camera sees the plate too."""
    scene = reset()
    _comparison_defaults(scene)
    grey = principled("Grey", (0.7, 0.7, 0.7), specular=0.0)
    quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], grey)
    quad("Wall", [(-3, 1.5, 0), (3, 1.5, 0), (3, 1.5, 3), (-3, 1.5, 3)], grey)
    metal = principled("Metal", (0.95, 0.95, 0.95), roughness=0.1, metallic=1.0)
    quad("Plate", [(-0.8, -0.2, 0.0), (0.8, -0.2, 0.0), (0.8, 0.6, 0.9), (-0.8, 0.6, 0.9)],
         metal)
    light = bpy.data.lights.new("Lamp", "AREA")
    light.size, light.energy = 0.3, 60.0
    obj = bpy.data.objects.new("Lamp", light)
    obj.location = (0.0, -1.5, 2.5)
    scene.collection.objects.link(obj)
    _aim(obj, (0.0, 0.2, 0.4))
    camera(scene, (0.0, -4.0, 2.2), (math.radians(70.0), 0.0, 0.0), lens=30.0)
    return scene


def glass_caustics():
    """Blender's defaults: a clear (roughness 0) and a frosted (0.25) glass sphere, IOR
    1.45, on a checker floor under a 2 m area lamp, black world: the caustics under the
    spheres come from lamp light through glass."""
    scene = reset()
    _comparison_defaults(scene)
    _checker("Floor", -4, 4, -4, 4, 0.0, [(0.8, 0.8, 0.8), (0.2, 0.2, 0.2)], 8)
    for x, rough in ((-0.7, 0.0), (0.7, 0.25)):
        mat = principled(f"Glass{rough}", (1.0, 1.0, 1.0), roughness=rough)
        node = mat.node_tree.nodes["Principled BSDF"]
        node.inputs["Transmission Weight"].default_value = 1.0
        node.inputs["IOR"].default_value = 1.45
        uv_sphere(f"Sphere{rough}", (x, 0.0, 0.6), 0.6, mat)
    light = bpy.data.lights.new("Lamp", "AREA")
    light.size, light.energy = 2.0, 500.0
    obj = bpy.data.objects.new("Lamp", light)
    obj.location = (0.0, 0.0, 4.0)
    scene.collection.objects.link(obj)
    camera(scene, (0.0, -4.5, 3.0), (math.radians(58.0), 0.0, 0.0), lens=40.0)
    return scene


def _node_material(name, kind, **inputs):
    """A material of one BSDF node of type `kind`, its other inputs and its
    distribution at Blender's defaults."""
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    node = nt.nodes.new(kind)
    for key, value in inputs.items():
        node.inputs[key].default_value = value
    nt.links.new(node.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    return mat


def node_closures():
    """Shader nodes as artists use them, at their own defaults: a Refraction BSDF
    (roughness 0.2, its default Beckmann distribution), a Glass BSDF (roughness 0.1,
    Multiscatter GGX), a dark Glossy BSDF (roughness 0.3: its colour at every angle, no
    Fresnel), a copper Principled metal and a black plastic with a Specular Tint, and a
    red Principled plastic with a coat; on a grey floor before a striped wall, lit by a
    uniform sky alone."""
    scene = reset()
    floor = principled("Floor", (0.5, 0.5, 0.5), specular=0.0)
    quad("Floor", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)], floor)
    _stripes("Wall", -4.0, 4.0, 0.0, 4.0, 2.0, STRIPE_COLORS, 12)
    tinted_metal = principled("TintedCopper", (0.95, 0.64, 0.54), roughness=0.25,
                              metallic=1.0)
    tinted_metal.node_tree.nodes["Principled BSDF"].inputs["Specular Tint"].default_value = (
        1.0, 0.35, 0.2, 1.0)
    tinted_plastic = principled("TintedPlastic", (0.03, 0.03, 0.03), roughness=0.2)
    tinted_plastic.node_tree.nodes["Principled BSDF"].inputs["Specular Tint"].default_value = (
        0.3, 0.6, 1.0, 1.0)
    coated = principled("Coated", (0.7, 0.08, 0.05), roughness=0.5)
    coated.node_tree.nodes["Principled BSDF"].inputs["Coat Weight"].default_value = 1.0
    materials = [
        _node_material("Refraction", "ShaderNodeBsdfRefraction", IOR=1.45, Roughness=0.2),
        _node_material("Glass", "ShaderNodeBsdfGlass", IOR=1.45, Roughness=0.1),
        _node_material("Glossy", "ShaderNodeBsdfGlossy", Color=(0.2, 0.12, 0.05, 1.0),
                       Roughness=0.3),
        tinted_metal, tinted_plastic, coated]
    for k, mat in enumerate(materials):           # two rows, the back one staggered
        x, y = -0.9 + 0.9 * (k % 3) + 0.45 * (k // 3), 1.0 * (k // 3)
        uv_sphere(f"Sphere{k}", (x, y, 0.36), 0.36, mat)
    camera(scene, (0.0, -3.6, 2.4), (math.radians(62.0), 0.0, 0.0), lens=45.0)
    _comparison_defaults(scene)
    _set_world(scene, (0.9, 0.9, 0.9), 1.0)
    return scene


COMPARISON_SCENES = {f.__name__: f for f in (
    metals, glossy_dielectric, glass, dof, instances, world_light, ray_visibility,
    mirror_caustic, glass_caustics, node_closures)}
SCENES.update(COMPARISON_SCENES)


HDRI_SIZE = (256, 128)
SUN_AZIMUTH, SUN_ELEVATION, SUN_RADIUS = 40.0, 35.0, 2.0      # degrees, in the image
SUN_RADIANCE = (2000.0, 1900.0, 1700.0)


def sky_pixels(width, height):
    """A procedural sky as an equirectangular RGBA float image (height, width, 4), rows
    bottom-up as Blender stores them: a horizon-to-zenith gradient warmer towards the
    sun, a dark ground below the horizon and a small, very bright sun disc (radius
    SUN_RADIUS degrees, about three texels across) at (SUN_AZIMUTH, SUN_ELEVATION).
    Directions follow Blender's equirectangular mapping: phi = pi - 2 pi u from +X
    towards +Y, elevation (v - 1/2) pi."""
    import numpy as np
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    phi = np.pi - 2.0 * np.pi * u[None, :]
    el = (v[:, None] - 0.5) * np.pi
    d = np.stack(np.broadcast_arrays(np.cos(el) * np.cos(phi), np.cos(el) * np.sin(phi),
                                     np.sin(el)), axis=-1)
    az, alt = math.radians(SUN_AZIMUTH), math.radians(SUN_ELEVATION)
    sun = np.array([math.cos(alt) * math.cos(az), math.cos(alt) * math.sin(az), math.sin(alt)])
    cos_sun = d @ sun
    t = np.sqrt(np.clip(np.sin(el), 0.0, 1.0))[..., None]
    zenith, horizon = np.array([0.15, 0.3, 0.8]), np.array([0.8, 0.75, 0.7])
    rgb = horizon * (1.0 - t) + zenith * t
    rgb = rgb + np.array([0.6, 0.35, 0.1]) * (((1.0 + cos_sun) / 2.0) ** 6)[..., None]
    rgb = np.where((el < 0.0)[..., None], np.array([0.12, 0.1, 0.08]), rgb)
    rgb = np.where((cos_sun > math.cos(math.radians(SUN_RADIUS)))[..., None],
                   np.array(SUN_RADIANCE), rgb)
    out = np.ones((height, width, 4), dtype=np.float32)
    out[..., :3] = rgb
    return out


def _packed_sky(name):
    """The sky as an OpenEXR image packed into the .blend (its path '//NAME.exr')."""
    import tempfile
    w, h = HDRI_SIZE
    img = bpy.data.images.new(name, w, h, float_buffer=True)
    img.pixels.foreach_set(sky_pixels(w, h).ravel())
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, f"{name}.exr")
        img.filepath_raw = path
        img.file_format = "OPEN_EXR"
        img.save()
        bpy.data.images.remove(img)
        img = bpy.data.images.load(path)
        img.pack()
    img.filepath_raw = f"//{name}.exr"
    img.colorspace_settings.name = "Linear Rec.709"
    return img


def _two_spheres_on_floor():
    """A diffuse and a glossy metal sphere (roughness 0.25) on a diffuse floor, seen
    from -Y, at the comparison defaults; the world is left to the caller."""
    scene = reset()
    _comparison_defaults(scene)
    grey = principled("Floor", (0.6, 0.6, 0.6), specular=0.0)
    quad("Floor", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)], grey)
    clay = principled("Clay", (0.8, 0.45, 0.25), specular=0.0)
    uv_sphere("Diffuse", (-0.6, 0.0, 0.5), 0.5, clay)
    metal = principled("Metal", (0.9, 0.9, 0.9), roughness=0.25, metallic=1.0)
    uv_sphere("Glossy", (0.6, 0.0, 0.5), 0.5, metal)
    camera(scene, (0.0, -4.0, 1.6), (math.radians(75.0), 0.0, 0.0), lens=35.0)
    return scene


def hdri_world():
    """Blender's defaults: a diffuse sphere and a glossy metal sphere (roughness 0.25)
    on a diffuse floor, lit only by an environment map (a procedural sky with a small,
    very bright sun, `sky_pixels`, packed as OpenEXR) through a Mapping node that turns
    it 60 degrees about Z."""
    scene = _two_spheres_on_floor()
    tree = scene.world.node_tree
    bg = tree.nodes["Background"]
    env = tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = _packed_sky("hdri_world_sky")
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(60.0))
    coords = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    tree.links.new(env.outputs["Color"], bg.inputs["Color"])
    bg.inputs["Strength"].default_value = 1.0
    return scene


SCENES["hdri_world"] = hdri_world


def sky_world():
    """A diffuse and a glossy metal sphere (roughness 0.25) on a diffuse floor, lit
    only by a Sky Texture at Blender's defaults (Multiple Scattering, sun 15 degrees up
    along +Y, in front of the camera and just above its view), 64 x 64."""
    scene = _two_spheres_on_floor()
    tree = scene.world.node_tree
    sky = tree.nodes.new("ShaderNodeTexSky")
    tree.links.new(sky.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    return scene


SCENES["sky_world"] = sky_world


def _artist_scenes():
    """sample_blends/artist_scenes.py's, volume_scenes.py's, subsurface_scenes.py's,
    light_tree_scenes.py's and displacement_scenes.py's scenes (which use this module's
    helpers)."""
    sys.path.insert(0, HERE)
    import artist_scenes
    import displacement_scenes
    import light_tree_scenes
    import subsurface_scenes
    import volume_scenes
    return {**artist_scenes.SCENES, **volume_scenes.SCENES, **subsurface_scenes.SCENES,
            **light_tree_scenes.SCENES, **displacement_scenes.SCENES}


if __name__ == "__main__":
    SCENES.update(_artist_scenes())


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("names", nargs="*", help=f"scenes to build (default all: {', '.join(SCENES)})")
    p.add_argument("--out-dir", default=HERE)
    args = p.parse_args(argv)
    names = args.names or list(SCENES)
    for name in names:
        if name not in SCENES:
            p.error(f"unknown scene {name!r}")
        SCENES[name]()
        path = os.path.join(os.path.abspath(args.out_dir), f"{name}.blend")
        # The small light scenes are stored compressed (86 KB instead of 440 KB each).
        bpy.ops.wm.save_as_mainfile(filepath=path, compress=name in LIGHT_SCENES
                                    or name in MOTION_SCENES)
        if bpy.data.volumes:          # their OpenVDB files, named relative to the .blend
            bpy.ops.file.make_paths_relative()
            bpy.ops.wm.save_mainfile()
            if os.path.exists(path + "1"):       # the backup Blender keeps of the first save
                os.remove(path + "1")
        print(f"built {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
