"""The file's own render settings: Film > Exposure as Cycles applies it, the view
transform's exposure applied by Blender to DRT's result as to Cycles', the caustics
switches read from a saved file, one warning per setting DRT does not honour, and
docs/settings.md written from the same table.

Film Exposure is compared with Cycles on light_sun_angle.blend (a grey plane under a
10-degree sun filling a 48 x 48 view, direct light only), where DRT and Cycles agree to
about 0.01% at exposure 1; the check (means within 1%) fails by a factor 5 when the
exposure is ignored (the control renders DRT at exposure 1 against Cycles' exposed
image)."""
import os
import tempfile

import numpy as np
import pytest

from conftest import SAMPLES_DIR, read_image_linear, render_blend

SUN = os.path.join(SAMPLES_DIR, "light_sun_angle.blend")
SAMPLES = 32
MEAN_TOLERANCE = 0.01

_renders = {}


def _direct_only(exposure):
    def setup(scene):
        scene.cycles.diffuse_bounces = 0
        scene.cycles.film_exposure = exposure
        layer = scene.view_layers[0]
        layer.use_pass_z = True
        layer.drt.use_pass_noise = True
    return setup


def _render(bpy, engine, exposure):
    """(scene-linear image, DRT's last_render copy or None), cached per module."""
    key = (engine, exposure)
    if key not in _renders:
        image = render_blend(bpy, SUN, engine, samples=SAMPLES, percentage=100,
                             setup=_direct_only(exposure))
        last = None
        if engine == "DRT":
            from drt_addon import render_engine
            lr = render_engine.last_render
            last = {"pixels": lr["pixels"].copy(), "alpha": lr["alpha"].copy(),
                    "passes": {k: v.copy() for k, v in lr["passes"].items()},
                    "warnings": list(lr["warnings"])}
        _renders[key] = (image, last)
    return _renders[key]


def _means_match(a, b) -> bool:
    return abs(a.mean() / b.mean() - 1.0) <= MEAN_TOLERANCE


@pytest.mark.parametrize("exposure", [5.0, 0.2])
def test_film_exposure_matches_cycles(bpy_drt, exposure):
    cycles, _ = _render(bpy_drt, "CYCLES", exposure)
    drt, last = _render(bpy_drt, "DRT", exposure)
    cycles_plain, _ = _render(bpy_drt, "CYCLES", 1.0)
    drt_plain, _ = _render(bpy_drt, "DRT", 1.0)
    print(f"exposure {exposure}: DRT mean {drt.mean():.5f}, Cycles {cycles.mean():.5f}, "
          f"ratio {drt.mean() / cycles.mean():.5f}; at exposure 1: DRT {drt_plain.mean():.5f},"
          f" Cycles {cycles_plain.mean():.5f}")
    assert cycles.mean() > 0.01
    # Cycles multiplies the image by the exposure, and so does DRT
    assert cycles.mean() / cycles_plain.mean() == pytest.approx(exposure, rel=1e-3)
    assert _means_match(drt, cycles)
    # the control: DRT ignoring the exposure fails the same check
    assert _means_match(drt_plain, cycles_plain)
    assert not _means_match(drt_plain, cycles)
    assert not any("Exposure" in w for w in last["warnings"]), last["warnings"]


def test_film_exposure_scales_the_light_not_the_data_passes(bpy_drt):
    """As Cycles (PassInfo::use_exposure): Combined scales, Depth does not; DRT Noise is the
    noise of Combined and scales with it; alpha does not. Same seed, so exactly."""
    _, plain = _render(bpy_drt, "DRT", 1.0)
    _, bright = _render(bpy_drt, "DRT", 5.0)
    np.testing.assert_allclose(bright["pixels"], 5.0 * plain["pixels"], rtol=1e-12)
    noise = plain["passes"]["DRT Noise"]
    assert noise.max() > 0
    np.testing.assert_allclose(bright["passes"]["DRT Noise"], 5.0 * noise, rtol=1e-9)
    np.testing.assert_array_equal(bright["passes"]["Depth"], plain["passes"]["Depth"])
    np.testing.assert_array_equal(bright["alpha"], plain["alpha"])


@pytest.mark.parametrize("bad", [-1.0, float("inf"), float("nan")])
def test_film_exposure_must_be_finite_and_not_negative(bad):
    from engine import RenderSettings
    with pytest.raises(ValueError, match="film_exposure"):
        RenderSettings(film_exposure=bad).validate()


def _decode_srgb(v):
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def _saved(bpy, scene, fmt, view_exposure, view_transform=None):
    """The Render Result as Blender writes it with the given view exposure: 16-bit PNG
    values (raw, 0..1) or scene-linear EXR."""
    vs = scene.view_settings
    old = (vs.exposure, vs.view_transform)
    vs.exposure = view_exposure
    if view_transform is not None:
        vs.view_transform = view_transform
    st = scene.render.image_settings
    try:
        with tempfile.TemporaryDirectory() as d:
            if fmt == "EXR":
                st.file_format, st.color_depth = "OPEN_EXR", "32"
                path = os.path.join(d, "out.exr")
                bpy.data.images["Render Result"].save_render(filepath=path, scene=scene)
                return read_image_linear(bpy, path)
            st.file_format, st.color_depth, st.color_mode = "PNG", "16", "RGB"
            path = os.path.join(d, "out.png")
            bpy.data.images["Render Result"].save_render(filepath=path, scene=scene)
            img = bpy.data.images.load(path, check_existing=False)
            img.colorspace_settings.name = "Non-Color"      # the stored values, as they are
            try:
                px = np.empty(img.size[0] * img.size[1] * 4, np.float32)
                img.pixels.foreach_get(px)
            finally:
                bpy.data.images.remove(img)
            return px.reshape(-1, 4)[:, :3].astype(np.float64)
    finally:
        vs.exposure, vs.view_transform = old


_views = {}


def _view_outputs(bpy, engine):
    if engine not in _views:
        render_blend(bpy, SUN, engine, samples=SAMPLES, percentage=100,
                     setup=_direct_only(1.0))
        scene = bpy.context.scene
        scene.render.dither_intensity = 0.0     # no noise added to the written values
        _views[engine] = {
            "standard 0": _decode_srgb(_saved(bpy, scene, "PNG", 0.0, "Standard")),
            "standard -1": _decode_srgb(_saved(bpy, scene, "PNG", -1.0, "Standard")),
            "file 0": _saved(bpy, scene, "PNG", 0.0),          # the file's AgX
            "file +1": _saved(bpy, scene, "PNG", 1.0),
            "exr 0": _saved(bpy, scene, "EXR", 0.0),
            "exr -1": _saved(bpy, scene, "EXR", -1.0),
        }
    return _views[engine]


@pytest.mark.parametrize("engine", ["DRT", "CYCLES"])
def test_view_exposure_is_applied_by_blender(bpy_drt, engine):
    """Color Management > Exposure: Blender multiplies the scene-linear result by
    2^exposure before the view transform, for DRT as for Cycles, and leaves the
    scene-linear EXR alone."""
    out = _view_outputs(bpy_drt, engine)
    ratio = out["standard -1"].mean() / out["standard 0"].mean()
    print(f"{engine}: decoded PNG mean ratio at exposure -1: {ratio:.5f}")
    assert ratio == pytest.approx(0.5, rel=1e-3)
    assert out["standard 0"].mean() == pytest.approx(out["exr 0"].mean(), rel=1e-3)
    np.testing.assert_array_equal(out["exr -1"], out["exr 0"])


def test_view_exposure_gives_drt_the_image_it_gives_cycles(bpy_drt):
    drt, cycles = _view_outputs(bpy_drt, "DRT"), _view_outputs(bpy_drt, "CYCLES")
    assert _means_match(drt["file +1"], cycles["file +1"])
    assert not _means_match(drt["file 0"], cycles["file +1"])     # the exposure shows


# ------------------------------------------------------------------------ warnings

@pytest.fixture
def factory_scene(bpy_drt):
    """Blender's factory startup scene (cube, light, camera), DRT still registered."""
    bpy_drt.ops.wm.read_factory_settings(use_empty=False)
    scene = bpy_drt.context.scene
    assert hasattr(scene, "drt")
    return scene


def _warnings(scene):
    from drt_addon.export import Reporter
    from drt_addon.export.settings_check import check
    reporter = Reporter()
    check(scene, scene.view_layers[0], reporter)
    return reporter.warnings


def _quiet_defaults(scene):
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False


def test_factory_defaults_warn_about_nothing(factory_scene):
    """Blender turns Denoise on by default and DRT denoises as Cycles does (read since
    2026-11-29: it warned before); Cycles' adaptive sampling at its defaults is not warned
    (DRT has its own Noise Threshold, off by default); nothing warns."""
    assert _warnings(factory_scene) == []


def test_no_warning_at_defaults(factory_scene):
    _quiet_defaults(factory_scene)
    assert _warnings(factory_scene) == []


def test_fresh_scene_defaults_are_quiet(bpy_drt):
    """A scene made by bpy.data.scenes.new has Blender's RNA defaults (some differ from
    the startup file's, e.g. the sampling pattern): quiet too."""
    scene = bpy_drt.data.scenes.new("fresh")
    try:
        _quiet_defaults(scene)
        assert _warnings(scene) == []
    finally:
        bpy_drt.data.scenes.remove(scene)


@pytest.mark.parametrize("change, expected", [
    (lambda s: (setattr(s.cycles, "use_adaptive_sampling", True),
                setattr(s.cycles, "adaptive_threshold", 0.05)),
     "Noise Threshold is 0.05, not used: DRT renders with its own Noise Threshold"),
    (lambda s: setattr(s.cycles, "time_limit", 30.0), "Time Limit is 30"),
    (lambda s: setattr(s.cycles, "use_fast_gi", True), "full global illumination"),
    (lambda s: setattr(s.render, "use_freestyle", True), "Freestyle"),
    (lambda s: setattr(s.view_layers[0], "samples", 16), "View Layer > Override > Samples"),
    (lambda s: setattr(s.cycles, "samples", 128), "Max Samples is 128, not used"),
])
def test_a_setting_drt_ignores_warns_once(factory_scene, change, expected):
    _quiet_defaults(factory_scene)
    change(factory_scene)
    warnings = _warnings(factory_scene)
    assert len(warnings) == 1 and expected in warnings[0], warnings


def test_own_settings_warn_only_when_drt_differs(factory_scene):
    _quiet_defaults(factory_scene)
    factory_scene.cycles.samples = 128
    factory_scene.drt.samples = 128
    assert _warnings(factory_scene) == []


def test_light_paths_and_clamps_are_the_files_own(factory_scene):
    """The bounce limits per kind and the clamps are the file's Cycles settings, which
    DRT renders with (as the glass spheres file with Indirect Light clamping off and 8
    bounces needs): no warning, and the engine gets them."""
    _quiet_defaults(factory_scene)
    c = factory_scene.cycles
    c.max_bounces, c.diffuse_bounces, c.glossy_bounces = 8, 2, 3
    c.transmission_bounces, c.transparent_max_bounces, c.volume_bounces = 6, 5, 1
    c.sample_clamp_direct, c.sample_clamp_indirect = 2.0, 0.0
    assert _warnings(factory_scene) == []
    s = factory_scene.drt.to_engine_settings()
    assert (s.max_bounces, s.diffuse_bounces, s.glossy_bounces, s.transmission_bounces,
            s.transparent_bounces, s.volume_bounces, s.clamp_direct, s.clamp_indirect) \
        == (8, 2, 3, 6, 5, 1, 2.0, 0.0)
    assert not hasattr(factory_scene.drt, "max_bounces")      # one vocabulary


def test_light_tree_is_the_files_own(factory_scene):
    """Sampling > Lights > Light Tree is read, not warned about: on (Cycles' default)
    the engine picks lights with the tree, off as Cycles' light distribution."""
    _quiet_defaults(factory_scene)
    assert factory_scene.drt.to_engine_settings().light_tree
    factory_scene.cycles.use_light_tree = False
    assert _warnings(factory_scene) == []
    assert not factory_scene.drt.to_engine_settings().light_tree


def test_the_seed_is_the_files_own_and_animated_changes_it_per_frame(factory_scene):
    """Sampling > Advanced > Seed is the file's; with Use Animated Seed every frame (and
    subframe) has a seed of its own, the same each time that frame renders."""
    _quiet_defaults(factory_scene)
    c = factory_scene.cycles
    c.seed = 7
    assert _warnings(factory_scene) == []
    assert factory_scene.drt.to_engine_settings().seed == 7
    assert not hasattr(factory_scene.drt, "seed")             # one vocabulary
    c.use_animated_seed = True
    assert _warnings(factory_scene) == []
    seeds = []
    for frame, sub in ((1, 0.0), (2, 0.0), (1, 0.0), (1, 0.5), (3, 0.0)):
        factory_scene.frame_set(frame, subframe=sub)
        seeds.append(factory_scene.drt.to_engine_settings().seed)
    assert seeds[0] == seeds[2] and len(set(seeds)) == 4
    c.seed = 8
    factory_scene.frame_set(1)
    assert factory_scene.drt.to_engine_settings().seed not in seeds


def test_animated_seed_changes_the_noise_from_frame_to_frame(bpy_drt):
    """Two frames of a still scene: the same image without Use Animated Seed, other noise
    with it (as in Cycles, whose animated seed is what Blender artists render animations
    with, so that a fixed noise pattern does not sit on the screen)."""
    from conftest import render_current
    bpy = bpy_drt
    images = {}
    for animated in (False, True):
        for frame in (1, 2):
            bpy.ops.wm.open_mainfile(filepath=os.path.join(SAMPLES_DIR, "cornell_box.blend"),
                                     load_ui=False)
            scene = bpy.context.scene
            scene.render.engine = "DRT"
            scene.render.resolution_percentage = 10
            scene.drt.samples = 4
            scene.cycles.use_animated_seed = animated
            scene.frame_set(frame)
            images[animated, frame] = render_current(bpy, scene)
    assert images[False, 1].mean() > 0.01
    np.testing.assert_array_equal(images[False, 1], images[False, 2])
    assert np.abs(images[True, 1] - images[True, 2]).mean() > 0.1 * images[True, 1].mean()
    # the same scene, its noise aside (4 samples on 26 x 26 pixels)
    assert images[True, 1].mean() == pytest.approx(images[False, 1].mean(), rel=0.2)


@pytest.mark.parametrize("kind,width", [("GAUSSIAN", 2.0), ("BOX", 0.5),
                                        ("BLACKMAN_HARRIS", 1.5)])
def test_the_pixel_filter_is_the_files_own(factory_scene, kind, width):
    """Film > Pixel Filter (type and width) is the file's Cycles setting, which DRT renders
    with: no warning, and the engine gets it (tests/test_pixel_filter_vs_cycles.py
    renders each type against Cycles)."""
    _quiet_defaults(factory_scene)
    factory_scene.cycles.pixel_filter_type, factory_scene.cycles.filter_width = kind, width
    assert _warnings(factory_scene) == []
    s = factory_scene.drt.to_engine_settings()
    assert (s.filter_type, s.filter_width) == (kind, width)
    assert not hasattr(factory_scene.drt, "filter_type")      # one vocabulary


def test_settings_that_only_matter_with_another_warn_only_then(factory_scene):
    _quiet_defaults(factory_scene)
    c, r = factory_scene.cycles, factory_scene.render
    c.film_transparent_glass = True          # needs Film > Transparent
    c.rolling_shutter_type = "TOP"           # needs motion blur
    c.texture_limit_render = "512"           # needs Simplify
    c.use_layer_samples = "IGNORE"
    factory_scene.view_layers[0].samples = 16     # ignored by the file itself
    c.adaptive_threshold = 0.1               # part of adaptive sampling, which is off
    assert _warnings(factory_scene) == []
    r.film_transparent = r.use_motion_blur = r.use_simplify = True
    warnings = _warnings(factory_scene)
    assert len(warnings) == 3, warnings
    assert any("Transparent Glass" in w for w in warnings)
    assert any("Rolling Shutter is TOP" in w for w in warnings)
    assert any("Texture Limit is 512" in w for w in warnings)


def test_unwritten_passes_warn_together(factory_scene):
    _quiet_defaults(factory_scene)
    layer = factory_scene.view_layers[0]
    layer.use_pass_subsurface_direct = layer.use_pass_shadow = True
    layer.use_pass_z = layer.use_pass_normal = True           # DRT writes these
    layer.use_pass_mist = layer.use_pass_position = True
    warnings = _warnings(factory_scene)
    assert len(warnings) == 1, warnings
    assert "Subsurface Direct" in warnings[0] and "Shadow" in warnings[0]
    listed = warnings[0].split("(it writes")[0]          # the passes warned about
    assert "Mist" not in listed and "Position" not in listed, warnings[0]


def test_a_render_warns_once_per_setting(factory_scene):
    """Through the render engine's Reporter: one warning for a setting DRT ignores
    (Freestyle), none for the file's Denoise, which the render honours."""
    bpy = __import__("bpy")
    from drt_addon import render_engine
    factory_scene.render.engine = "DRT"
    factory_scene.render.resolution_percentage = 1            # 19 x 10
    factory_scene.drt.samples = 1
    factory_scene.cycles.use_adaptive_sampling = False
    factory_scene.render.use_freestyle = True
    bpy.ops.render.render()
    last = render_engine.last_render
    assert last["ok"], last["error"]
    assert sum("Freestyle" in w for w in last["warnings"]) == 1, last["warnings"]
    assert not any("enois" in w for w in last["warnings"]), last["warnings"]
    assert "Noisy Image" in last["passes"]                    # denoised, as Cycles would


# ------------------------------------------------------------------------ the table

def test_the_table_covers_every_cycles_setting_and_pass(bpy_drt):
    from drt_addon.export.file_settings import SETTINGS
    listed = {s.path for s in SETTINGS}
    assert len(listed) == len(SETTINGS), "a setting is listed twice"
    scene = bpy_drt.data.scenes.new("table")
    try:
        layer = scene.view_layers[0]
        wanted = [f"scene.cycles.{p.identifier}" for p in scene.cycles.bl_rna.properties]
        wanted += [f"view_layer.cycles.{p.identifier}"
                   for p in layer.cycles.bl_rna.properties]
        wanted += [f"view_layer.{p.identifier}" for p in layer.bl_rna.properties
                   if p.identifier.startswith("use_pass_")]
        missing = [p for p in wanted if p not in listed
                   and not p.endswith((".rna_type", ".name"))]
        assert missing == []
    finally:
        bpy_drt.data.scenes.remove(scene)


def test_quiet_values_are_blenders_defaults(bpy_drt):
    """Every row's path exists in this Blender and its quiet value is the default of a
    new scene."""
    from drt_addon.export.file_settings import IGNORED, OWN, SETTINGS
    from drt_addon.export.settings_check import _MISSING, is_quiet, read
    scene = bpy_drt.data.scenes.new("defaults")
    scene.world = bpy_drt.data.worlds.new("defaults")   # as in Blender's new files
    try:
        layer = scene.view_layers[0]
        loud = []
        for s in SETTINGS:
            value = read(s.path, scene, layer)
            assert value is not _MISSING, s.path
            if s.kind in (IGNORED, OWN) and s.warns and not is_quiet(s, value):
                loud.append(s.path)
        assert loud == []           # Denoise, on in a new scene, is read since 2026-11-29
    finally:
        bpy_drt.data.scenes.remove(scene)


def test_docs_page_is_written_from_the_table():
    import importlib.util
    root = os.path.dirname(SAMPLES_DIR)
    spec = importlib.util.spec_from_file_location(
        "make_settings_docs", os.path.join(root, "docs", "make_settings_docs.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    with open(os.path.join(root, "docs", "settings.md")) as f:
        assert f.read() == module.render_markdown(), \
            "docs/settings.md is stale: run docs/make_settings_docs.py"


# ------------------------------------------------------------------------ caustics

def test_caustics_switched_off_in_a_saved_file_are_honoured(bpy_drt, tmp_path):
    """A file saved with both caustics switches off: DRT reads them (no warning) and
    renders exactly what it renders with them switched off in memory, which is not the
    image with caustics on (tests/test_scenes_vs_cycles.py compares that one with
    Cycles)."""
    bpy = bpy_drt
    original = os.path.join(SAMPLES_DIR, "glass_caustics.blend")

    def off(scene):
        scene.cycles.caustics_reflective = False
        scene.cycles.caustics_refractive = False

    bpy.ops.wm.open_mainfile(filepath=original, load_ui=False)
    off(bpy.context.scene)
    saved = str(tmp_path / "caustics_off.blend")
    bpy.ops.wm.save_as_mainfile(filepath=saved, copy=True)

    bpy.ops.wm.open_mainfile(filepath=saved, load_ui=False)
    settings = bpy.context.scene.drt.to_engine_settings()
    assert (settings.caustics_reflective, settings.caustics_refractive) == (False, False)
    assert not any("austic" in w for w in _warnings(bpy.context.scene))

    from_file = render_blend(bpy, saved, "DRT", samples=16, percentage=50)
    in_memory = render_blend(bpy, original, "DRT", samples=16, percentage=50, setup=off)
    caustics_on = render_blend(bpy, original, "DRT", samples=16, percentage=50)
    np.testing.assert_array_equal(from_file, in_memory)
    change = abs(caustics_on.mean() / from_file.mean() - 1)
    print(f"caustics on vs off (DRT, 16 samples): mean differs by {100 * change:.1f}%")
    assert change > 0.02
