"""The file's own render settings: Film > Exposure as Cycles applies it, the view
transform's exposure applied by Blender to DRT's result as to Cycles'.

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
        scene.drt.diffuse_bounces = 0
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
