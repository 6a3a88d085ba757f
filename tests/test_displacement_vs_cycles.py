"""True displacement (Material > Settings > Displacement: Displacement Only, Displacement
and Bump) against Cycles at its defaults, and what it costs scenes without it. The engine
side alone: test_displacement.py.

The plane: a 6 m plane, Subdivision (Simple, 7 levels), scaled and turned (the
Displacement node's default Object space then differs from World), displaced by a Noise
Texture at its default (Generated) coordinates through a Displacement node (Scale 0.5),
coloured by the same noise through a Color Ramp, under a low sun. The surface must move
(its silhouette and shadows), read its colour at the undisplaced point (Generated
coordinates, as Cycles' generated attribute) and, for Displacement and Bump, bend its
normal as Cycles' bump evaluation does on the undisplaced surface. The control, the same
material as Bump Only (what DRT rendered before), fails.

The sample scene: sample_blends/displacement.blend, a cobbled path (Voronoi -> Color Ramp
-> Displacement, Displacement Only) and a rock (Noise, Displacement and Bump) at sunset;
docs/displacement.md shows it."""
from __future__ import annotations

import os

import numpy as np
import pytest

import node_probe
from conftest import render_blend
from node_probe import image_errors, new_material, new_scene
from test_artist_scenes_vs_cycles import _agrees

SAMPLES = 64
SAMPLES_DIR = os.path.join(os.path.dirname(os.path.dirname(__file__)), "sample_blends")
SCENE_CYCLES_SAMPLES = 1024
SCENE_DRT_SAMPLES = 512


def _plane_scene(bpy, method, coordinates=None, vector=False, flat=False):
    """The plane (the module's docstring); coordinates: a Texture Coordinate output for
    the noise (None: its default); vector: a Vector Displacement node (Tangent space) of
    the noise's Color instead of a Displacement node; flat: flat shaded (Displacement and
    Bump then bumps from the undisplaced vertex normals, and no shadow ray is lifted)."""
    scene = new_scene(bpy, 96)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.1
    bpy.ops.mesh.primitive_plane_add(size=6.0)
    plane = bpy.context.object
    plane.scale = (1.0, 0.8, 1.2)
    plane.rotation_euler = (0.0, 0.0, 0.3)
    mod = plane.modifiers.new("Subdivision", "SUBSURF")
    mod.subdivision_type = "SIMPLE"
    mod.levels = mod.render_levels = 7
    if not flat:
        bpy.ops.object.shade_smooth()
    mat, nt = new_material(bpy, "Displaced")
    mat.displacement_method = method
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Roughness"].default_value = 0.4
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 2.0
    if coordinates is not None:
        coords = nt.nodes.new("ShaderNodeTexCoord")
        nt.links.new(coords.outputs[coordinates], noise.inputs["Vector"])
    if vector:
        disp = nt.nodes.new("ShaderNodeVectorDisplacement")
        disp.inputs["Scale"].default_value = 0.4
        nt.links.new(noise.outputs["Color"], disp.inputs["Vector"])
    else:
        disp = nt.nodes.new("ShaderNodeDisplacement")
        disp.inputs["Scale"].default_value = 0.5
        nt.links.new(noise.outputs["Fac"], disp.inputs["Height"])
    nt.links.new(disp.outputs["Displacement"], nt.nodes["Material Output"].inputs["Displacement"])
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    nt.links.new(noise.outputs["Fac"], ramp.inputs["Fac"])
    nt.links.new(ramp.outputs["Color"], bsdf.inputs["Base Color"])
    plane.data.materials.append(mat)
    node_probe.sun_and_camera(bpy, scene, 3.0, 0.05, (1.1, 0.3, 0.5), (0.0, -5.0, 3.5),
                              (0.98, 0.0, 0.0))
    return scene, mat


# (method, texture coordinates (None: the noise's default), Vector Displacement, flat
# shading, mean tolerance, block tolerance)
PLANE_CASES = [
    ("DISPLACEMENT", None, False, False, 0.01, 0.03),
    ("BOTH", None, False, False, 0.01, 0.03),
    ("BOTH", "Object", False, False, 0.01, 0.03),
    ("DISPLACEMENT", None, True, False, 0.01, 0.03),
    ("BOTH", None, False, True, 0.01, 0.03),
]


@pytest.mark.parametrize("method, coordinates, vector, flat, mean_tol, block_tol",
                         PLANE_CASES)
def test_displacement_matches_cycles(bpy_drt, method, coordinates, vector, flat, mean_tol,
                                     block_tol):
    """Measured (DRT and Cycles at 64 samples, of the image mean): see the module's
    numbers in docs/displacement.md. The control, the material in Bump Only mode, has
    blocks off by more than 10 %."""
    bpy = bpy_drt
    scene, mat = _plane_scene(bpy, method, coordinates, vector, flat)
    cycles = node_probe.render(bpy, scene, "CYCLES", SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", SAMPLES)
    mean, block = image_errors(drt, cycles)
    mat.displacement_method = "BUMP"
    control = image_errors(node_probe.render(bpy, scene, "DRT", SAMPLES), cycles,
                           "control: Bump Only")
    print(f"{method} {coordinates or 'Generated'}{' vector' if vector else ''}"
          f"{' flat' if flat else ''}: mean "
          f"{mean:.2%}, largest block {block:.2%}; as Bump Only: mean {control[0]:.2%}, "
          f"largest block {control[1]:.2%}")
    assert mean < mean_tol and block < block_tol, (mean, block)
    assert control[1] > 0.1, control


def test_only_scenes_with_true_displacement_pay_for_it(bpy_drt):
    """Bump Only (Blender's default): no mesh is moved, no vertex normals or undisplaced
    corners are read. Displacement Only: the plane moves, and a grid with two users
    (linked duplicates, instanced) moves once, in object space, for both of its places,
    as Cycles displaces a mesh once."""
    bpy = bpy_drt
    from drt_addon.export import export_scene
    scene, mat = _plane_scene(bpy, "BUMP")
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=60, y_subdivisions=60, size=2.0,
                                    location=(0.0, 5.0, 0.0))
    grid = bpy.context.object
    grid.data.materials.append(mat)
    twin = bpy.data.objects.new("Twin", grid.data)
    twin.location = (3.0, 5.0, 0.0)
    scene.collection.objects.link(twin)
    stats = {}
    bump = export_scene(bpy.context.evaluated_depsgraph_get(), stats=stats)
    assert stats["displaced_meshes"] == 0
    assert all(m.undisplaced is None for m in bump.meshes)
    assert all(m.displacement is None for m in bump.materials)
    mat.displacement_method = "DISPLACEMENT"
    stats = {}
    moved = export_scene(bpy.context.evaluated_depsgraph_get(), stats=stats)
    assert stats["displaced_meshes"] == 2, stats          # the plane, and the grid once
    placed = [m for m in moved.meshes if m.instances is not None]
    assert len(placed) == 1 and len(placed[0].instances) == 2
    for m in moved.meshes:
        assert m.undisplaced is not None
        assert np.ptp(m.positions[:, 2]) > 0.1, np.ptp(m.positions[:, 2])   # no longer flat


def test_displacement_scene_matches_cycles(bpy_drt):
    """sample_blends/displacement.blend (64 x 48, DRT 512 against Cycles 1024 samples):
    means within 1 % per channel, every 8 x 8 block within 3 % of the image mean. The
    control, both materials as Bump Only, fails."""
    bpy = bpy_drt
    path = os.path.join(SAMPLES_DIR, "displacement.blend")
    cycles = render_blend(bpy, path, "CYCLES", SCENE_CYCLES_SAMPLES, percentage=100)
    drt = render_blend(bpy, path, "DRT", SCENE_DRT_SAMPLES, percentage=100)
    assert _agrees("displacement", drt, cycles)

    def bump_only(scene):
        for m in bpy.data.materials:
            m.displacement_method = "BUMP"
    control = render_blend(bpy, path, "DRT", 128, percentage=100, setup=bump_only)
    assert not _agrees("displacement as Bump Only (control)", control, cycles)


def _adaptive_plane(bpy, method, levels=2):
    """The plane at Subdivision render levels `levels`, with Adaptive Subdivision on at
    Blender's defaults (Pixel space, Pixel Size 1, Dicing Rate 1, Max Subdivisions 12)."""
    scene, mat = _plane_scene(bpy, method)
    mod = bpy.data.objects["Plane"].modifiers["Subdivision"]
    mod.levels = mod.render_levels = levels
    mod.use_adaptive_subdivision = True
    return scene, mat, mod


def test_adaptive_subdivision_matches_cycles(bpy_drt):
    """The plane at render levels 2 (4 x 4 quads) with Adaptive Subdivision: Cycles dices
    it to about a pixel, and so does DRT (DRT and Cycles at 64 samples, of the image
    mean: means within 1 %, blocks within 3 %). The control, adaptive subdivision off in
    DRT alone (the render levels, as DRT rendered it before), fails."""
    bpy = bpy_drt
    scene, mat, mod = _adaptive_plane(bpy, "BOTH")
    cycles = node_probe.render(bpy, scene, "CYCLES", SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", SAMPLES)
    mean, block = image_errors(drt, cycles)
    mod.use_adaptive_subdivision = False
    control = image_errors(node_probe.render(bpy, scene, "DRT", SAMPLES), cycles,
                           "control: the render levels, not diced")
    print(f"adaptive subdivision: mean {mean:.2%}, largest block {block:.2%}; at the "
          f"render levels: mean {control[0]:.2%}, largest block {control[1]:.2%}")
    assert mean < 0.01 and block < 0.03, (mean, block)
    assert control[1] > 0.1, control


def _export(bpy, view=None):
    from drt_addon.export import Reporter, export_scene
    stats, reporter = {}, Reporter()
    scene = export_scene(bpy.context.evaluated_depsgraph_get(), reporter, stats=stats,
                         view=view)
    return scene, stats, reporter.warnings


def test_adaptive_subdivision_dices_displaced_meshes_alone_by_the_files_settings(bpy_drt):
    """Only a mesh that its material moves is diced (Bump Only leaves the render levels'
    32 triangles); its triangles follow the Pixel Size and the Dicing Rate (4 times the
    segment length: about 16 times fewer), Max Subdivisions caps the segments of an edge
    of the cage (3 levels: 8, 2 per edge of the level-2 mesh), and in Object space the
    undisplaced mesh's edges are Edge Length long (a grid's diagonals and the stitches
    between grids of other factors up to 1.5 times). The Rendered viewport dices
    to the Viewport rate. No warning names it any more."""
    bpy = bpy_drt
    scene, mat, mod = _adaptive_plane(bpy, "BUMP")
    exported, stats, warnings = _export(bpy)
    assert stats["diced_meshes"] == 0 and stats["triangles"] == 32
    mat.displacement_method = "DISPLACEMENT"
    exported, stats, warnings = _export(bpy)
    fine = stats["triangles"]
    assert stats["diced_meshes"] == 1 and fine > 5000, stats
    assert not any("adaptive" in w for w in warnings), warnings
    mod.adaptive_pixel_size = 4.0
    coarse = _export(bpy)[1]["triangles"]
    assert fine / 32 < coarse < fine / 8, (fine, coarse)
    mod.adaptive_pixel_size = 1.0
    scene.cycles.dicing_rate = 4.0
    assert _export(bpy)[1]["triangles"] == coarse
    scene.cycles.dicing_rate = 1.0
    scene.cycles.max_subdivisions = 3
    assert _export(bpy)[1]["triangles"] == 32 * 4
    scene.cycles.max_subdivisions = 12
    mod.adaptive_space = "OBJECT"
    mod.adaptive_object_edge_length = 0.25
    exported, stats, _ = _export(bpy)
    local = exported.meshes[0].undisplaced.astype(np.float64)     # object space
    longest = np.linalg.norm(local - np.roll(local, -1, axis=1), axis=2).max()
    assert 0.25 < longest <= 0.25 * 1.5, longest      # the grid's diagonals: 0.35
    view = (exported.camera, 96, 96)
    from drt_addon.export.dicing import SceneDicing
    dicing = SceneDicing(bpy.context.evaluated_depsgraph_get(), view)
    assert dicing.rate == scene.cycles.preview_dicing_rate == 8.0
    mod.adaptive_space = "PIXEL"
    in_view = _export(bpy, view)[1]["triangles"]
    assert in_view < coarse, (in_view, coarse)            # 8 px in the viewport, not 4


@pytest.mark.parametrize("adaptive", [False, True])
def test_a_deforming_displaced_mesh_moves_its_displacement_along(bpy_drt, adaptive):
    """Motion blur of a mesh that deforms (a shape key) and is displaced: every time step
    carries the same offsets, as Cycles adds them to its motion steps, so the steps differ
    by the deformation alone (1 m along x over the shutter). Diced by adaptive
    subdivision, its new vertices follow the deformation too."""
    from engine.motion import DeformMotion
    from test_motion_blender import CUBE, _mesh, _shape_key_motion
    bpy = bpy_drt
    from drt_addon.export import export_scene
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    _shape_key_motion(bpy.context.scene)
    cube = bpy.data.objects["Cube"]
    sub = cube.modifiers.new("Subdivision", "SUBSURF")
    sub.subdivision_type = "SIMPLE"
    sub.levels = sub.render_levels = 3
    sub.use_adaptive_subdivision = adaptive
    mat, nt = new_material(bpy, "Displaced")
    mat.displacement_method = "DISPLACEMENT"
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 4.0
    disp = nt.nodes.new("ShaderNodeDisplacement")
    disp.inputs["Scale"].default_value = 0.2
    nt.links.new(noise.outputs["Fac"], disp.inputs["Height"])
    nt.links.new(disp.outputs["Displacement"], nt.nodes["Material Output"].inputs["Displacement"])
    cube.data.materials.clear()
    cube.data.materials.append(mat)
    mesh = _mesh(export_scene(bpy.context.evaluated_depsgraph_get()), "Cube")
    assert isinstance(mesh.motion, DeformMotion) and mesh.undisplaced is not None
    assert (len(mesh.triangles) > 12 * 4 ** 3 * 2) == adaptive      # diced finer
    steps = mesh.motion.positions
    np.testing.assert_allclose(steps[1], mesh.positions, atol=1e-6)
    for k, dx in ((0, -0.5), (2, 0.5)):
        np.testing.assert_allclose(steps[k] - steps[1],
                                   np.tile([dx, 0.0, 0.0], (len(steps[1]), 1)),
                                   atol=1e-5)
    # the displacement itself is there: the cube's faces are no longer flat
    assert np.ptp(np.abs(steps[1] - steps[1].mean(axis=0)).max(axis=1)) > 0.02


def _normal_map(nt):
    """The Principled BSDF's Normal from a tangent-space Normal Map of a constant colour
    whose 2c - 1 is not of unit length, at Strength 0.6."""
    colour = nt.nodes.new("ShaderNodeRGB")
    colour.outputs[0].default_value = (0.75, 0.4, 0.85, 1.0)
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nmap.inputs["Strength"].default_value = 0.6
    nt.links.new(colour.outputs[0], nmap.inputs["Color"])
    nt.links.new(nmap.outputs["Normal"], nt.nodes["Principled BSDF"].inputs["Normal"])


def _tilted_faces_scene(bpy):
    """A flat-shaded cube cut into 4 x 4 quads a side (Subdivision, Simple, 2 levels),
    moved 0.15 m along its vertex normals by a constant Displacement (Displacement and
    Bump): the vertices on its edges move diagonally, those inside a side straight out,
    so the quads along the edges tilt, as a displaced ceiling's edge faces tilt where a
    wall meets it. Its Principled BSDF's Normal comes from a tangent-space Normal Map of
    a constant colour whose 2c - 1 is not of unit length, at Strength 0.6."""
    scene = new_scene(bpy, 96)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.1
    bpy.ops.mesh.primitive_cube_add(size=2.0)
    cube = bpy.context.object
    cube.rotation_euler = (0.0, 0.0, 0.5)
    mod = cube.modifiers.new("Subdivision", "SUBSURF")
    mod.subdivision_type = "SIMPLE"
    mod.levels = mod.render_levels = 2
    mat, nt = new_material(bpy, "Tilted")
    mat.displacement_method = "BOTH"
    disp = nt.nodes.new("ShaderNodeDisplacement")
    disp.inputs["Height"].default_value = 1.0
    disp.inputs["Scale"].default_value = 0.3
    nt.links.new(disp.outputs["Displacement"], nt.nodes["Material Output"].inputs["Displacement"])
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Roughness"].default_value = 0.35
    _normal_map(nt)
    cube.data.materials.append(mat)
    node_probe.sun_and_camera(bpy, scene, 3.0, 0.05, (0.9, 0.2, 2.2), (3.2, -4.2, 3.0),
                              (1.05, 0.0, 0.65))
    return scene


def test_normal_map_on_flat_faces_displacement_tilted_matches_cycles(bpy_drt):
    """On a face shaded flat Cycles builds a tangent-space Normal Map on the face's own
    normal (sd->Ng), not on the undisplaced vertex normals its bump leaves as the
    shading normal there; and it applies Strength to the map's colour (x and y scaled, z
    mixed from 1), not by blending the result towards the normal; nor does it lift
    shadow rays off flat faces. Measured (512 samples each): mean 0.04 %, largest block
    1.3 % (a silhouette's; at 256 samples DRT's block alone, against Cycles at 4096,
    ranged 1.5 to 3.5 % over seeds 0-3, which a 3 % bound against Cycles' own 256 did
    not allow). Before (the map on the undisplaced normals, Strength as a blend, shadow
    rays lifted): mean 0.27 %, largest block 562 % at 64 samples; RoomExercise.blend's
    displaced ceiling lit twice as bright as Cycles."""
    bpy = bpy_drt
    scene = _tilted_faces_scene(bpy)
    cycles = node_probe.render(bpy, scene, "CYCLES", 8 * SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", 8 * SAMPLES)
    mean, block = image_errors(drt, cycles)
    print(f"tilted flat faces with a Normal Map: mean {mean:.2%}, largest block {block:.2%}")
    assert mean < 0.01 and block < 0.03, (mean, block)


def test_bump_only_displacement_under_a_shaders_own_normal_matches_cycles(bpy_drt):
    """The plane (smooth, scaled unevenly and turned), its displacement as Bump Only, with
    its Principled BSDF's Normal from a Normal Map (_normal_map): Cycles' bump still sets
    the surface's own normal (sd->N), against which the map's bent lobes are shadowed and
    for which lights are picked, while the lobes keep the map's normal; and the map is
    worked out in the object's space. Measured (64 samples each): mean 0.02 %, largest
    block 0.5 %. Before (the bump left out with a warning, the map's frame built in the
    world): mean 6.4 %, largest block 18 %. The same material with true displacement is
    a gap still (docs/displacement.md)."""
    bpy = bpy_drt
    scene, mat = _plane_scene(bpy, "BUMP")
    _normal_map(mat.node_tree)
    cycles = node_probe.render(bpy, scene, "CYCLES", SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", SAMPLES)
    mean, block = image_errors(drt, cycles)
    print(f"Bump Only with a Normal Map: mean {mean:.2%}, largest block {block:.2%}")
    assert mean < 0.01 and block < 0.03, (mean, block)


def _surface_normal_readout(bpy, mat):
    """The plane's surface as an Emission whose channels read the surface normal three
    ways, as a shader's nodes do: red the Fresnel node (IOR 1.45), green the Geometry
    node's Normal x 0.5 + 0.5 (its x), blue the Texture Coordinate node's Normal x 0.5 +
    0.5 (its y, in the turned and scaled object's space)."""
    nt = mat.node_tree
    fresnel = nt.nodes.new("ShaderNodeFresnel")
    geometry = nt.nodes.new("ShaderNodeNewGeometry")
    coords = nt.nodes.new("ShaderNodeTexCoord")
    halves = []
    for out in (geometry.outputs["Normal"], coords.outputs["Normal"]):
        half = nt.nodes.new("ShaderNodeVectorMath")
        half.operation = "MULTIPLY_ADD"
        half.inputs[1].default_value = (0.5, 0.5, 0.5)
        half.inputs[2].default_value = (0.5, 0.5, 0.5)
        nt.links.new(out, half.inputs[0])
        split = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(half.outputs[0], split.inputs[0])
        halves.append(split)
    combine = nt.nodes.new("ShaderNodeCombineXYZ")
    nt.links.new(fresnel.outputs[0], combine.inputs["X"])
    nt.links.new(halves[0].outputs["X"], combine.inputs["Y"])
    nt.links.new(halves[1].outputs["Y"], combine.inputs["Z"])
    emission = nt.nodes.new("ShaderNodeEmission")
    nt.links.new(combine.outputs[0], emission.inputs["Color"])
    nt.links.new(emission.outputs[0], nt.nodes["Material Output"].inputs["Surface"])


@pytest.mark.parametrize("method", ["BUMP", "BOTH"])
def test_the_displacements_bump_is_the_normal_the_surface_nodes_read(bpy_drt, method):
    """Cycles runs the Displacement socket's bump before the surface's nodes and its Set
    Normal writes sd->N, so Fresnel, Geometry > Normal and Texture Coordinate > Normal
    read the bumped normal (_surface_normal_readout on the plane). Each channel is
    compared alone. Measured (32 samples each; per channel, Fresnel, Geometry, Texture
    Coordinate): Bump Only means 0.00 %, blocks 0.9 %, 0.6 %, 0.6 %; Displacement and
    Bump means 0.00 %, blocks 1.2 %, 0.7 %, 0.7 %. Before, DRT's nodes read the normal
    the bump had not bent: means 5.4 %, 1.6 %, 0.8 % and blocks 130 %, 27 %, 18 % (Bump
    Only), blocks 119 %, 30 %, 22 % (Displacement and Bump). The control: Cycles' own
    image without the bump differs by more than 5 % in some channel's blocks."""
    bpy = bpy_drt
    scene, mat = _plane_scene(bpy, method)
    _surface_normal_readout(bpy, mat)
    cycles = node_probe.render(bpy, scene, "CYCLES", 32)
    drt = node_probe.render(bpy, scene, "DRT", 32)
    errors = [image_errors(drt[..., k:k + 1], cycles[..., k:k + 1],
                           f"DRT against Cycles, {'RGB'[k]}") for k in range(3)]
    nt = mat.node_tree
    for link in list(nt.nodes["Material Output"].inputs["Displacement"].links):
        nt.links.remove(link)
    mat.displacement_method = "BUMP"
    flat = node_probe.render(bpy, scene, "CYCLES", 32)
    control = max(image_errors(flat[..., k:k + 1], cycles[..., k:k + 1],
                               f"control: Cycles without the displacement, {'RGB'[k]}")[1]
                  for k in range(3))
    print(f"{method}: per channel (mean, block) "
          + ", ".join(f"({m:.2%}, {b:.2%})" for m, b in errors)
          + f"; Cycles without the bump: worst block {control:.2%}")
    assert all(m < 0.01 and b < 0.03 for m, b in errors), errors
    assert control > 0.05, control
