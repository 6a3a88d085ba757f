"""The Vector pass (engine.motion_vectors) against Cycles' own, through the compositor as
an artist gets it: an object that moves, a camera that turns, a mesh that deforms (a
shape key), and motion blur on (both engines write zeros then). Cycles renders one
centred sample per pixel (its Vector pass is its samples' mean; DRT's is the pixel
centre's), so the two agree to float precision inside objects; pixels on a silhouette,
where a centre and a sample may see different surfaces, are left out (a one-pixel border).
"""
from __future__ import annotations

import numpy as np
import pytest

from conftest import read_render_rgba
from test_passes import composite

W, H = 64, 48


def _scene(bpy, camera_turns=False, deforms=False, blur=False):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    s = bpy.context.scene
    s.render.resolution_x, s.render.resolution_y, s.render.resolution_percentage = W, H, 100
    bpy.ops.mesh.primitive_cube_add(size=1, location=(0, 0, 0))
    cube = bpy.context.object
    for frame, x, z in ((1, -0.5, -0.25), (3, 0.5, 0.25)):
        cube.location.x, cube.location.z = x, z
        cube.keyframe_insert("location", frame=frame)
    if deforms:                           # a plane behind whose far corner rises
        bpy.ops.mesh.primitive_plane_add(size=4, location=(0, 2, 0), rotation=(1.5708, 0, 0))
        plane = bpy.context.object
        plane.shape_key_add(name="Basis")
        key = plane.shape_key_add(name="Lift")
        key.data[3].co.z += 1.0
        for frame, value in ((1, 0.0), (3, 1.0)):
            key.value = value
            key.keyframe_insert("value", frame=frame)
    bpy.ops.object.camera_add(location=(0, -6, 0), rotation=(1.5707963, 0, 0))
    s.camera = bpy.context.object
    if camera_turns:
        for frame, rz in ((1, 0.0), (3, 0.1)):
            s.camera.rotation_euler.z = rz
            s.camera.keyframe_insert("rotation_euler", index=2, frame=frame)
    for obj in s.objects:                 # linear keys: the motion is the same each frame
        action = obj.animation_data.action if obj.animation_data else None
        for curve in _curves(action):
            for k in curve.keyframe_points:
                k.interpolation = "LINEAR"
    if deforms:
        for curve in _curves(plane.data.shape_keys.animation_data.action):
            for k in curve.keyframe_points:
                k.interpolation = "LINEAR"
    s.frame_set(2)
    s.view_layers[0].use_pass_vector = True
    s.render.use_motion_blur = blur
    return s


def _curves(action):
    if action is None:
        return []
    if hasattr(action, "fcurves"):
        return list(action.fcurves)
    return [c for layer in action.layers for strip in layer.strips
            for bag in strip.channelbags for c in bag.fcurves]


def _vectors(bpy, scene, engine):
    scene.render.engine = engine
    if engine == "CYCLES":
        scene.cycles.samples, scene.cycles.filter_width = 1, 0.01
    else:
        scene.drt.samples = 1
    composite(bpy, scene, "Vector")
    bpy.ops.render.render()
    v = read_render_rgba(bpy, scene).reshape(H, W, 4)[::-1]         # top-down
    if engine == "DRT":
        from drt_addon import render_engine
        assert render_engine.last_render["ok"], render_engine.last_render["error"]
        np.testing.assert_allclose(render_engine.last_render["passes"]["Vector"], v,
                                   atol=1e-4)
    return v


def _inside(v):
    """Pixels whose 3 x 3 neighbourhood all moves or all stays (no silhouette)."""
    moving = np.abs(v).max(axis=2) > 0
    pad = np.pad(moving, 1, mode="edge")
    same = np.ones_like(moving)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            same &= pad[dy:dy + H, dx:dx + W] == moving
    return same


@pytest.mark.parametrize("case", ["object", "camera", "deform"])
def test_vector_pass_matches_cycles(bpy_drt, case):
    bpy = bpy_drt
    kw = {"object": {}, "camera": {"camera_turns": True}, "deform": {"deforms": True}}[case]
    cycles = _vectors(bpy, _scene(bpy, **kw), "CYCLES")
    drt = _vectors(bpy, _scene(bpy, **kw), "DRT")
    inside = _inside(cycles) & _inside(drt)
    moving = inside & (np.abs(cycles).max(axis=2) > 0)
    assert moving.sum() > 150, moving.sum()                  # the cube (and the plane)
    err = np.abs(drt - cycles)[inside].max()
    print(f"\nvector pass, {case}: {moving.sum()} moving pixels, largest difference "
          f"{err:.4f} px, largest vector {np.abs(cycles).max():.2f} px")
    assert err < 0.02, err
    # the control: a vector sign or the frame step wrong would be off by pixels
    assert np.abs(cycles[moving]).max() > 2.0


def test_vector_pass_is_zero_with_motion_blur_on(bpy_drt):
    bpy = bpy_drt
    for engine in ("CYCLES", "DRT"):
        v = _vectors(bpy, _scene(bpy, blur=True), engine)
        assert np.abs(v).max() == 0.0, engine
