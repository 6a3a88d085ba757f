"""Tangent-space Normal Maps against Cycles on what artists' meshes hold: n-gons, no UV
map, a non-uniform scale and smooth normals that fan out (a tube's end ring, averaged
with its cap). Found in OddBitWizard's tunnel.blend (a 32-sided tube scaled 10 times
along its axis, whose road and brick materials read pink, missing normal maps), which
rendered 8.8 % brighter than Cycles with a worst 8 x 8 block of 396 %.

What Cycles does there (scene/mesh.cpp, kernel/svm/tex_coord.h), and DRT now too:
- tangents by MikkTSpace on the render triangles, so an n-gon has them, and on a mesh
  without a UV map from map_to_sphere of the object-space positions
  (drt_addon/export/mikktspace.py; Blender's calc_tangents refused both);
- the tangent and the smooth normal interpolated in object space and not normalised
  (engine/nodes/tangent_frame.py);
- a mesh that true displacement moves stays in its object space, so its smooth normals
  are interpolated there before they reach the world (export/mesh.py
  cycles_applies_transform), with or without a Normal Map.
The MikkTSpace tangents alone against Blender's: test_mikktspace.py."""
from __future__ import annotations

import math

import pytest

import node_probe
from node_probe import drt_against_cycles, new_material, new_scene

SAMPLES = 64


def _tube_scene(bpy, method="BUMP", uv=True, normal_map=True):
    """A 32-sided tube with an n-gon cap at one end (open at the other, so its smooth
    normals fan out at one end only), shaded smooth, scaled 4 times along its axis and
    laid across the view, the cap towards the camera, under a sun from above the camera. Its Principled BSDF's
    Normal comes from a tangent-space Normal Map of a constant colour that tilts it far
    (2c - 1 = (0.7, -0.5, 0.8)). method: Bump Only, or Displacement and Bump with a
    Displacement node at its mid-level (true displacement that moves nothing); uv=False
    removes the UV map."""
    import bmesh
    from mathutils import Vector
    scene = new_scene(bpy, 96)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.1
    bpy.ops.mesh.primitive_cylinder_add(vertices=32, radius=0.5, depth=1.0)
    tube = bpy.context.object
    bm = bmesh.new()                      # open at one end, as the tunnel is
    bm.from_mesh(tube.data)
    bmesh.ops.delete(bm, geom=[f for f in bm.faces if len(f.verts) > 4
                               and f.calc_center_median().z > 0.0], context="FACES_ONLY")
    bm.to_mesh(tube.data)
    bm.free()
    bpy.ops.object.shade_smooth()
    tube.scale = (1.0, 1.0, 4.0)
    tube.rotation_euler = (0.0, math.radians(90.0), math.radians(25.0))
    if not uv:
        while tube.data.uv_layers:
            tube.data.uv_layers.remove(tube.data.uv_layers[0])
    mat, nt = new_material(bpy, "Mapped")
    mat.displacement_method = method
    nt.nodes["Principled BSDF"].inputs["Roughness"].default_value = 0.35
    if normal_map:
        colour = nt.nodes.new("ShaderNodeRGB")
        colour.outputs[0].default_value = (0.85, 0.25, 0.9, 1.0)
        nmap = nt.nodes.new("ShaderNodeNormalMap")
        nt.links.new(colour.outputs[0], nmap.inputs["Color"])
        nt.links.new(nmap.outputs["Normal"], nt.nodes["Principled BSDF"].inputs["Normal"])
    if method != "BUMP":
        disp = nt.nodes.new("ShaderNodeDisplacement")
        disp.inputs["Height"].default_value = 0.5          # the mid-level: no offset
        nt.links.new(disp.outputs["Displacement"],
                     nt.nodes["Material Output"].inputs["Displacement"])
    tube.data.materials.append(mat)
    location = Vector((3.0, -6.0, 2.4))
    view = (-location).to_track_quat("-Z", "Y").to_euler()
    node_probe.sun_and_camera(bpy, scene, 3.0, 0.05, (view.x - 0.5, view.y, view.z + 0.6),
                              location, view)
    return scene


CASES = {
    "uv_map": dict(),
    "no_uv_map": dict(uv=False),
    "true_displacement": dict(method="BOTH"),
    "true_displacement_without_map": dict(method="BOTH", normal_map=False),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_normal_map_on_a_scaled_ngon_tube_matches_cycles(bpy_drt, case):
    """The tube (_tube_scene) in four forms, DRT against Cycles at 64 samples each: mean
    within 1 %, largest 8 x 8 block within 3 %. Measured: means 0.08-0.09 %, largest
    blocks 2.26 % (uv_map, no_uv_map), 2.28 % (true_displacement), 2.40 %
    (true_displacement_without_map). Before (Blender's tangents, which the n-gon cap
    left out, so no map at all; world normals normalised per corner under true
    displacement): mean 178 %, largest block 1765 % with the map; 1.20 % and 12.6 %
    without it. On the tunnel's own tube with a plain Principled BSDF and this kind of
    map, the tangents already MikkTSpace's, the frame interpolated in the world and
    normalised gave mean -2.8 %, largest block 23.5 % (320 pixels, DRT 64 against Cycles
    256 samples); 0.0 % and 1.0 % now."""
    scene = _tube_scene(bpy_drt, **CASES[case])
    mean, block = drt_against_cycles(bpy_drt, scene, SAMPLES)
    print(f"tube, {case}: mean {mean:.2%}, largest block {block:.2%}")
    assert mean < 0.01 and block < 0.03, (mean, block)
