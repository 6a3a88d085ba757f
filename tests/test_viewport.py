"""The Rendered viewport's session (drt_addon.viewport) and its camera
(drt_addon.viewport_camera), in the bpy module: the same code Blender's view_update and
view_draw call, driven by the depsgraph's real updates (a depsgraph_update_post handler
passes them, as Blender passes them to view_update) and a 3D view's matrices.
tests/test_viewport_window.py drives it in a real Blender window.

The viewport's full-resolution film is exactly the final render's (the same camera, seed
and sample indices; films of disjoint sample ranges merge exactly), so an image after an
edit is checked against a fresh export's render, not against a threshold.
"""
from __future__ import annotations

import threading
import time
import types

import numpy as np
import pytest

W, H = 64, 40
SAMPLES = 8


def _wait(session, samples, timeout=300.0):
    """The published (rgba bottom-up, samples) once `samples` are in, or fail."""
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < timeout:
        assert session.error is None, session.error
        p = session.published
        if p is not None and p[0] == session.generation and p[2] >= samples and p[3] == 1:
            return p
        time.sleep(0.02)
    raise AssertionError(f"no {samples}-sample image in {timeout} s")


def _context(rv3d, use_border=False, border=(0, 0, 1, 1)):
    space = types.SimpleNamespace(use_render_border=use_border,
                                  render_border_min_x=border[0], render_border_min_y=border[1],
                                  render_border_max_x=border[2], render_border_max_y=border[3])
    return types.SimpleNamespace(region=types.SimpleNamespace(width=W, height=H),
                                 space_data=space, region_data=rv3d)


def _camera_view(bpy, cam):
    dg = bpy.context.evaluated_depsgraph_get()
    return types.SimpleNamespace(view_perspective="CAMERA",
                                 view_matrix=cam.matrix_world.inverted(),
                                 window_matrix=cam.calc_matrix_camera(dg, x=W, y=H))


@pytest.fixture
def scene(bpy_drt):
    bpy = bpy_drt
    bpy.ops.wm.read_factory_settings(use_empty=True)
    s = bpy.context.scene
    s.render.engine = "DRT"
    s.render.resolution_x, s.render.resolution_y = W, H
    s.cycles.preview_samples = SAMPLES
    s.cycles.use_preview_denoising = False
    bpy.ops.mesh.primitive_plane_add(size=20)
    bpy.ops.mesh.primitive_cube_add(size=1, location=(0, 0, 0.5))
    cube = bpy.context.object
    mat = bpy.data.materials.new("Red")
    if mat.node_tree is None:                       # Blender before 5.0
        mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.05, 0.05, 1)
    cube.data.materials.append(mat)
    bpy.ops.object.light_add(type="POINT", location=(1, -1, 3))
    bpy.context.object.data.energy = 500
    bpy.ops.object.camera_add(location=(0, -6, 2), rotation=(1.396, 0, 0))
    s.camera = bpy.context.object
    s.world = None                                  # black: only the lamp lights the scene
    return bpy


@pytest.fixture
def session(scene):
    """A ViewportSession synced by the depsgraph's updates, as view_update syncs it."""
    bpy = scene
    from drt_addon.export import Reporter
    from drt_addon.viewport import ViewportSession
    redraws = []
    s = ViewportSession(lambda: redraws.append(time.perf_counter()))
    s.redraws = redraws
    s.context = _context(_camera_view(bpy, bpy.context.scene.camera))

    def on_update(_scene, depsgraph):
        s.sync(depsgraph, s.context, Reporter())

    s.on_update = on_update
    bpy.app.handlers.depsgraph_update_post.append(on_update)
    s.sync(bpy.context.evaluated_depsgraph_get(), s.context, Reporter())
    yield s
    if on_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(on_update)
    s.free()


def _final(session, samples=SAMPLES):
    """engine.render of a fresh export of the viewport's view (no memo): the reference."""
    import bpy
    import engine
    from drt_addon.export import export_scene
    from drt_addon.viewport import viewport_settings
    view = session.view
    d = export_scene(bpy.context.evaluated_depsgraph_get(), view=(view.camera, view.width,
                                                                   view.height))
    settings = viewport_settings(bpy.context.scene)
    from dataclasses import replace
    film, _ = engine.render(d, replace(settings, samples=samples))
    return film.mean()


def _image(published):
    return published[1][::-1, :, :3].astype(np.float64)


def _same(a, b):
    assert a.shape == b.shape
    err = np.abs(a - b).max() / max(b.max(), 1e-9)
    assert err < 1e-5, err


def test_projection_camera_traces_the_scene_cameras_rays(scene):
    """Camera view: the camera read off the view and window matrices gives the scene
    camera's own rays at every pixel (perspective with shift and each sensor fit,
    orthographic), clip planes included."""
    bpy = scene
    from engine.camera import CameraModel
    from drt_addon.export.camera import export_camera
    from drt_addon.viewport_camera import projection_camera
    cam = bpy.context.scene.camera
    ys, xs = np.mgrid[0:H, 0:W]
    xy = np.stack([xs.ravel() + 0.5, ys.ravel() + 0.5], axis=1).astype(np.float64)
    cases = [("PERSP", "AUTO"), ("PERSP", "VERTICAL"), ("ORTHO", "AUTO")]
    for kind, fit in cases:
        cam.data.type, cam.data.sensor_fit = kind, fit
        cam.data.shift_x, cam.data.shift_y = 0.1, -0.05
        cam.data.clip_start, cam.data.clip_end = 0.25, 40.0
        dg = bpy.context.evaluated_depsgraph_get()
        want = CameraModel(export_camera(cam, dg), W, H).generate(xy)
        rv3d = _camera_view(bpy, cam)
        got = CameraModel(projection_camera(rv3d.view_matrix, rv3d.window_matrix), W,
                          H).generate(xy)
        # Blender's matrices are float32: agreement to float32's precision
        assert np.abs(got.directions - want.directions).max() < 1e-6, (kind, fit)
        assert np.abs(got.origins - want.origins).max() < 1e-5, (kind, fit)
        assert np.abs(got.tmax - want.tmax).max() < 1e-5 * want.tmax.max(), (kind, fit)


@pytest.mark.parametrize("ortho", [False, True])
def test_user_view_rays_go_through_their_pixels(bpy_drt, ortho):
    """A user view (off-centre, as a panned view): each pixel centre's ray starts on the
    near plane, ends on the far plane and projects onto that pixel centre."""
    from engine.camera import CameraModel
    from drt_addon.viewport_camera import projection_camera
    rng = np.random.default_rng(3)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))
    view = np.eye(4)
    view[:3, :3], view[:3, 3] = q.T, -q.T @ np.array([3.0, -2.0, 1.0])
    n, f, l, r, b, t = 0.5, 200.0, -0.3, 0.5, -0.25, 0.35
    proj = np.zeros((4, 4))
    if ortho:
        l, r, b, t = 10 * l, 10 * r, 10 * b, 10 * t
        n = -100.0
        proj[0, 0], proj[0, 3] = 2 / (r - l), -(r + l) / (r - l)
        proj[1, 1], proj[1, 3] = 2 / (t - b), -(t + b) / (t - b)
        proj[2, 2], proj[2, 3], proj[3, 3] = -2 / (f - n), -(f + n) / (f - n), 1.0
    else:
        proj[0, 0], proj[0, 2] = 2 * n / (r - l), (r + l) / (r - l)
        proj[1, 1], proj[1, 2] = 2 * n / (t - b), (t + b) / (t - b)
        proj[2, 2], proj[2, 3], proj[3, 2] = -(f + n) / (f - n), -2 * f * n / (f - n), -1.0
    width, height = 80, 60            # (r - l) / (t - b) = 80 / 60: square pixels
    model = CameraModel(projection_camera(view, proj), width, height)
    xy = rng.uniform(0, 1, size=(50, 2)) * [width, height]
    rays = model.generate(xy)
    for point, depth in ((rays.origins, -1.0), (rays.origins + rays.directions *
                                                 rays.tmax[:, None], 1.0)):
        clip = (proj @ view @ np.c_[point, np.ones(len(point))].T).T
        ndc = clip[:, :3] / clip[:, 3:]
        want = np.c_[xy[:, 0] / width * 2 - 1, 1 - xy[:, 1] / height * 2]
        assert np.abs(ndc[:, :2] - want).max() < 1e-6
        assert np.abs(ndc[:, 2] - depth).max() < 1e-6


def test_viewport_renders_the_final_renders_image_and_follows_edits(session):
    """The first image is the final render's; a moved cube, a new Base Color and a
    lamp's power re-export no mesh (a colour: one material), and each image after them
    is again exactly a fresh export's render; navigation restarts without an export."""
    import bpy
    from drt_addon.viewport import last_viewport
    s = session
    assert last_viewport["first_sync"] and last_viewport["export_stats"]["mesh_evaluations"] == 2
    first = _image(_wait(s, SAMPLES))
    _same(first, _final(s))
    assert s.redraws, "the render thread never asked for a redraw"
    print(f"\nviewport: first sync: export {last_viewport['export_seconds']:.3f} s, build "
          f"{last_viewport['build_seconds']:.3f} s, first image "
          f"{last_viewport['first_image_seconds']:.3f} s")

    edits = {
        "move": lambda: setattr(bpy.data.objects["Cube"].location, "x", 1.0),
        "colour": lambda: bpy.data.materials["Red"].node_tree.nodes["Principled BSDF"]
        .inputs["Base Color"].__setattr__("default_value", (0.05, 0.8, 0.05, 1)),
        "lamp": lambda: setattr(bpy.data.lights[0], "energy", 1000.0),
    }
    before = first
    for name, change in edits.items():
        syncs = last_viewport["syncs"]
        change()
        bpy.context.view_layer.update()                   # fires the update handler
        assert last_viewport["syncs"] == syncs + 1, name
        stats = last_viewport["export_stats"]
        assert stats["mesh_evaluations"] == 0, (name, stats)
        assert stats["material_exports"] == (1 if name == "colour" else 0), (name, stats)
        # a lamp's edit keeps the acceleration structure (RenderContext.relit)
        assert last_viewport["rebuilt"] == (name != "lamp"), name
        image = _image(_wait(s, SAMPLES))
        print(f"viewport {name}: export {last_viewport['export_seconds']:.3f} s, build "
              f"{last_viewport['build_seconds']:.3f} s, first image "
              f"{last_viewport['first_image_seconds']:.3f} s")
        _same(image, _final(s))
        assert np.abs(image - before).max() > 0.05, name
        if name == "lamp":                 # the same samples, twice the light
            _same(image, 2.0 * before)
        before = image

    # a selection is no edit: nothing restarts
    gen = s.generation
    bpy.data.objects["Cube"].select_set(True)
    bpy.context.view_layer.update()
    assert s.generation == gen

    # navigation: a new view, no export
    from drt_addon.viewport_camera import view_of
    syncs = last_viewport["syncs"]
    cam = bpy.context.scene.camera
    cam.location.x -= 1.0
    bpy.app.handlers.depsgraph_update_post.remove(s.on_update)   # the view alone moves
    bpy.context.view_layer.update()
    s.context = _context(_camera_view(bpy, cam))
    assert s.look(view_of(s.context, bpy.context.evaluated_depsgraph_get()))
    moved = _image(_wait(s, SAMPLES))
    assert last_viewport["syncs"] == syncs
    _same(moved, _final(s))


def test_viewport_without_a_scene_camera(scene):
    """A user view needs no scene camera (the final render does)."""
    bpy = scene
    from drt_addon.export import Reporter
    from drt_addon.viewport import ViewportSession
    cam = bpy.context.scene.camera
    rv3d = _camera_view(bpy, cam)
    rv3d.view_perspective = "PERSP"
    bpy.data.objects.remove(cam)
    assert bpy.context.scene.camera is None
    s = ViewportSession(lambda: None)
    try:
        s.sync(bpy.context.evaluated_depsgraph_get(), _context(rv3d), Reporter())
        image = _image(_wait(s, 2))
        assert image.shape == (H, W, 3) and image.max() > 0.05
    finally:
        s.free()


def test_render_region_traces_only_its_pixels(scene):
    """View > Render Region: the traced image is the border's rectangle, and its rays are
    the whole view's rays through those pixels."""
    bpy = scene
    from engine.camera import CameraModel
    from drt_addon.export import Reporter
    from drt_addon.viewport import ViewportSession
    from drt_addon.viewport_camera import view_of
    rv3d = _camera_view(bpy, bpy.context.scene.camera)
    rv3d.view_perspective = "PERSP"
    ctx = _context(rv3d, use_border=True, border=(0.25, 0.5, 0.75, 1.0))
    view = view_of(ctx, bpy.context.evaluated_depsgraph_get())
    r = view.region
    assert (r.x, r.y, r.width, r.height) == (16, 20, 32, 20)
    ys, xs = np.mgrid[0:r.height, 0:r.width]
    xy = np.stack([xs.ravel() + 0.5, ys.ravel() + 0.5], axis=1).astype(np.float64)
    part = CameraModel(view.traced_camera(), r.width, r.height).generate(xy)
    top = H - (r.y + r.height)
    whole = CameraModel(view.camera, W, H).generate(xy + [r.x, top])
    assert np.abs(part.directions - whole.directions).max() < 1e-9
    s = ViewportSession(lambda: None)
    try:
        s.sync(bpy.context.evaluated_depsgraph_get(), ctx, Reporter())
        assert _image(_wait(s, 1)).shape == (20, 32, 3)
    finally:
        s.free()


def test_viewport_denoises_as_its_settings_ask(scene):
    """Sampling > Viewport > Denoise: from the start sample on, the published image is
    OpenImageDenoise's, nearer a 256-sample render than the noisy image it came from."""
    bpy = scene
    from engine.denoiser import available
    if available() is not None:
        pytest.fail(f"OpenImageDenoise is not available: {available()}")
    from drt_addon.export import Reporter
    from drt_addon.viewport import ViewportSession, last_viewport
    c = bpy.context.scene.cycles
    c.use_preview_denoising, c.preview_denoising_start_sample = True, 2
    c.preview_samples = 4
    s = ViewportSession(lambda: None)
    try:
        s.context = _context(_camera_view(bpy, bpy.context.scene.camera))
        s.sync(bpy.context.evaluated_depsgraph_get(), s.context, Reporter())
        denoised = _image(_wait(s, 4))
        assert last_viewport["denoised"] and "denoised" in s.status()
        noisy = _final(s, 4)
        reference = _final(s, 256)

        def rel_mse(img):
            return float(np.mean((img - reference) ** 2 / (reference ** 2 + 1e-2)))
        print(f"\nviewport denoise: relMSE noisy {rel_mse(noisy):.4f}, denoised "
              f"{rel_mse(denoised):.4f}")
        assert rel_mse(denoised) < 0.7 * rel_mse(noisy)
    finally:
        s.free()


def test_viewport_shows_a_shadow_catcher_as_the_final_render(scene):
    """A shadow catcher floor in the viewport: the image and alpha are Cycles' matte with
    the shadow laid in (its viewport form), exactly what a fresh export's film gives."""
    bpy = scene
    import engine
    from dataclasses import replace
    from drt_addon import shadow_catcher
    from drt_addon.export import Reporter, export_scene
    from drt_addon.viewport import ViewportSession, viewport_settings
    bpy.data.objects["Plane"].is_shadow_catcher = True
    bpy.context.scene.render.film_transparent = True
    s = ViewportSession(lambda: None)
    try:
        s.context = _context(_camera_view(bpy, bpy.context.scene.camera))
        s.sync(bpy.context.evaluated_depsgraph_get(), s.context, Reporter())
        published = _wait(s, SAMPLES)[1][::-1].astype(np.float64)
        view = s.view
        d = export_scene(bpy.context.evaluated_depsgraph_get(),
                         view=(view.camera, view.width, view.height))
        settings = replace(viewport_settings(bpy.context.scene), samples=SAMPLES)
        ctx = engine.RenderContext(d, settings)
        try:
            film, _ = engine.render(d, settings, context=ctx)
            rgb, alpha = shadow_catcher.combined(ctx, film, None)
        finally:
            ctx.close()
        _same(published[..., :3], rgb)
        np.testing.assert_allclose(published[..., 3], alpha, atol=1e-6)
        # the floor is a hole but for the cube's shadow on it
        assert 0.2 < (alpha < 0.05).mean() < 0.95 and (alpha > 0.5).mean() > 0.05
    finally:
        s.free()
        bpy.data.objects["Plane"].is_shadow_catcher = False
        bpy.context.scene.render.film_transparent = False


def test_free_stops_the_render_threads(session):
    """Leaving Rendered mode frees the engine: no viewport thread is left tracing."""
    session.free()
    alive = [t.name for t in threading.enumerate() if t.name.startswith("DRT viewport")]
    assert alive == []


def test_viewport_settings_read_cycles_viewport_samples(scene):
    from drt_addon.viewport import UNLIMITED, viewport_settings
    bpy = scene
    c = bpy.context.scene.cycles
    c.preview_samples = 24
    assert viewport_settings(bpy.context.scene).samples == 24
    c.preview_samples = 0                                   # Cycles: no limit
    assert viewport_settings(bpy.context.scene).samples == UNLIMITED


def test_pause_keeps_the_image_and_traces_nothing(scene):
    """Cycles' Pause (scene.cycles.preview_pause, the header's button): a paused view
    starts no thread and says so; resumed, it traces again; paused mid-render, its thread
    stops."""
    bpy = scene
    from drt_addon.export import Reporter
    from drt_addon.viewport import ViewportSession

    def tracing():
        return [t for t in threading.enumerate() if t.name.startswith("DRT viewport")
                and t.is_alive()]
    c = bpy.context.scene.cycles
    c.preview_pause, c.preview_samples = True, 1 << 20
    s = ViewportSession(lambda: None)
    try:
        ctx = _context(_camera_view(bpy, bpy.context.scene.camera))
        dg = bpy.context.evaluated_depsgraph_get()
        s.sync(dg, ctx, Reporter())
        assert s.paused and s.status() == "DRT: paused" and not tracing()
        c.preview_pause = False
        s.follow_pause(bpy.context.scene, ctx, dg)
        _wait(s, 1)
        assert tracing()                              # refining towards 2^20 samples
        c.preview_pause = True
        s.follow_pause(bpy.context.scene, ctx, dg)
        t0 = time.perf_counter()
        while tracing() and time.perf_counter() - t0 < 30.0:
            time.sleep(0.02)
        assert not tracing() and s.published is not None
    finally:
        c.preview_pause = False
        s.free()
