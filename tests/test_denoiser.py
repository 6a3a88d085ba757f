"""engine.denoiser: Open Image Denoise as Cycles runs it, on images whose clean version is
known. A smooth image (a ramp with a disc) is made noisy by multiplying each pixel by
an independent variable of mean 1 and standard deviation 0.35 (the mean of 8 exponential
variables, as 8 samples of a diffusely lit pixel give: the noisy image is unbiased, as
a render's is); the denoiser must bring it much closer to the clean image and keep its
mean. The albedo is the clean image's colour without its shading, the normals a sphere's.
"""
from __future__ import annotations

import numpy as np
import pytest

from engine import denoiser
from engine.denoiser import DenoiseSettings

H, W = 64, 96
FACTOR = 0.3         # relMSE kept: measured 0.04 to 0.22 of the noisy image's


def _scene(seed=1, aux_noise=0.0):
    """(clean, noisy, albedo, normal): a checkerboard albedo (edges that only the albedo
    shows) lit from one side on a surface folded along a diagonal crease (an edge that
    only the normals show)."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:H, 0:W] / np.array([H, W])[:, None, None]
    checker = ((np.floor(x * 8) + np.floor(y * 6)) % 2)[..., None]
    albedo = checker * np.array([0.8, 0.3, 0.2]) + (1 - checker) * np.array([0.2, 0.5, 0.7])
    side = (x + y > 1.0)[..., None]
    normal = np.where(side, np.array([0.6, 0.0, 0.8]), np.array([-0.6, 0.0, 0.8]))
    normal = normal + 0.2 * np.stack([x - 0.5, y - 0.5, 0 * x], axis=-1)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    light = np.array([0.5, 0.3, 0.81]) / np.linalg.norm([0.5, 0.3, 0.81])
    clean = albedo * (0.2 + np.clip(normal @ light, 0, None))[..., None]
    noisy = clean * rng.gamma(8.0, 1.0 / 8.0, clean.shape)
    if aux_noise:
        albedo = np.clip(albedo * rng.gamma(1 / aux_noise ** 2, aux_noise ** 2,
                                            albedo.shape), 0, 1)
        normal = normal + aux_noise * rng.normal(size=normal.shape)
        normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    return clean, noisy, albedo, normal


def _rel_mse(a, ref):
    return float(np.mean((a - ref) ** 2 / (ref ** 2 + 0.01)))


def test_the_binding_loads():
    assert denoiser.available() is None


@pytest.mark.parametrize("passes", denoiser.INPUT_PASSES)
@pytest.mark.parametrize("prefilter", denoiser.PREFILTERS)
@pytest.mark.parametrize("quality", denoiser.QUALITIES)
def test_denoised_is_much_closer_to_the_clean_image_and_keeps_its_mean(passes, prefilter,
                                                                       quality):
    clean, noisy, albedo, normal = _scene()
    out = denoiser.denoise(noisy, albedo, normal, DenoiseSettings(passes, prefilter, quality))
    assert out.shape == (H, W, 3) and out.dtype == np.float32
    assert np.isfinite(out).all()
    assert _rel_mse(out, clean) < FACTOR * _rel_mse(noisy, clean)
    assert np.allclose(out.mean(axis=(0, 1)), clean.mean(axis=(0, 1)), rtol=0.03)


def test_albedo_and_normals_help_and_the_settings_reach_oidn():
    """Edges the albedo and the normals show are kept better with them: each input pass
    setting gives its own image, and more guidance gives a smaller error."""
    clean, noisy, albedo, normal = _scene()
    err = {p: _rel_mse(denoiser.denoise(noisy, albedo, normal, DenoiseSettings(p)), clean)
           for p in denoiser.INPUT_PASSES}
    assert err["RGB_ALBEDO_NORMAL"] < err["RGB"]
    assert err["RGB_ALBEDO"] < err["RGB"]
    fast = denoiser.denoise(noisy, albedo, normal, DenoiseSettings(quality="FAST"))
    high = denoiser.denoise(noisy, albedo, normal, DenoiseSettings(quality="HIGH"))
    assert not np.array_equal(fast, high)


def test_accurate_prefilter_cleans_noisy_guides_that_none_trusts():
    """With noisy albedo and normals (as a few samples give), ACCURATE denoises them first
    and tells OIDN they are clean; NONE tells OIDN they are clean as they are, so their
    noise is copied into the image: its error is larger."""
    clean, noisy, albedo, normal = _scene(aux_noise=0.5)
    err = {p: _rel_mse(denoiser.denoise(noisy, albedo, normal,
                                        DenoiseSettings(prefilter=p)), clean)
           for p in denoiser.PREFILTERS}
    assert err["ACCURATE"] < err["NONE"]


def test_rgba_input_non_finite_pixels_and_bad_input():
    clean, noisy, albedo, normal = _scene()
    rgba = np.concatenate([noisy, np.ones((H, W, 1))], axis=-1)
    rgba[3, 5, 0] = np.nan
    rgba[7, 9, :3] = np.inf
    out = denoiser.denoise(rgba, albedo, normal)
    assert out.shape == (H, W, 3) and np.isfinite(out).all()
    with pytest.raises(ValueError, match="albedo"):
        denoiser.denoise(noisy, None, normal)
    with pytest.raises(ValueError, match="normal"):
        denoiser.denoise(noisy, albedo, normal[:10])
    with pytest.raises(ValueError, match="colour"):
        denoiser.denoise(noisy[..., 0], albedo, normal)
    with pytest.raises(ValueError, match="prefilter"):
        DenoiseSettings(prefilter="SOME")
    # colour alone needs no guides
    assert denoiser.denoise(noisy, settings=DenoiseSettings("RGB")).shape == (H, W, 3)
