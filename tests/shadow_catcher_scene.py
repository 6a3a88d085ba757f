"""The shadow catcher comparison scene of tests/test_shadow_catcher_vs_cycles.py and
docs/make_shadow_catcher_docs.py, built in Blender with its defaults: a floor plane that
is a shadow catcher (Object > Visibility > Shadow Catcher), an orange cube and a grey
sphere resting on it, a sun (Blender's default angle) and a fill area lamp that is no
shadow catcher, under a blue-grey world; Film > Transparent and the Shadow Catcher pass
as asked."""
from __future__ import annotations

import math

from light_pass_scene import _add, _principled, empty_scene


def build(bpy, size=(64, 48), samples=64, transparent=True, catcher_pass=True):
    scene = empty_scene(bpy, size, samples, (0.3, 0.35, 0.45))
    scene.render.film_transparent = transparent
    floor = _add(bpy, "primitive_plane_add",
                 _principled(bpy, "floor", **{"Base Color": (0.6, 0.6, 0.6, 1.0)}), size=8.0)
    floor.is_shadow_catcher = True
    _add(bpy, "primitive_cube_add",
         _principled(bpy, "orange", **{"Base Color": (0.8, 0.35, 0.1, 1.0)}), size=1.0,
         location=(0.6, 0.3, 0.5))
    _add(bpy, "primitive_uv_sphere_add",
         _principled(bpy, "grey", **{"Base Color": (0.5, 0.5, 0.5, 1.0)}), radius=0.45,
         location=(-0.9, -0.2, 0.45))
    bpy.ops.object.shade_smooth()
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(40), 0.0, math.radians(30))
    scene.collection.objects.link(sun)
    fill = bpy.data.objects.new("Fill", bpy.data.lights.new("Fill", "AREA"))
    fill.data.energy, fill.data.size = 60.0, 1.0
    fill.location = (-2.0, -2.0, 2.5)
    fill.rotation_euler = (math.radians(40), 0.0, math.radians(-45))
    fill.is_shadow_catcher = False
    scene.collection.objects.link(fill)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, -6.0, 3.0)
    cam.rotation_euler = (math.radians(68), 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.view_layers[0].cycles.use_pass_shadow_catcher = catcher_pass
    bpy.context.view_layer.update()
    return scene
