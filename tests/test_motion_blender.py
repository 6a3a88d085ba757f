"""Motion blur from Blender: the exporter samples the scene over the shutter and DRT's
blurred renders match Cycles'.

Scenes: sample_blends/motion_cube.blend (a red cube sliding 1 m along +X within the
shutter) and motion_torus.blend (an upright torus turning 100 degrees about the
vertical within the shutter); shutter 0.5 frames, frame 1, direct light only.

Thresholds, as for the other Cycles comparisons (tests/test_lights_vs_cycles.py): the
image means differ by at most 2% per channel and the per-pixel mean absolute difference
is at most 5% of Cycles' image mean. Cycles renders 1024 samples per pixel, DRT 256 (128
for the variants). Each comparison also checks that a render without the effect under
test (no motion blur, the other shutter position, a box shutter) misses the thresholds.
"""
import math
import os

import numpy as np
import pytest

from conftest import SAMPLES_DIR, render_blend

MEAN_TOLERANCE = 0.02
MAD_TOLERANCE = 0.05
CYCLES_SAMPLES = 1024
DRT_SAMPLES = 256
CUBE = os.path.join(SAMPLES_DIR, "motion_cube.blend")
TORUS = os.path.join(SAMPLES_DIR, "motion_torus.blend")
CUBE_SPEED = 2.0          # m per frame (build_samples.MOTION_CUBE_SPEED)
SHUTTER = 0.5

_renders = {}


def _direct(scene):
    scene.cycles.diffuse_bounces = 0


def render(bpy, path, engine, tag="", setup=None, samples=None):
    key = (path, engine, tag)
    if key not in _renders:
        def both(scene):
            _direct(scene)
            if setup is not None:
                setup(scene)
        samples = samples or (CYCLES_SAMPLES if engine == "CYCLES" else DRT_SAMPLES)
        _renders[key] = render_blend(bpy, path, engine, samples, percentage=100, setup=both)
    return _renders[key]


def compare(drt, cycles):
    m_drt, m_cyc = drt.mean(axis=(0, 1)), cycles.mean(axis=(0, 1))
    rel = np.abs(m_drt - m_cyc) / m_cyc
    return rel, float(np.abs(drt - cycles).mean() / cycles.mean())


def within(drt, cycles) -> bool:
    rel, mad = compare(drt, cycles)
    return bool((rel <= MEAN_TOLERANCE).all() and mad <= MAD_TOLERANCE)


def _blur_off(scene):
    scene.render.use_motion_blur = False


def _position(value):
    def setup(scene):
        scene.render.motion_blur_position = value
    return setup


def _ramp_shutter(scene):
    """Shutter curve rising linearly from closed to open: the end of the streak counts most."""
    mapping = scene.render.motion_blur_shutter_curve
    points = mapping.curves[0].points
    for p, xy in zip(points, [(0.0, 0.0), (0.5, 0.5), (1.0, 1.0)]):
        p.location = xy
    mapping.update()


def redness_centroid_x(image) -> float:
    """Mean column (pixel centres at i + 0.5) weighted by R - G: the red cube only (the
    floor and its shadows are grey)."""
    w = np.clip(image[..., 0] - image[..., 1], 0.0, None)
    cols = np.arange(image.shape[1]) + 0.5
    return float((w.sum(axis=0) * cols).sum() / w.sum())


# ----------------------------------------------------------------- DRT against Cycles
@pytest.mark.parametrize("path", [CUBE, TORUS], ids=["cube", "torus"])
def test_blurred_render_matches_cycles_and_a_sharp_one_does_not(bpy_drt, path):
    cycles = render(bpy_drt, path, "CYCLES")
    drt = render(bpy_drt, path, "DRT")
    sharp = render(bpy_drt, path, "DRT", "off", _blur_off, samples=64)
    assert drt.shape == cycles.shape == (48, 64, 3)
    assert np.isfinite(drt).all() and cycles.mean() > 0.01
    rel, mad = compare(drt, cycles)
    rel_s, mad_s = compare(sharp, cycles)
    print(f"{os.path.basename(path)}: DRT mean {drt.mean(axis=(0, 1))}, Cycles mean "
          f"{cycles.mean(axis=(0, 1))}, mean difference {100 * rel.max():.3f}%, MAD "
          f"{100 * mad:.3f}%; without motion blur: {100 * rel_s.max():.3f}%, "
          f"MAD {100 * mad_s:.2f}%")
    assert (rel <= MEAN_TOLERANCE).all(), rel
    assert mad <= MAD_TOLERANCE, mad
    assert not within(sharp, cycles), (rel_s, mad_s)


@pytest.mark.parametrize("position,offset", [("START", +0.5), ("END", -0.5)])
def test_shutter_position_moves_the_streak_as_blender_defines(bpy_drt, position, offset):
    """START opens the shutter at the frame (the streak lies ahead of the frame's cube),
    END closes it there (behind). Each matches Cycles' render with that position, misses
    the opposite one, and the streak's centroid moves by the projected distance the cube
    travels in half a shutter, CUBE_SPEED x SHUTTER / 2 = 0.5 m."""
    import bpy
    from bpy_extras.object_utils import world_to_camera_view
    from mathutils import Vector
    cycles = render(bpy_drt, CUBE, "CYCLES", position, _position(position))
    drt = render(bpy_drt, CUBE, "DRT", position, _position(position), samples=128)
    centre = render(bpy_drt, CUBE, "DRT")
    scene = bpy.context.scene
    w = scene.render.resolution_x
    u = [world_to_camera_view(scene, scene.camera, Vector((x, 0.0, 0.25))).x for x in
         (0.0, offset)]
    expected = (u[1] - u[0]) * w
    moved = redness_centroid_x(drt) - redness_centroid_x(centre)
    moved_cycles = redness_centroid_x(cycles) - redness_centroid_x(render(bpy_drt, CUBE,
                                                                          "CYCLES"))
    rel, mad = compare(drt, cycles)
    print(f"{position}: centroid moved {moved:+.2f} px (Cycles {moved_cycles:+.2f}, "
          f"projected {expected:+.2f}); vs Cycles: mean {100 * rel.max():.3f}%, "
          f"MAD {100 * mad:.2f}%")
    assert abs(expected) > 8
    assert abs(moved - expected) < 1.0
    assert (rel <= MEAN_TOLERANCE).all() and mad <= MAD_TOLERANCE, (rel, mad)
    other = "END" if position == "START" else "START"
    assert not within(drt, render(bpy_drt, CUBE, "CYCLES", other, _position(other)))


def test_shutter_curve_matches_cycles_and_a_box_shutter_does_not(bpy_drt):
    cycles = render(bpy_drt, CUBE, "CYCLES", "ramp", _ramp_shutter)
    drt = render(bpy_drt, CUBE, "DRT", "ramp", _ramp_shutter, samples=128)
    from drt_addon import render_engine
    curve = render_engine.last_render["scene"].shutter.curve
    assert curve is not None and curve[0] < 0.01 and curve[-1] > 0.99
    rel, mad = compare(drt, cycles)
    print(f"ramp shutter: mean {100 * rel.max():.3f}%, MAD {100 * mad:.2f}%")
    assert (rel <= MEAN_TOLERANCE).all() and mad <= MAD_TOLERANCE, (rel, mad)
    assert not within(render(bpy_drt, CUBE, "DRT"), cycles)


def _shape_key_motion(scene):
    """The cube's motion made by a shape key instead of its transform: a deformation."""
    import bpy
    cube = bpy.data.objects["Cube"]
    cube.animation_data_clear()
    cube.location.x = -CUBE_SPEED
    cube.shape_key_add(name="Basis")
    key = cube.shape_key_add(name="Moved")
    for p in key.data:
        p.co.x += 2 * CUBE_SPEED
    for frame, value in ((0, 0.0), (2, 1.0)):
        key.value = value
        key.keyframe_insert("value", frame=frame)
    _linear(cube.data.shape_keys)
    scene.frame_set(1)


def _linear(id_with_animation):
    ad = id_with_animation.animation_data
    fcurves = getattr(ad.action, "fcurves", None)
    if fcurves is None:
        from bpy_extras import anim_utils
        fcurves = anim_utils.action_get_channelbag_for_slot(ad.action, ad.action_slot).fcurves
    for fc in fcurves:
        for k in fc.keyframe_points:
            k.interpolation = "LINEAR"


def test_deforming_mesh_matches_cycles(bpy_drt):
    from drt_addon import render_engine
    from engine.motion import DeformMotion
    cycles = render(bpy_drt, CUBE, "CYCLES", "shape keys", _shape_key_motion)
    drt = render(bpy_drt, CUBE, "DRT", "shape keys", _shape_key_motion, samples=128)
    cube = [m for m in render_engine.last_render["scene"].meshes if m.name == "Cube"][0]
    assert isinstance(cube.motion, DeformMotion)
    rel, mad = compare(drt, cycles)
    print(f"shape-key deformation ({len(cube.motion.times)} time steps): mean "
          f"{100 * rel.max():.3f}%, MAD {100 * mad:.2f}%")
    assert (rel <= MEAN_TOLERANCE).all() and mad <= MAD_TOLERANCE, (rel, mad)
    assert not within(render(bpy_drt, CUBE, "DRT", "off", _blur_off, samples=64), cycles)


def _camera_pan(scene):
    """The cube stands still at the frame's place and the camera slides along -X."""
    import bpy
    bpy.data.objects["Cube"].animation_data_clear()
    bpy.data.objects["Cube"].location.x = 0.0
    cam = scene.camera
    x0 = cam.location.x
    for frame in (0, 2):
        cam.location.x = x0 - (frame - 1) * CUBE_SPEED
        cam.keyframe_insert("location", index=0, frame=frame)
    _linear(cam)
    scene.frame_set(1)


def test_moving_camera_matches_cycles(bpy_drt):
    from drt_addon import render_engine
    cycles = render(bpy_drt, CUBE, "CYCLES", "camera", _camera_pan)
    drt = render(bpy_drt, CUBE, "DRT", "camera", _camera_pan, samples=128)
    exported = render_engine.last_render["scene"]
    assert exported.camera.motion is not None and exported.has_motion()
    assert all(m.motion is None for m in exported.meshes)
    rel, mad = compare(drt, cycles)
    print(f"moving camera: mean {100 * rel.max():.3f}%, MAD {100 * mad:.2f}%")
    assert (rel <= MEAN_TOLERANCE).all() and mad <= MAD_TOLERANCE, (rel, mad)
    sharp = render(bpy_drt, CUBE, "DRT", "camera off",
                   lambda s: (_camera_pan(s), _blur_off(s)), samples=64)
    assert not within(sharp, cycles)


def _camera_zoom(scene):
    """The cube stands still off-centre and the camera zooms from 10 to 90 mm over frames
    0..2 (40 to 60 mm within the shutter)."""
    import bpy
    bpy.data.objects["Cube"].animation_data_clear()
    bpy.data.objects["Cube"].location.x = 0.8
    data = scene.camera.data
    for frame, lens in ((0, 10.0), (2, 90.0)):
        data.lens = lens
        data.keyframe_insert("lens", frame=frame)
    _linear(data)
    scene.frame_set(1)


def test_zooming_camera_matches_cycles(bpy_drt):
    from drt_addon import render_engine
    cycles = render(bpy_drt, CUBE, "CYCLES", "zoom", _camera_zoom)
    drt = render(bpy_drt, CUBE, "DRT", "zoom", _camera_zoom, samples=128)
    cam = render_engine.last_render["scene"].camera
    assert cam.motion is None
    np.testing.assert_allclose(cam.lens_motion[1], [40.0, 50.0, 60.0], rtol=1e-5)
    rel, mad = compare(drt, cycles)
    sharp = render(bpy_drt, CUBE, "DRT", "zoom off",
                   lambda s: (_camera_zoom(s), _blur_off(s)), samples=64)
    print(f"zooming camera: mean {100 * rel.max():.3f}%, MAD {100 * mad:.2f}%; without "
          f"blur: {compare(sharp, cycles)}")
    assert (rel <= MEAN_TOLERANCE).all() and mad <= MAD_TOLERANCE, (rel, mad)
    assert not within(sharp, cycles)


def test_object_without_motion_blur_sits_at_the_shutters_middle_as_in_cycles(bpy_drt):
    """Cycles exports everything at the shutter's middle and only samples the other
    times for blurred objects: with position START and the cube's motion blur off, the
    cube stands half a shutter after the frame, in both engines."""
    def setup(scene):
        import bpy
        scene.render.motion_blur_position = "START"
        bpy.data.objects["Cube"].cycles.use_motion_blur = False
    cycles = render(bpy_drt, CUBE, "CYCLES", "cube not blurred", setup, samples=256)
    drt = render(bpy_drt, CUBE, "DRT", "cube not blurred", setup, samples=64)
    frame = render(bpy_drt, CUBE, "DRT", "off", _blur_off, samples=64)
    shift = redness_centroid_x(cycles) - redness_centroid_x(frame)
    print(f"unblurred cube: DRT centroid {redness_centroid_x(drt):.2f}, Cycles "
          f"{redness_centroid_x(cycles):.2f}, frame {redness_centroid_x(frame):.2f}")
    assert shift > 8                                      # Cycles moved it: START
    assert abs(redness_centroid_x(drt) - redness_centroid_x(cycles)) < 0.5
    assert within(drt, cycles)


# ------------------------------------------------------------ the static path, frames
@pytest.fixture
def frame_spy(bpy_drt, monkeypatch):
    """Records every frame change the exporter makes (and still makes it)."""
    from drt_addon.export import motion
    calls = []
    original = motion.set_frame

    def spy(target, frame, subframe):
        calls.append((type(target).__name__, int(frame), round(float(subframe), 6)))
        original(target, frame, subframe)
    monkeypatch.setattr(motion, "set_frame", spy)
    return calls


def _render_small(bpy, samples=4):
    from drt_addon import render_engine
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    scene.drt.samples = samples
    scene.cycles.diffuse_bounces = 0
    try:
        bpy.ops.render.render()
    except RuntimeError:          # the operator raises when the engine reported an error
        pass
    return render_engine.last_render


def test_motion_blur_off_takes_the_static_path_without_changing_frames(bpy_drt, frame_spy):
    from drt_addon.export import export_scene
    bpy = bpy_drt
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    scene = bpy.context.scene
    for off in ("use_motion_blur", "shutter 0"):
        if off == "use_motion_blur":
            scene.render.use_motion_blur = False
        else:
            scene.render.use_motion_blur = True
            scene.render.motion_blur_shutter = 0.0
        s = export_scene(bpy.context.evaluated_depsgraph_get())
        assert s.shutter is None and not s.has_motion()
        assert all(m.motion is None for m in s.meshes) and s.camera.motion is None
        last = _render_small(bpy)
        assert last["ok"] and last["scene"].shutter is None
        assert not last["scene"].has_motion()
    assert frame_spy == []
    # Motion blur on: frames are changed (the spy works) and the cube gets its motion.
    scene.render.motion_blur_shutter = SHUTTER
    s = export_scene(bpy.context.evaluated_depsgraph_get())
    assert s.has_motion() and len(frame_spy) == 3


def test_nothing_moving_attaches_no_motion(bpy_drt):
    bpy = bpy_drt
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    bpy.data.objects["Cube"].animation_data_clear()
    last = _render_small(bpy)
    s = last["scene"]
    assert last["ok"] and s.shutter is not None          # motion blur is on ...
    assert all(m.motion is None for m in s.meshes) and s.camera.motion is None
    assert not s.has_motion()                              # ... but the path is static
    assert last["export_stats"]["motion"]["rigid"] == 0


def test_shutter_zero_and_blur_off_render_the_static_frame(bpy_drt):
    """Shutter 0 renders exactly what motion blur off renders: the cube at frame 1
    (x = 0), not where a blurred render puts the light."""
    off = render(bpy_drt, CUBE, "DRT", "off small", _blur_off, samples=16)
    zero = render(bpy_drt, CUBE, "DRT", "zero small",
                  lambda s: setattr(s.render, "motion_blur_shutter", 0.0), samples=16)
    start_zero = render(bpy_drt, CUBE, "DRT", "zero start small", lambda s: (
        setattr(s.render, "motion_blur_shutter", 0.0), _position("START")(s)), samples=16)
    blurred = render(bpy_drt, CUBE, "DRT", "blurred small", samples=16)
    np.testing.assert_array_equal(zero, off)
    np.testing.assert_array_equal(start_zero, off)
    assert np.abs(blurred - off).mean() > 0.05 * off.mean()


def test_frames_are_sampled_at_the_shutter_and_restored(bpy_drt, frame_spy):
    """Position START from frame 1 + subframe 0.25 with shutter 0.5: the shutter is
    [1.25, 1.75]. The export evaluates the middle (1.5), then the open and close times,
    through RenderEngine.frame_set, and restores frame 1 + 0.25."""
    bpy = bpy_drt
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    scene = bpy.context.scene
    scene.render.motion_blur_position = "START"
    scene.frame_set(1, subframe=0.25)
    last = _render_small(bpy)
    assert last["ok"], last["error"]
    assert [c[1:] for c in frame_spy] == [(1, 0.5), (1, 0.25), (1, 0.75), (1, 0.25)]
    assert all(c[0] == "DRTRenderEngine" for c in frame_spy)
    assert (scene.frame_current, scene.frame_subframe) == (1, 0.25)
    cube = bpy.data.objects["Cube"].evaluated_get(bpy.context.evaluated_depsgraph_get())
    assert cube.matrix_world.translation.x == pytest.approx(CUBE_SPEED * 0.25, abs=1e-6)
    # The exported cube: at the shutter's middle, moving 1 m within the shutter.
    motion = [m for m in last["scene"].meshes if m.name == "Cube"][0].motion
    np.testing.assert_allclose(motion.times, [0.0, 0.5, 1.0])
    np.testing.assert_allclose(motion.matrices[:, 0, 3], [0.5, 1.0, 1.5], atol=1e-6)


def test_frame_is_restored_when_the_export_fails(bpy_drt, monkeypatch):
    from drt_addon.export import motion
    bpy = bpy_drt
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    scene = bpy.context.scene
    original = motion.set_frame
    calls = []

    def failing(target, frame, subframe):
        calls.append((frame, subframe))
        original(target, frame, subframe)
        if len(calls) == 2:
            raise RuntimeError("evaluation failed")
    monkeypatch.setattr(motion, "set_frame", failing)
    scene.render.motion_blur_position = "END"
    last = _render_small(bpy)
    assert not last["ok"] and "evaluation failed" in last["error"]
    assert calls[-1] == (1, 0.0) and len(calls) == 3
    assert (scene.frame_current, scene.frame_subframe) == (1, 0.0)


# ------------------------------------------------------------------ export details
def _export(bpy, reporter=None):
    from drt_addon.export import export_scene
    return export_scene(bpy.context.evaluated_depsgraph_get(), reporter)


def _mesh(scene, name):
    return [m for m in scene.meshes if m.name == name][0]


def test_motion_steps_and_per_object_toggles(bpy_drt):
    """motion_steps n gives 2**n + 1 transforms over the shutter (Cycles' count), each
    the evaluated transform at its time; use_motion_blur off leaves the object still."""
    bpy = bpy_drt
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    cube = bpy.data.objects["Cube"]
    cube.cycles.motion_steps = 2
    s = _export(bpy)
    motion = _mesh(s, "Cube").motion
    np.testing.assert_allclose(motion.times, [0, 0.25, 0.5, 0.75, 1])
    # Shutter [0.75, 1.25] around frame 1, x = 2 (frame - 1).
    np.testing.assert_allclose(motion.matrices[:, 0, 3], [-0.5, -0.25, 0, 0.25, 0.5], atol=1e-6)
    assert bpy.context.scene.frame_current == 1 and bpy.context.scene.frame_subframe == 0
    cube.cycles.use_motion_blur = False
    s = _export(bpy)
    assert _mesh(s, "Cube").motion is None and not s.has_motion()


def _cube_collection(bpy):
    """The motion cube's file with the cube, its animation cleared, alone in a collection
    the view layer excludes (for instancers to instance): (scene, collection)."""
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    scene = bpy.context.scene
    cube = bpy.data.objects["Cube"]
    cube.animation_data_clear()
    coll = bpy.data.collections.new("Group")
    scene.collection.children.link(coll)
    scene.collection.objects.unlink(cube)
    coll.objects.link(cube)
    scene.view_layers[0].layer_collection.children["Group"].exclude = True
    return scene, coll


def test_moving_instancer_blurs_its_instances_mirrored_ones_too(bpy_drt):
    """A collection instanced twice by a moving empty (once mirrored): every instance gets
    a rigid motion whose middle transform places it where the static export does, with
    the same triangle winding (geometric normals pointing the same way)."""
    from engine.instancing import expand
    from engine.motion import RigidMotion
    bpy = bpy_drt
    scene, coll = _cube_collection(bpy)
    for i, sx in enumerate((1.0, -1.0)):
        empty = bpy.data.objects.new(f"Spawner{i}", None)
        empty.instance_type = "COLLECTION"
        empty.instance_collection = coll
        empty.scale = (sx, 1.0, 1.0)
        scene.collection.objects.link(empty)
        for frame in (0, 2):
            empty.location = ((frame - 1) * CUBE_SPEED, 0.6 * i, 0.0)
            empty.keyframe_insert("location", frame=frame)
        _linear(empty)
    scene.frame_set(1)
    blurred = _export(bpy)
    scene.render.use_motion_blur = False
    still = _export(bpy)
    moving = [m for m in blurred.meshes if m.name.startswith("Cube#")]
    # without blur the two places are one instanced mesh: its world copies
    # (engine.instancing.expand, whose winding a mirror turns over as the tracer does)
    fixed = [c for m in still.meshes if m.name.startswith("Cube#") for c in expand(m)]
    assert len(moving) == len(fixed) == 2
    for m, f in zip(moving, fixed):
        assert isinstance(m.motion, RigidMotion) and not m.motion.is_static()
        mid = m.motion.at(np.array([0.5]))[0]
        world = m.positions @ mid[:3, :3].T + mid[:3, 3]
        np.testing.assert_allclose(world, f.positions, atol=1e-6)
        n_m = np.cross(world[m.triangles[:, 1]] - world[m.triangles[:, 0]],
                       world[m.triangles[:, 2]] - world[m.triangles[:, 0]])
        n_f = np.cross(f.positions[f.triangles[:, 1]] - f.positions[f.triangles[:, 0]],
                       f.positions[f.triangles[:, 2]] - f.positions[f.triangles[:, 0]])
        assert ((n_m * n_f).sum(1) > 0).all()
        assert abs(m.motion.matrices[2, 0, 3] - m.motion.matrices[0, 0, 3]) == pytest.approx(
            CUBE_SPEED * SHUTTER)


def test_scaling_through_zero_is_traced_as_a_deformation(bpy_drt):
    """A cube growing from scale 0 has no inverse transform at the shutter's open: it is
    exported as world-space vertices over the shutter, and renders."""
    from engine.motion import DeformMotion
    bpy = bpy_drt
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    cube = bpy.data.objects["Cube"]
    cube.animation_data_clear()
    for frame, scale in ((0.75, 0.0), (1.25, 1.0)):
        cube.scale = (scale,) * 3
        cube.keyframe_insert("scale", frame=frame)
    _linear(cube)
    bpy.context.scene.frame_set(1)
    s = _export(bpy)
    motion = _mesh(s, "Cube").motion
    assert isinstance(motion, DeformMotion)
    assert np.abs(motion.positions[0]).max() < 1e-6          # a point at the open
    last = _render_small(bpy)
    assert last["ok"], last["error"]
    assert np.isfinite(last["pixels"]).all()


def test_deformation_is_exported_in_world_space(bpy_drt):
    from engine.motion import DeformMotion
    bpy = bpy_drt
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    _shape_key_motion(bpy.context.scene)
    s = _export(bpy)
    cube = _mesh(s, "Cube")
    assert isinstance(cube.motion, DeformMotion)
    np.testing.assert_allclose(cube.motion.times, [0, 0.5, 1])
    # x of every vertex moves by CUBE_SPEED x SHUTTER = 1 m, around the frame's place.
    dx = cube.motion.positions[:, :, 0] - cube.motion.positions[1, :, 0]
    np.testing.assert_allclose(dx, [[-0.5] * 8, [0] * 8, [0.5] * 8], atol=1e-5)
    np.testing.assert_allclose(cube.motion.positions[1], cube.positions, atol=1e-6)
    assert abs(cube.positions[:, 0].mean()) < 1e-5


def _growing_grid(obj):
    """Geometry nodes replacing the mesh by a grid with 4 + 4 x frame columns: its
    topology changes with time (and Object.is_deform_modified says so)."""
    import bpy
    tree = bpy.data.node_groups.new("Grow", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = tree.nodes, tree.links
    nodes.new("NodeGroupInput")
    out = nodes.new("NodeGroupOutput")
    frame = nodes.new("GeometryNodeInputSceneTime")
    mul = nodes.new("ShaderNodeMath")
    mul.operation, mul.inputs[1].default_value = "MULTIPLY", 4.0
    add = nodes.new("ShaderNodeMath")
    add.operation, add.inputs[1].default_value = "ADD", 4.0
    grid = nodes.new("GeometryNodeMeshGrid")
    links.new(frame.outputs["Frame"], mul.inputs[0])
    links.new(mul.outputs[0], add.inputs[0])
    links.new(add.outputs[0], grid.inputs["Vertices X"])
    links.new(grid.outputs["Mesh"], out.inputs[0])
    obj.modifiers.new("Grow", "NODES").node_group = tree


def test_topology_change_warns_and_keeps_the_middle_geometry(bpy_drt):
    """Geometry whose vertex count changes within the shutter cannot be blurred as a
    deformation: the export says so and keeps the shutter-middle geometry (its movement
    still blurs)."""
    from drt_addon.export import Reporter
    from engine.motion import RigidMotion
    bpy = bpy_drt
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    cube = bpy.data.objects["Cube"]
    _growing_grid(cube)
    bpy.context.scene.frame_set(1)
    reporter = Reporter()
    s = _export(bpy, reporter)
    assert any("changes topology" in w and "'Cube'" in w for w in reporter.warnings), \
        reporter.warnings
    mesh = _mesh(s, "Cube")
    assert isinstance(mesh.motion, RigidMotion)
    assert len(mesh.positions) == 8 * 3       # 4 + 4 x 1 columns, 3 rows: at frame 1


def test_moving_light_is_exported_in_time_slices(bpy_drt):
    """A lamp keyed to move gets 8 slices over the shutter (the issue asks moving lamps to
    blur; Cycles itself renders lamps at the shutter's middle, so there is no Cycles
    reference for this one): slice positions run across the lamp's path over the shutter,
    in order, symmetric about the middle; a still lamp gets none."""
    from drt_addon.export import Reporter
    from drt_addon.export.motion import LIGHT_SLICES
    bpy = bpy_drt
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    light = bpy.data.objects["Light"]
    s = _export(bpy, Reporter())
    assert not getattr(s.lights[0], "motion_slices", None)
    x0 = float(light.location.x)
    for frame in (0, 2):
        light.location.x = x0 + (frame - 1.0)
        light.keyframe_insert("location", index=0, frame=frame)
    _linear(light)
    bpy.context.scene.frame_set(1)
    reporter = Reporter()
    s = _export(bpy, reporter)
    assert not any("moves during the shutter" in w for w in reporter.warnings)
    slices = s.lights[0].motion_slices
    assert len(slices) == LIGHT_SLICES
    xs = np.array([np.asarray(sl.matrix)[0, 3] if hasattr(sl, "matrix") else sl.position[0]
                   for sl in slices]) - x0
    shutter = bpy.context.scene.render.motion_blur_shutter
    expected = (np.arange(LIGHT_SLICES) + 0.5) / LIGHT_SLICES * shutter - shutter / 2
    np.testing.assert_allclose(xs, expected, atol=1e-6)
    assert s.has_motion()
    from drt_addon.render_engine import last_render
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    scene.drt.samples = 4
    bpy.ops.render.render()
    assert last_render["ok"] and np.isfinite(last_render["pixels"]).all()


def test_default_shutter_curve_is_a_box_shutter(bpy_drt):
    bpy = bpy_drt
    bpy.ops.wm.open_mainfile(filepath=CUBE, load_ui=False)
    assert _export(bpy).shutter.curve is None
    _ramp_shutter(bpy.context.scene)
    curve = _export(bpy).shutter.curve
    assert curve.shape == (256,)
    np.testing.assert_allclose(curve, np.arange(256) / 255, atol=0.01)
    assert math.isclose(bpy.context.scene.render.motion_blur_shutter, SHUTTER)


def test_still_instances_stay_instances_with_motion_blur_on(bpy_drt):
    """A collection instanced by three empties that stand still and one that moves, with
    motion blur on: the still places are one instanced mesh of three places
    (export.instances.regroup_still, where Blender puts them), the moving one a mesh of
    its own with its motion; the same samples render the scene with the still places
    expanded into copies to 1e-3 of the image."""
    import copy as copying
    from engine import RenderSettings, render
    from engine.instancing import expand
    from engine.motion import RigidMotion
    bpy = bpy_drt
    scene, coll = _cube_collection(bpy)
    for i in range(4):
        empty = bpy.data.objects.new(f"Spawner{i}", None)
        empty.instance_type = "COLLECTION"
        empty.instance_collection = coll
        empty.location = (0.0, 0.7 * i, 0.0)
        scene.collection.objects.link(empty)
        if i == 3:
            for frame in (0, 2):
                empty.location = ((frame - 1) * CUBE_SPEED, 0.7 * i, 0.0)
                empty.keyframe_insert("location", frame=frame)
            _linear(empty)
    scene.frame_set(1)
    assert scene.render.use_motion_blur
    blurred = _export(bpy)
    cubes = [m for m in blurred.meshes if m.name.startswith("Cube#")]
    still = [m for m in cubes if m.instances is not None]
    moving = [m for m in cubes if m.instances is None]
    assert len(still) == 1 and len(still[0].instances) == 3
    assert len(moving) == 1 and isinstance(moving[0].motion, RigidMotion)
    places = sorted(still[0].instances.matrices[:, 1, 3])
    np.testing.assert_allclose(places, [0.0, 0.7, 1.4], atol=1e-6)
    assert blurred.has_motion()
    copies = copying.copy(blurred)
    copies.meshes = [c for m in blurred.meshes for c in expand(m)]
    settings = RenderSettings(samples=16, seed=5)
    a, b = (render(s, settings)[0].mean() for s in (blurred, copies))
    assert a.mean() > 0.01
    assert np.abs(a - b).mean() < 1e-3 * a.mean()
