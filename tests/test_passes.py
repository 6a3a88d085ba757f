"""Render passes: Depth, Normal, Mist, Position, UV, Denoising Normal, Denoising Albedo
and DRT Noise exist when enabled in the view layer, reach Blender's compositor, and hold
the right values (Depth, Mist, Position and UV also Cycles' own).

The scene is built here: a large plane with base colour (0.7, 0.4, 0.2) seen by a camera
looking down at it at an angle (so depth varies over the image and is not the distance
along the ray), 32 x 24 pixels. Analytic expectations come from Blender's own camera
frame (`Camera.view_frame`), not from DRT's camera model. Passes are read back through
the compositor (Render Layers node -> output -> saved OpenEXR), the way users get them.
"""
import os

import numpy as np
import pytest

from conftest import render_current

W, H = 32, 24
BASE = (0.7, 0.4, 0.2)
PASS_NAMES = ["Depth", "Normal", "Denoising Normal", "Denoising Albedo", "DRT Noise", "Mist",
              "Position", "UV"]
MIST = dict(start=1.0, depth=6.0, falloff="LINEAR")     # over the plane: 0.2 to 0.8


def build_scene(bpy, light="SUN"):
    from mathutils import Vector
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    scene.render.resolution_x, scene.render.resolution_y = W, H
    scene.render.resolution_percentage = 100
    scene.drt.samples = 8
    scene.cycles.use_denoising = False       # these tests read the render's own samples
    mat = bpy.data.materials.new("Base")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*BASE, 1.0)
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    mesh = bpy.data.meshes.new("Plane")
    mesh.from_pydata([(-10, -10, 0), (10, -10, 0), (10, 10, 0), (-10, 10, 0)], [], [(0, 1, 2, 3)])
    mesh.materials.append(mat)
    plane = bpy.data.objects.new("Plane", mesh)
    scene.collection.objects.link(plane)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.lens = 35.0
    cam.location = (0.3, -3.0, 2.5)
    cam.rotation_euler = (Vector((0.0, 0.5, 0.0)) - cam.location).to_track_quat(
        "-Z", "Y").to_euler()
    scene.collection.objects.link(cam)
    scene.camera = cam
    if light == "SUN":
        lamp = bpy.data.lights.new("Sun", "SUN")
        lamp.energy = 2.0
        lobj = bpy.data.objects.new("Sun", lamp)
    else:
        lamp = bpy.data.lights.new("Area", "AREA")
        lamp.size = 2.0
        lamp.energy = 300.0
        lobj = bpy.data.objects.new("Area", lamp)
        lobj.location = (0.0, 1.0, 3.0)
    scene.collection.objects.link(lobj)
    world = bpy.data.worlds.new("World")
    scene.world = world
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    bpy.context.view_layer.update()            # evaluate matrix_world
    return scene


def enable_passes(scene, on=True):
    vl = scene.view_layers[0]
    vl.use_pass_z = on
    vl.use_pass_normal = on
    vl.drt.use_pass_denoising_data = on
    vl.drt.use_pass_noise = on
    vl.use_pass_mist = on
    vl.use_pass_position = on
    vl.use_pass_uv = on
    for name, value in MIST.items():
        setattr(scene.world.mist_settings, name, value)


def composite(bpy, scene, pass_name):
    """Route one Render Layers output to the compositor's output (Blender 5 node groups)."""
    tree = bpy.data.node_groups.new("Comp", "CompositorNodeTree")
    tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
    rl = tree.nodes.new("CompositorNodeRLayers")
    rl.scene = scene
    out = tree.nodes.new("NodeGroupOutput")
    if pass_name is not None:
        tree.links.new(rl.outputs[pass_name], out.inputs[0])
    scene.compositing_node_group = tree
    scene.render.use_compositing = True
    return tree, rl


def render_and_save(bpy, scene):
    return render_current(bpy, scene)


def camera_frame(bpy, scene):
    """World-space origin and per-pixel-centre unit ray directions (H, W, 3), row 0 at the
    top, from Blender's view frame of the camera; and the camera's rotation matrix."""
    cam = scene.camera
    corners = np.array([tuple(v) for v in cam.data.view_frame(scene=scene)])
    tl = corners[(corners[:, 0] < 0) & (corners[:, 1] > 0)][0]
    tr = corners[(corners[:, 0] > 0) & (corners[:, 1] > 0)][0]
    bl = corners[(corners[:, 0] < 0) & (corners[:, 1] < 0)][0]
    u = (np.arange(W) + 0.5) / W
    v = (np.arange(H) + 0.5) / H
    local = tl + u[None, :, None] * (tr - tl) + v[:, None, None] * (bl - tl)
    m = np.array(cam.matrix_world, dtype=np.float64)
    rot = m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0)
    d = local @ rot.T
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    return m[:3, 3], d, rot


@pytest.fixture(scope="module")
def passes(bpy_drt):
    """Each pass as it comes out of the compositor, and as DRT wrote it."""
    bpy = bpy_drt
    from drt_addon import render_engine
    out = {}
    for name in PASS_NAMES:
        scene = build_scene(bpy)
        enable_passes(scene)
        composite(bpy, scene, name)
        out[name] = render_and_save(bpy, scene)
        np.testing.assert_array_equal(render_engine.last_render["passes"][name].shape[:2], (H, W))
        out["written " + name] = render_engine.last_render["passes"][name]
    frame = camera_frame(bpy, build_scene(bpy))
    return bpy, frame, out


def test_passes_exist_only_when_enabled(bpy_drt):
    bpy = bpy_drt
    scene = build_scene(bpy)
    enable_passes(scene, True)
    _, rl = composite(bpy, scene, None)
    enabled = {o.name for o in rl.outputs if o.enabled}
    assert set(PASS_NAMES) <= enabled, enabled
    scene = build_scene(bpy)
    enable_passes(scene, False)
    _, rl = composite(bpy, scene, None)
    enabled = {o.name for o in rl.outputs if o.enabled}
    assert not (set(PASS_NAMES) & enabled), enabled
    from drt_addon import render_engine
    render_and_save(bpy, scene)
    assert render_engine.last_render["passes"] == {}


def test_depth_is_the_distance_along_the_view_axis_to_the_plane(passes):
    bpy, (origin, d, rot), out = passes
    t = -origin[2] / d[..., 2]                       # ray to the plane z = 0
    hit = origin + d * t[..., None]
    axis = -rot[:, 2]
    expected = (hit - origin) @ axis                 # camera-space depth, not t
    depth = out["Depth"][..., 0]
    np.testing.assert_allclose(depth, expected, rtol=1e-4)
    np.testing.assert_allclose(out["written Depth"], expected, rtol=1e-4)
    # and it is not the distance along the ray, which differs by 1/cos off-axis
    assert np.abs(t - expected).max() / expected.max() > 0.05
    assert expected.max() / expected.min() > 1.5      # the depth really varies


def test_depth_matches_cycles_z_pass(passes, bpy_drt):
    bpy, _, out = passes
    scene = build_scene(bpy)
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 1
    scene.cycles.filter_width = 0.01     # Cycles' depth is its first sample's: centre it
    scene.view_layers[0].use_pass_z = True
    composite(bpy, scene, "Depth")
    cycles_depth = render_and_save(bpy, scene)[..., 0]
    np.testing.assert_allclose(out["Depth"][..., 0], cycles_depth, rtol=2e-3)


def test_position_is_the_hit_on_the_plane(passes):
    """The mean of the pixel's camera samples' hits: on the plane (z = 0 to rounding),
    and where the pixel centre's ray meets it, to the spread of 8 samples over the
    pixel's filter (measured: mean 1.1 cm, largest 11 cm at the far edge)."""
    bpy, (origin, d, _), out = passes
    t = -origin[2] / d[..., 2]
    expected = origin + d * t[..., None]
    pos = out["Position"]
    np.testing.assert_allclose(pos[..., 2], 0.0, atol=1e-6)
    err = np.linalg.norm(pos - expected, axis=-1)
    print(f"position: mean error {err.mean():.4f} m, largest {err.max():.4f} m")
    assert err.mean() < 0.03 and err.max() < 0.15
    np.testing.assert_allclose(out["written Position"], pos, atol=1e-6)


def test_position_matches_cycles(passes, bpy_drt):
    """Cycles' Position pass at 64 samples against DRT's (8 here): the image means agree
    per axis, and pixels to the samples' spread."""
    bpy, _, out = passes
    scene = build_scene(bpy)
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 64
    scene.view_layers[0].use_pass_position = True
    composite(bpy, scene, "Position")
    cycles = render_and_save(bpy, scene)[..., :3]
    pos = out["Position"]
    bias = np.abs(pos.mean(axis=(0, 1)) - cycles.mean(axis=(0, 1)))
    err = np.linalg.norm(pos - cycles, axis=-1)
    print(f"position against Cycles: mean per axis {bias}, per pixel mean {err.mean():.4f}"
          f" m, largest {err.max():.4f} m")
    assert bias.max() < 0.01 and err.mean() < 0.03


def test_uv_matches_cycles(bpy_drt):
    """A small plane with a UV map and no texture (its UVs are exported for the pass
    alone), the background around it: Cycles' UV pass at 64 samples against DRT's, u, v
    and coverage, per pixel: mean difference 0.006 (DRT's coverage counts its 16 pass
    samples: up to 0.23 off at the plane's edges), and inside the plane u and v within
    0.02 (measured 0.010)."""
    bpy = bpy_drt
    images = {}
    for engine in ("CYCLES", "DRT"):
        scene = build_scene(bpy)
        plane = bpy.data.objects["Plane"]
        uv = plane.data.uv_layers.new(name="UVMap")
        for i, corner in enumerate([(0.1, 0.2), (0.9, 0.2), (0.9, 0.7), (0.1, 0.7)]):
            uv.data[i].uv = corner
        plane.scale = (0.15, 0.15, 1.0)
        bpy.context.view_layer.update()
        scene.render.engine = engine
        scene.cycles.samples = 64
        scene.drt.samples = 64
        scene.view_layers[0].use_pass_uv = True
        composite(bpy, scene, "UV")
        images[engine] = render_and_save(bpy, scene)[..., :3]
    cycles, drt = images["CYCLES"], images["DRT"]
    covered = cycles[..., 2] > 0.99
    assert 0.1 < covered.mean() < 0.9                         # plane and background
    assert cycles[covered, 0].max() - cycles[covered, 0].min() > 0.3   # u varies
    diff = np.abs(drt - cycles)
    inside = covered & (drt[..., 2] > 0.99)                   # no edge in either's samples
    print(f"UV: mean difference {diff.mean():.4f}, largest {diff.max():.4f}, inside the "
          f"plane {diff[inside].max():.4f}")
    assert diff.mean() < 0.01 and diff[inside].max() < 0.02


@pytest.mark.parametrize("falloff", ["LINEAR", "QUADRATIC", "INVERSE_QUADRATIC"])
def test_mist_matches_cycles(bpy_drt, falloff):
    """Mist of the plane (distances 3 to 7 m, Start 1 m, Depth 6 m) against Cycles'
    Mist pass at 64 samples, per pixel: mean difference below 0.005, largest 0.03; the
    control, DRT with Start 0.5 m later, is off by more than 0.03 on average."""
    bpy = bpy_drt
    images = {}
    for engine, start in (("CYCLES", 1.0), ("DRT", 1.0), ("DRT", 1.5)):
        scene = build_scene(bpy)
        scene.render.engine = engine
        scene.cycles.samples = 64
        scene.view_layers[0].use_pass_mist = True
        mist = scene.world.mist_settings
        mist.start, mist.depth, mist.falloff = start, 6.0, falloff
        composite(bpy, scene, "Mist")
        images[engine, start] = render_and_save(bpy, scene)[..., 0]
    cycles = images["CYCLES", 1.0]
    assert cycles.max() - cycles.min() > 0.3                  # the mist varies over it
    diff = np.abs(images["DRT", 1.0] - cycles)
    print(f"mist {falloff}: mean difference {diff.mean():.4f}, largest {diff.max():.4f}")
    assert diff.mean() < 0.005 and diff.max() < 0.03
    assert np.abs(images["DRT", 1.5] - cycles).mean() > 0.03


def test_normal_is_the_plane_normal(passes):
    bpy, _, out = passes
    n = out["Normal"]
    np.testing.assert_allclose(n, np.broadcast_to([0.0, 0.0, 1.0], n.shape), atol=1e-5)


def test_denoising_normal_is_the_plane_normal_in_camera_space(passes):
    bpy, (_, _, rot), out = passes
    expected = rot.T @ np.array([0.0, 0.0, 1.0])
    assert abs(expected[2]) > 0.3 and abs(expected[1]) > 0.3     # not the world normal
    n = out["Denoising Normal"]
    np.testing.assert_allclose(n, np.broadcast_to(expected, n.shape), atol=1e-5)


def test_denoising_albedo_is_the_base_colour(passes):
    bpy, _, out = passes
    a = out["Denoising Albedo"]
    np.testing.assert_allclose(a, np.broadcast_to(BASE, a.shape), atol=1e-6)


def test_noise_pass_predicts_the_difference_between_independent_renders(bpy_drt):
    """With independent samples (the 'random' sampler), the DRT Noise pass (standard
    error of each pixel's mean) predicts the spread between two renders with different
    seeds: E[(a - b)^2] = 2 sigma^2. Checked over all pixels within 15%; a pass off by a
    factor sqrt(2) (variance of a sample instead of the mean, or a missing 1/n) fails."""
    bpy = bpy_drt
    from drt_addon import render_engine
    images, noise = [], []
    for seed in (1, 2):
        scene = build_scene(bpy, light="AREA")
        scene.render.resolution_x, scene.render.resolution_y = 48, 36
        scene.drt.sampler = "random"
        scene.drt.samples = 16
        scene.cycles.seed = seed
        scene.view_layers[0].drt.use_pass_noise = True
        composite(bpy, scene, "DRT Noise")
        noise.append(render_and_save(bpy, scene))
        images.append(render_engine.last_render["pixels"])
    np.testing.assert_allclose(noise[1], render_engine.last_render["passes"]["DRT Noise"],
                               rtol=1e-6)
    a, b = images
    predicted = np.mean(noise[0] ** 2 + noise[1] ** 2)
    measured = np.mean((a - b) ** 2)
    ratio = measured / predicted
    print(f"noise pass: measured / predicted squared difference = {ratio:.3f}")
    assert 0.85 < ratio < 1.15, ratio
    assert predicted > 0


def test_compositor_denoiser_uses_the_passes(bpy_drt):
    """Denoise node fed with Image, Denoising Normal and Denoising Albedo: the result is
    closer to a converged render than the noisy input."""
    bpy = bpy_drt
    from drt_addon import render_engine

    def scene_with(samples):
        scene = build_scene(bpy, light="AREA")
        scene.drt.samples = samples
        scene.view_layers[0].drt.use_pass_denoising_data = True
        return scene
    scene = scene_with(256)
    composite(bpy, scene, "Image")
    reference = render_and_save(bpy, scene)
    scene = scene_with(2)
    tree, rl = composite(bpy, scene, None)
    den = tree.nodes.new("CompositorNodeDenoise")
    out = [n for n in tree.nodes if n.bl_idname == "NodeGroupOutput"][0]
    tree.links.new(rl.outputs["Image"], den.inputs["Image"])
    tree.links.new(rl.outputs["Denoising Normal"], den.inputs["Normal"])
    tree.links.new(rl.outputs["Denoising Albedo"], den.inputs["Albedo"])
    tree.links.new(den.outputs[0], out.inputs[0])
    denoised = render_and_save(bpy, scene)
    noisy = render_engine.last_render["pixels"]
    err_noisy = np.abs(noisy - reference).mean()
    err_denoised = np.abs(denoised - reference).mean()
    print(f"denoiser: error {err_noisy:.4f} -> {err_denoised:.4f}")
    assert np.isfinite(denoised).all()
    assert err_denoised < 0.7 * err_noisy


def test_index_passes_match_cycles(bpy_drt):
    """Object Index and Material Index: on the plane (object 1, material 0) two cubes
    (objects 3 and 5: linked duplicates, one instanced mesh with two places, of
    material 2) and a third (object 7, the plane's material). Cycles at 16 samples
    against DRT: both write sample 0's hit, so they agree but where the two engines'
    first samples fall on different sides of an edge (measured: 98 % of pixels equal);
    every object's and material's index is found; the control, DRT's pass with the
    duplicates' indices swapped, agrees less."""
    from drt_addon.blender_compat import MATERIAL_INDEX_PASS, OBJECT_INDEX_PASS
    bpy = bpy_drt
    images = {}
    for engine, swap in (("CYCLES", False), ("DRT", False), ("DRT", True)):
        scene = build_scene(bpy)
        plane = bpy.data.objects["Plane"]
        plane.pass_index = 1
        red = bpy.data.materials.new("Red")
        red.pass_index = 2
        bpy.ops.mesh.primitive_cube_add(size=0.6, location=(-0.6, 0.3, 0.3))
        first = bpy.context.object
        first.data.materials.append(red)
        second = bpy.data.objects.new("Duplicate", first.data)
        second.location = (0.1, 0.9, 0.3)
        scene.collection.objects.link(second)
        first.pass_index, second.pass_index = (5, 3) if swap else (3, 5)
        bpy.ops.mesh.primitive_cube_add(size=0.5, location=(0.8, 0.2, 0.25))
        third = bpy.context.object
        third.pass_index = 7
        third.data.materials.append(plane.data.materials[0])
        bpy.context.view_layer.update()
        scene.render.engine = engine
        scene.cycles.samples = 16
        scene.drt.samples = 16
        vl = scene.view_layers[0]
        vl.use_pass_object_index = vl.use_pass_material_index = True
        for name in (OBJECT_INDEX_PASS, MATERIAL_INDEX_PASS):
            composite(bpy, scene, name)
            images[engine, swap, name] = render_and_save(bpy, scene)[..., 0]
    for name, found in ((OBJECT_INDEX_PASS, {0, 1, 3, 5, 7}), (MATERIAL_INDEX_PASS, {0, 2})):
        cycles, drt = images["CYCLES", False, name], images["DRT", False, name]
        for image in (cycles, drt):       # 0: the background, if any pixel shows it
            assert found - {0} <= set(np.unique(image)) <= found, (name, np.unique(image))
        same = (drt == cycles).mean()
        print(f"{name}: {same:.1%} of pixels equal to Cycles'")
        assert same > 0.9, name
    swapped = (images["DRT", True, OBJECT_INDEX_PASS]
               == images["CYCLES", False, OBJECT_INDEX_PASS]).mean()
    assert swapped < (images["DRT", False, OBJECT_INDEX_PASS]
                      == images["CYCLES", False, OBJECT_INDEX_PASS]).mean() - 0.03
