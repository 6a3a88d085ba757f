"""Export correctness: what DRT's exporter hands the tracer matches what Blender reports.

The scene is built here with bpy and rendered through bpy.ops.render.render at 8 x 8
pixels and one sample, only to get the exporter run on Blender's own render depsgraph
(where hide_render and disabled collections apply); the checks are on the exported
description (`render_engine.last_render["scene"]`), compared with Blender's evaluated
meshes and matrices. Also: bad input (NaN vertices, no camera, an unsupported shader
node), and the camera: resolution percentage, pixel aspect, border render and the DoF
focus object.
"""
import math
import os

import numpy as np
import pytest

from conftest import SAMPLES_DIR, read_render_result, render_blend


# --------------------------------------------------------------------------- helpers
def _principled(bpy, name, color):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    return mat


def _mesh_object(bpy, name, verts, faces, collection=None, mesh=None):
    if mesh is None:
        mesh = bpy.data.meshes.new(name)
        mesh.from_pydata(verts, [], faces)
        mesh.validate()
    obj = bpy.data.objects.new(name, mesh)
    (collection or bpy.context.scene.collection).objects.link(obj)
    return obj


CUBE_V = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
          (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
CUBE_F = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]


def _camera(bpy, scene, location=(0.0, -14.0, 4.0), target=(0.0, 0.0, 0.0)):
    from mathutils import Vector
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = location
    cam.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(cam)
    scene.camera = cam
    return cam


def _render_settings(scene, size=(8, 8), samples=1):
    scene.render.engine = "DRT"
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.drt.samples = samples


def build_scene(bpy):
    """Everything the exporter must get right, in one scene."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    _render_settings(scene)
    red = _principled(bpy, "Red", (0.8, 0.1, 0.1))
    blue = _principled(bpy, "Blue", (0.1, 0.1, 0.8))
    grey = _principled(bpy, "Grey", (0.5, 0.5, 0.5))

    # A cube with three smooth and three flat faces, two material slots, an array and a
    # subdivision modifier (the same levels in the viewport and in renders).
    cube = _mesh_object(bpy, "Modified", CUBE_V, CUBE_F)
    cube.data.materials.append(red)
    cube.data.materials.append(blue)
    for i, poly in enumerate(cube.data.polygons):
        poly.use_smooth = i < 3
        poly.material_index = 0 if i % 2 == 0 else 1
    arr = cube.modifiers.new("Array", "ARRAY")
    arr.count = 3
    sub = cube.modifiers.new("Subdivision", "SUBSURF")
    sub.levels = sub.render_levels = 1
    cube.location = (-3.0, 1.0, 0.5)
    cube.rotation_euler = (0.3, 0.2, 0.9)
    cube.scale = (0.5, 0.7, 0.4)

    # A linked duplicate: two objects, one mesh, no modifiers.
    plain = _mesh_object(bpy, "Plain", CUBE_V, CUBE_F)
    plain.data.materials.append(grey)
    plain.location = (4.0, 0.0, 0.0)
    plain.shadow_terminator_geometry_offset = 0.25     # Object > Shadow Terminator
    dup = _mesh_object(bpy, "PlainDuplicate", None, None, mesh=plain.data)
    dup.location = (4.0, 3.0, 1.0)
    dup.scale = (-1.0, 1.0, 1.0)                # a mirrored instance

    # A collection instanced twice; the collection itself is excluded from the view layer.
    src = bpy.data.collections.new("Source")
    scene.collection.children.link(src)
    inst = _mesh_object(bpy, "Instanced", CUBE_V[:4], [(0, 1, 2, 3)], collection=src)
    inst.data.materials.append(grey)
    bpy.context.view_layer.layer_collection.children["Source"].exclude = True
    for i, loc in enumerate([(0.0, 5.0, 0.0), (2.0, 6.0, 1.0)]):
        e = bpy.data.objects.new(f"Instancer{i}", None)
        e.instance_type = "COLLECTION"
        e.instance_collection = src
        e.location = loc
        e.rotation_euler = (0.0, 0.0, 0.5 * i)
        scene.collection.objects.link(e)

    # Left out: disabled in renders, in a collection disabled in renders.
    # Exported as holdouts: the object's own flag and a holdout collection.
    _mesh_object(bpy, "DisabledInRenders", CUBE_V, CUBE_F).hide_render = True
    off = bpy.data.collections.new("RenderOff")
    scene.collection.children.link(off)
    off.hide_render = True
    _mesh_object(bpy, "InRenderOffCollection", CUBE_V, CUBE_F, collection=off)
    _mesh_object(bpy, "Holdout", CUBE_V, CUBE_F).is_holdout = True
    hc = bpy.data.collections.new("HoldoutCollection")
    scene.collection.children.link(hc)
    _mesh_object(bpy, "InHoldoutCollection", CUBE_V, CUBE_F, collection=hc)
    bpy.context.view_layer.layer_collection.children["HoldoutCollection"].holdout = True
    # Rendered although hidden in the viewport (the eye icon).
    vh = _mesh_object(bpy, "ViewportHidden", CUBE_V, CUBE_F)
    vh.location = (0.0, -3.0, 0.0)
    vh.hide_set(True)

    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(sun)
    _camera(bpy, scene)
    return scene


def _render_drt(bpy):
    """Render with DRT; an error DRT reports makes Blender's operator raise, which is
    fine here: the outcome is read from last_render."""
    from drt_addon import render_engine
    try:
        bpy.ops.render.render()
    except RuntimeError:
        assert render_engine.last_render["error"]
    return render_engine.last_render


def _expected(bpy, name):
    """Blender's evaluated mesh of object `name`: world-space corner positions (T,3,3),
    split normals (T,3,3) in world space, material slot per triangle, flat flags."""
    obj = bpy.data.objects[name]
    dg = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(dg)
    me = ev.to_mesh()
    try:
        me.calc_loop_triangles()
        m = np.array(ev.matrix_world, dtype=np.float64)
        co = np.array([v.co for v in me.vertices], dtype=np.float64) @ m[:3, :3].T + m[:3, 3]
        tris = np.array([t.vertices[:] for t in me.loop_triangles])
        normal_matrix = np.linalg.inv(m[:3, :3]).T
        split = np.array([t.split_normals[:] for t in me.loop_triangles]) @ normal_matrix.T
        split /= np.linalg.norm(split, axis=2, keepdims=True)
        mat = np.array([t.material_index for t in me.loop_triangles])
        smooth = np.array([me.polygons[t.polygon_index].use_smooth for t in me.loop_triangles])
        # A slot without a material, or no slot at all, exports DRT's "none" material.
        slots = [s.material.name if s.material else "none" for s in obj.material_slots]
        return co[tris], split, mat, smooth, slots or ["none"]
    finally:
        ev.to_mesh_clear()


@pytest.fixture(scope="module")
def exported(bpy_drt):
    bpy = bpy_drt
    build_scene(bpy)
    last = _render_drt(bpy)
    assert last["ok"], last["error"]
    return bpy, last["scene"], last["export_stats"], list(last["warnings"])


def _by_name(scene, name):
    return [m for m in scene.meshes if m.name == name]


# --------------------------------------------------------------------------- geometry
def test_objects_left_out_and_kept(exported):
    bpy, scene, stats, warnings = exported
    names = sorted(m.name.split("#")[0] for m in scene.meshes if not m.holdout)
    # the collection's two places are one instanced mesh (test_collection_instances)
    assert names == sorted(["Modified", "Plain", "PlainDuplicate", "Instanced",
                            "ViewportHidden"]), names
    assert sorted(m.name for m in scene.meshes if m.holdout) == ["Holdout",
                                                                  "InHoldoutCollection"]
    assert stats["holdouts"] == 2
    assert not any("holdout" in w.lower() for w in warnings), warnings
    assert len(scene.lights) == 1


def test_triangles_bounds_normals_and_materials_match_blender(exported):
    bpy, scene, stats, _ = exported
    for name in ("Modified", "Plain", "PlainDuplicate", "ViewportHidden"):
        (mesh,) = _by_name(scene, name)
        corners, split, mat, smooth, slot_names = _expected(bpy, name)
        # triangle count of the evaluated mesh (modifiers applied)
        assert len(mesh.triangles) == len(corners), name
        got = mesh.positions[mesh.triangles]
        # world-space bounds
        np.testing.assert_allclose(got.reshape(-1, 3).min(0), corners.reshape(-1, 3).min(0),
                                   atol=1e-5)
        np.testing.assert_allclose(got.reshape(-1, 3).max(0), corners.reshape(-1, 3).max(0),
                                   atol=1e-5)
        # per-triangle material: the name of the slot's material
        got_names = [scene.materials[i].name for i in mesh.material_indices]
        assert got_names == [slot_names[min(i, len(slot_names) - 1)] for i in mat], name
        # same triangles in the same order, winding aside (mirrored instances flip it)
        np.testing.assert_allclose(np.sort(got, axis=1), np.sort(corners, axis=1), atol=1e-5)
        # geometric normal of each exported triangle agrees with Blender's face side
        gn = np.cross(got[:, 1] - got[:, 0], got[:, 2] - got[:, 0])
        gn /= np.linalg.norm(gn, axis=1, keepdims=True)
        face_side = split.mean(axis=1)
        assert np.all((gn * face_side).sum(1) > 0), name
        if smooth.any():
            assert mesh.corner_normals is not None
            cn = mesh.corner_normals.astype(np.float64)
            # match Blender's split normals corner by corner (as a set per triangle)
            np.testing.assert_allclose(np.sort(cn, axis=1), np.sort(split, axis=1), atol=1e-4)
            # flat faces: all three corners carry the same (the polygon's) normal
            flat = cn[~smooth]
            np.testing.assert_allclose(flat, np.repeat(flat[:, :1], 3, axis=1), atol=1e-5)
            # smooth faces: corner normals differ within a triangle somewhere
            assert np.abs(cn[smooth] - cn[smooth][:, :1]).max() > 0.05
        else:
            assert mesh.corner_normals is None


def test_shadow_terminator_geometry_offset_is_exported(exported):
    _, scene, _, _ = exported
    assert [m.terminator_offset for m in _by_name(scene, "Plain")] == [0.25]
    assert [m.terminator_offset for m in _by_name(scene, "Modified")] == [pytest.approx(0.1)]


def test_modifiers_are_applied(exported):
    bpy, scene, _, _ = exported
    (mesh,) = _by_name(scene, "Modified")
    # 6 quads x 3 (array) x 4 (one subdivision level) x 2 triangles
    assert len(mesh.triangles) == 6 * 3 * 4 * 2


def test_mirrored_duplicate_keeps_its_normals_outwards(exported):
    bpy, scene, _, _ = exported
    (mesh,) = _by_name(scene, "PlainDuplicate")
    p = mesh.positions[mesh.triangles]
    gn = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    outward = p.mean(axis=1) - mesh.positions.mean(axis=0)
    assert np.all((gn * outward).sum(1) > 0)


def test_collection_instances(exported):
    """A collection instanced twice is one mesh in object space with two places
    (engine.scene.Instances), each where Blender puts it."""
    bpy, scene, stats, _ = exported
    (m,) = [m for m in scene.meshes if m.name.startswith("Instanced#")]
    assert m.instances is not None and len(m.instances) == 2
    assert stats["instances"] == 2
    np.testing.assert_allclose(np.sort(m.positions, axis=0),
                               np.sort(np.array(CUBE_V[:4], dtype=np.float64), axis=0))
    places = sorted(m.instances.matrices, key=lambda a: a[0, 3])
    for a, loc, angle in zip(places, [(0.0, 5.0, 0.0), (2.0, 6.0, 1.0)], [0.0, 0.5]):
        c, s = math.cos(angle), math.sin(angle)
        rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
        expected = np.array(CUBE_V[:4], dtype=np.float64) @ rot.T + loc
        world = m.positions @ a[:3, :3].T + a[:3, 3]
        np.testing.assert_allclose(np.sort(world, axis=0), np.sort(expected, axis=0),
                                   atol=1e-6)


def test_instances_reuse_evaluated_meshes(exported):
    """One to_mesh per distinct evaluated geometry: the linked duplicate and the second
    collection instance reuse arrays read before."""
    bpy, scene, stats, _ = exported
    assert stats["meshes"] == 7                       # 5 rendered (one of them the two
    #                                                   collection instances) + 2 holdouts
    assert stats["mesh_evaluations"] == 6, stats      # Modified, Plain, Instanced,
    #                                                   ViewportHidden and the 2 holdouts
    assert stats["mesh_reuses"] == 2, stats           # PlainDuplicate, second Instanced
    assert scene.triangle_count() == stats["triangles"]


def test_many_instances_evaluate_their_mesh_once(bpy_drt):
    """200 linked duplicates of a 3840-triangle sphere: one evaluation, 199 reuses, and
    one mesh with 200 places (engine.scene.Instances)."""
    bpy = bpy_drt
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    _render_settings(scene)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, radius=0.4)
    src = bpy.context.active_object
    src.data.materials.append(_principled(bpy, "Grey", (0.5, 0.5, 0.5)))
    for i in range(199):
        o = bpy.data.objects.new(f"Copy{i}", src.data)
        o.location = (i % 20, i // 20, 0.0)
        scene.collection.objects.link(o)
    _camera(bpy, scene, location=(10.0, -20.0, 15.0), target=(10.0, 5.0, 0.0))
    from drt_addon.export import export_scene
    stats = {}
    s = export_scene(bpy.context.evaluated_depsgraph_get(), stats=stats)
    tris = len(src.data.polygons) * 2 - 2 * 128          # quads + the two fans of triangles
    assert stats["mesh_evaluations"] == 1 and stats["mesh_reuses"] == 199, stats
    assert len(s.meshes) == 1 and len(s.meshes[0].instances) == 200
    assert s.triangle_count() == tris and stats["instances"] == 200
    print(f"export of 200 places of {s.triangle_count()} triangles: "
          f"{stats['seconds']:.2f} s")


# --------------------------------------------------------------------------- bad input
def test_nan_vertex_drops_its_triangles_with_a_warning_naming_the_object(bpy_drt):
    """As Cycles: the triangles of a NaN vertex are skipped, the rest renders (the
    comparison with Cycles is in test_degenerate_input.py)."""
    bpy = bpy_drt
    build_scene(bpy)
    obj = bpy.data.objects["Plain"]
    obj.data.vertices[2].co = (float("nan"), 0.0, 0.0)
    from drt_addon.export import Reporter, export_scene
    reporter = Reporter()
    s = export_scene(bpy.context.evaluated_depsgraph_get(), reporter)
    plain = _by_name(s, "Plain")[0]
    obj.data.calc_loop_triangles()
    touching = sum(2 in t.vertices[:] for t in obj.data.loop_triangles)
    assert touching > 0
    assert len(plain.triangles) == 12 - touching and np.isfinite(plain.positions).all()
    assert sum("'Plain'" in w and "NaN" in w for w in reporter.warnings) == 1, reporter.warnings
    last = _render_drt(bpy)
    assert last["ok"], last["error"]


def test_hair_volumes_and_point_clouds_are_named_once_and_the_rest_renders(bpy_drt):
    """Nothing is dropped silently: particle hair on a mesh and a hair Curves object are
    exported as strands (export.hair), a point cloud DRT cannot draw yet is named in one
    warning, a Volume object without a file in its own, and the render works."""
    bpy = bpy_drt
    build_scene(bpy)
    from drt_addon.export import Reporter, export_scene
    reporter = Reporter()
    export_scene(bpy.context.evaluated_depsgraph_get(), reporter)
    assert not any("not rendered yet" in w for w in reporter.warnings), reporter.warnings
    obj = bpy.data.objects["Plain"]
    mod = obj.modifiers.new("Fur", "PARTICLE_SYSTEM")
    mod.particle_system.settings.type = "HAIR"
    mod.particle_system.settings.count = 10
    smoke = bpy.data.objects.new("Smoke", bpy.data.volumes.new("Smoke"))
    bpy.context.scene.collection.objects.link(smoke)
    curves = bpy.data.hair_curves.new("Strands")
    curves.add_curves([3, 4])
    strands = bpy.data.objects.new("Strands", curves)
    bpy.context.scene.collection.objects.link(strands)
    dots = bpy.data.objects.new("Dots", bpy.data.pointclouds.new("Dots"))
    bpy.context.scene.collection.objects.link(dots)
    reporter = Reporter()
    s = export_scene(bpy.context.evaluated_depsgraph_get(), reporter)
    assert sorted((c.name, c.curve_count) for c in s.curves) == [("Plain (Fur)", 10),
                                                                 ("Strands", 2)]
    said = [w for w in reporter.warnings if "not rendered yet" in w]
    assert len(said) == 1 and "point clouds ('Dots')" in said[0], reporter.warnings
    assert "hair" not in said[0]
    smoke = [w for w in reporter.warnings if "Volume object 'Smoke'" in w]
    assert len(smoke) == 1 and "names no OpenVDB file" in smoke[0], reporter.warnings
    # a smoke simulation's domain: its grids are named as left out, the mesh renders
    domain = _mesh_object(bpy, "Domain", [(-1, -1, 3), (1, -1, 3), (1, 1, 3), (-1, 1, 3)],
                          [(0, 1, 2, 3)])
    fluid = domain.modifiers.new("Fluid", "FLUID")
    fluid.fluid_type = "DOMAIN"
    reporter = Reporter()
    s = export_scene(bpy.context.evaluated_depsgraph_get(), reporter)
    said = [w for w in reporter.warnings if "not rendered yet" in w]
    assert len(said) == 1 and "smoke simulation grids" in said[0] and "'Domain'" in said[0]
    assert _by_name(s, "Plain")                  # the emitter itself still renders
    last = _render_drt(bpy)
    assert last["ok"], last["error"]


def test_no_camera_gives_a_clear_error(bpy_drt):
    bpy = bpy_drt
    build_scene(bpy)
    bpy.context.scene.camera = None
    from drt_addon.export import ExportError, export_scene
    with pytest.raises(ExportError, match="no active camera"):
        export_scene(bpy.context.evaluated_depsgraph_get())
    # Blender itself refuses to start a render without a camera, with its own message.
    with pytest.raises(RuntimeError, match="(?i)camera"):
        bpy.ops.render.render()


def _plain_gets(bpy, name, kind):
    """Give the object 'Plain' a new material of one BSDF node of type `kind` (returned)."""
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    node = nodes.new(kind)
    mat.node_tree.links.new(node.outputs[0], nodes["Material Output"].inputs["Surface"])
    bpy.data.objects["Plain"].data.materials[0] = mat
    return node


def test_unsupported_shader_node_renders_with_a_warning(bpy_drt):
    bpy = bpy_drt
    build_scene(bpy)
    _plain_gets(bpy, "Toony", "ShaderNodeBsdfToon")
    last = _render_drt(bpy)
    assert last["ok"], last["error"]
    assert any("Toony" in w and "Toon" in w for w in last["warnings"]), last["warnings"]
    assert np.isfinite(last["pixels"]).all()


def test_every_integrator_renders_every_material_without_a_warning(bpy_drt):
    """The distribution and Whitted integrators run on the path tracer's kernels, so a
    scene with coat, sheen, translucency, refraction-only glass and Beckmann renders
    with each of them with no warning about what it leaves out, and a finite image."""
    bpy = bpy_drt
    build_scene(bpy)
    _plain_gets(bpy, "Frosted", "ShaderNodeBsdfRefraction").inputs["Roughness"].default_value = 0.3
    for integrator in ("path", "distribution", "whitted"):
        bpy.context.scene.drt.integrator = integrator
        last = _render_drt(bpy)
        assert last["ok"], (integrator, last["error"])
        assert not [w for w in last["warnings"] if "integrator" in w], last["warnings"]
        assert np.isfinite(last["pixels"]).all() and last["pixels"].max() > 0.0
    bpy.context.scene.drt.integrator = "path"


# --------------------------------------------------------------------------- camera
def test_resolution_percentage_uses_blenders_integer_maths(bpy_drt):
    bpy = bpy_drt
    build_scene(bpy)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = 100, 30
    scene.render.resolution_percentage = 29        # 100 * 0.29 = 28.999... in floating point
    last = _render_drt(bpy)
    assert last["ok"], last["error"]
    assert (last["scene"].width, last["scene"].height) == (29, 8)
    assert last["pixels"].shape == (8, 29, 3)


def _save_render(bpy, scene):
    return read_render_result(bpy, scene)


LIGHT_POINT = os.path.join(SAMPLES_DIR, "light_point.blend")


def _direct(scene):
    scene.cycles.diffuse_bounces = 0


def test_pixel_aspect_matches_cycles(bpy_drt):
    """A 32 x 16 image with pixels twice as wide as high: DRT's view of the lit plane
    matches Cycles' (mean within 2%, MAD within 5%), and the scene is sensitive to it:
    square pixels would put the light's falloff elsewhere and fail those thresholds."""
    def wide_pixels(scene):
        _direct(scene)
        scene.render.resolution_x, scene.render.resolution_y = 32, 16
        scene.render.pixel_aspect_x = 2.0

    def square_pixels(scene):
        _direct(scene)
        scene.render.resolution_x, scene.render.resolution_y = 32, 16
    drt = render_blend(bpy_drt, LIGHT_POINT, "DRT", 64, 100, wide_pixels)
    cyc = render_blend(bpy_drt, LIGHT_POINT, "CYCLES", 64, 100, wide_pixels)
    square = render_blend(bpy_drt, LIGHT_POINT, "DRT", 16, 100, square_pixels)
    assert drt.shape == cyc.shape == (16, 32, 3)

    def close(a, b):
        rel = np.abs(a.mean((0, 1)) - b.mean((0, 1))) / b.mean((0, 1))
        return rel.max() <= 0.02 and np.abs(a - b).mean() / b.mean() <= 0.05
    assert close(drt, cyc), (drt.mean(), cyc.mean(), np.abs(drt - cyc).mean() / cyc.mean())
    assert not close(square, cyc)


@pytest.fixture(scope="module")
def border_renders(bpy_drt):
    bpy = bpy_drt
    border = dict(border_min_x=0.25, border_max_x=0.7, border_min_y=0.1, border_max_y=0.55)

    def full(scene):
        _direct(scene)
        scene.render.resolution_x, scene.render.resolution_y = 40, 32
        scene.camera.data.shift_x = 0.1              # shifts must carry over to the border

    def with_border(crop):
        def setup(scene):
            full(scene)
            scene.render.use_border = True
            scene.render.use_crop_to_border = crop
            for k, v in border.items():
                setattr(scene.render, k, v)
        return setup
    from drt_addon import render_engine
    whole = render_blend(bpy, LIGHT_POINT, "DRT", 64, 100, full)
    cropped = render_blend(bpy, LIGHT_POINT, "DRT", 64, 100, with_border(True))
    traced = render_engine.last_render["scene"]
    uncropped = render_blend(bpy, LIGHT_POINT, "DRT", 64, 100, with_border(False))
    # Blender's pixel rectangle: int(fraction x size) in float32 (0.7 is stored as
    # 0.69999999, and 0.69999999 x 40 rounds to 28.0 in float32), rows from the bottom.
    f32 = np.float32
    x0, x1 = int(f32(0.25) * f32(40)), int(f32(0.7) * f32(40))
    y0, y1 = int(f32(0.1) * f32(32)), int(f32(0.55) * f32(32))
    assert x1 - x0 == 18
    crop = whole[32 - y1:32 - y0, x0:x1]
    return whole, cropped, uncropped, crop, traced, (x0, x1, y0, y1)


def test_border_render_traces_only_the_border(border_renders):
    whole, cropped, uncropped, crop, traced, (x0, x1, y0, y1) = border_renders
    assert (traced.width, traced.height) == (x1 - x0, y1 - y0)


def test_cropped_border_render_equals_the_full_renders_crop(border_renders):
    whole, cropped, uncropped, crop, traced, _ = border_renders
    assert cropped.shape == crop.shape
    # The light's falloff makes a strong gradient, so a shifted window would not match;
    # the only difference left is sampling noise of the anti-aliasing (sub-1%).
    rel = np.abs(cropped - crop) / crop
    assert rel.mean() < 0.005 and rel.max() < 0.03, (rel.mean(), rel.max())
    shifted = np.roll(crop, 1, axis=1)
    assert (np.abs(cropped - shifted) / crop).mean() > 0.01


def test_uncropped_border_render_is_placed_in_the_frame(border_renders):
    whole, cropped, uncropped, crop, traced, (x0, x1, y0, y1) = border_renders
    assert uncropped.shape == whole.shape
    inside = uncropped[32 - y1:32 - y0, x0:x1]
    np.testing.assert_allclose(inside, cropped, rtol=1e-6, atol=1e-7)
    outside = np.ones(whole.shape[:2], dtype=bool)
    outside[32 - y1:32 - y0, x0:x1] = False
    assert np.all(uncropped[outside] == 0.0)


def test_dof_focus_object_sets_the_focus_distance(bpy_drt):
    bpy = bpy_drt
    build_scene(bpy)
    scene = bpy.context.scene
    cam = scene.camera
    cam.data.dof.use_dof = True
    cam.data.dof.aperture_fstop = 2.0
    cam.data.dof.focus_distance = 1.0
    target = bpy.data.objects.new("FocusTarget", None)
    target.location = (1.5, 2.0, -0.5)
    scene.collection.objects.link(target)
    cam.data.dof.focus_object = target
    from drt_addon.export import export_scene
    s = export_scene(bpy.context.evaluated_depsgraph_get())
    m = np.array(cam.matrix_world)
    axis = m[:3, 2] / np.linalg.norm(m[:3, 2])
    expected = abs((np.array(target.location) - m[:3, 3]) @ axis)
    assert s.camera.focus_distance == pytest.approx(expected, rel=1e-6)
    assert abs(expected - 1.0) > 5.0                      # not the ignored focus_distance
    assert s.camera.aperture_radius == pytest.approx(cam.data.lens * 1e-3 / 4.0)


def test_light_export_warns_about_what_drt_ignores(bpy_drt):
    bpy = bpy_drt
    build_scene(bpy)
    scene = bpy.context.scene
    spot = bpy.data.objects.new("Spot", bpy.data.lights.new("Spot", "SPOT"))
    spot.scale = (2.0, 1.0, 1.0)
    area = bpy.data.lights.new("Area", "AREA")
    area.spread = 0.5
    area_obj = bpy.data.objects.new("Area", area)
    for o in (spot, area_obj):
        scene.collection.objects.link(o)
    from drt_addon.export import Reporter, export_scene
    reporter = Reporter()
    s = export_scene(bpy.context.evaluated_depsgraph_get(), reporter)
    assert len(s.lights) == 3
    assert any("'Spot'" in w and "elliptical" in w for w in reporter.warnings), reporter.warnings
    # the Spread is rendered (tests/test_area_spread_vs_cycles.py): exported, not warned
    assert not any("'Area'" in w for w in reporter.warnings), reporter.warnings
    assert [round(l.spread, 6) for l in s.lights if hasattr(l, "spread")] == [0.5]


def test_an_object_blender_cannot_evaluate_is_left_out_with_a_warning():
    """obj.to_mesh() raising (Blender: "Object does not have geometry data") leaves that
    object out, named in a warning, instead of failing the whole render."""
    from drt_addon.export import Reporter
    from drt_addon.export.mesh import _evaluate

    class Broken:
        name = "Broken"

        def to_mesh(self):
            raise RuntimeError("Error: Object does not have geometry data\n")
    reporter = Reporter()
    assert _evaluate(Broken(), reporter=reporter) is None
    assert reporter.warnings == ["DRT: object 'Broken' is left out: Blender cannot evaluate "
                                 "its mesh (Error: Object does not have geometry data)"]
