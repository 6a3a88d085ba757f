"""Run inside a Blender binary (`blender -b --python THIS -- OUT.blend`) by
tests/test_debian_blender.py: enables the DRT legacy add-on in the preferences (saved in
BLENDER_USER_CONFIG, as on a render-farm worker), builds a tiny scene with this Blender
(a .blend saved by a newer Blender does not open in 3.4) and saves it to OUT.blend.

The scene, 32 x 24 pixels, 4 DRT samples (Whitted integrator), frames 1-2: a large grey plane
(smooth shaded, so its normals are read per corner), a red cube
(Principled BSDF) that moves from x = 0 (frame 1) to x = 1 (frame 2), an area lamp above
it, a black world, and a camera looking slightly down so that the image's top rows see
only the black sky. Prints `DRT-PYTHON major.minor` first, so that the test can tell a
Python its packages do not fit from a failure, and last `DRT-CORNER-NORMALS min max`: the
lengths of the plane's corner normals as DRT's exporter reads them in this Blender.
"""
import importlib
import sys

import addon_utils
import bpy
import numpy as np

print(f"DRT-PYTHON {sys.version_info[0]}.{sys.version_info[1]}", flush=True)
out = sys.argv[sys.argv.index("--") + 1]

addon_utils.enable("drt", default_set=True, handle_error=None)
if "DRT" not in {e.bl_idname for e in bpy.types.RenderEngine.__subclasses__()}:
    raise SystemExit("DRT-ERROR the DRT add-on did not register")
bpy.ops.wm.save_userpref()

for ob in list(bpy.data.objects):
    bpy.data.objects.remove(ob)
scene = bpy.context.scene

bpy.ops.mesh.primitive_plane_add(size=20)
bpy.ops.object.shade_smooth()    # read through the corner normals (same look as flat)
plane = bpy.context.object
bpy.ops.mesh.primitive_cube_add(size=1, location=(0, 0, 0.5))
cube = bpy.context.object
red = bpy.data.materials.new("Red")
red.use_nodes = True
red.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.05, 0.05, 1)
cube.data.materials.append(red)
for frame, x in ((1, 0.0), (2, 1.0)):
    cube.location.x = x
    cube.keyframe_insert("location", index=0, frame=frame)

bpy.ops.object.light_add(type="AREA", location=(0, 0, 3))
bpy.context.object.data.energy = 150
bpy.ops.object.camera_add(location=(0, -6, 2), rotation=(1.396, 0, 0))   # 10 degrees down
scene.camera = bpy.context.object

world = scene.world or bpy.data.worlds.new("World")
scene.world = world
world.color = (0, 0, 0)
if world.use_nodes and "Background" in world.node_tree.nodes:
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)

r = scene.render
r.engine = "DRT"
r.resolution_x, r.resolution_y, r.resolution_percentage = 32, 24, 100
r.image_settings.file_format = "PNG"
r.image_settings.color_mode = "RGB"
scene.view_settings.view_transform = "Standard"
scene.drt.samples = 4
# Whitted: the compiled path tracer's kernels take minutes to compile in a fresh checkout
# (the bpy-module tests cover it); Whitted's compile in seconds and still trace through
# Embree, shade the exported materials and lights, and report progress the same way.
scene.drt.integrator = "whitted"
scene.frame_start, scene.frame_end, scene.frame_current = 1, 2, 1
bpy.ops.wm.save_as_mainfile(filepath=out)
print(f"DRT-SCENE {out}", flush=True)

# The exporter's corner normals of the smooth plane, read in this Blender (unit length when
# read right; Blender before 4.1 leaves them zero unless asked to compute them).
mesh_export = importlib.import_module("drt.drt_addon.export.mesh")
evaluated = plane.evaluated_get(bpy.context.evaluated_depsgraph_get())
normals = mesh_export.mesh_arrays(evaluated.to_mesh())[3]
lengths = np.linalg.norm(normals.reshape(-1, 3), axis=1)
print(f"DRT-CORNER-NORMALS {lengths.min():.4f} {lengths.max():.4f}", flush=True)
evaluated.to_mesh_clear()
