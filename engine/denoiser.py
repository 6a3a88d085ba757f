"""Intel Open Image Denoise (OIDN) on a finished image, as Cycles runs it.

Cycles' Render > Denoise with OpenImageDenoise (`integrator/denoiser_oidn.cpp`) runs
OIDN's "RT" filter on the Combined pass, HDR, not sRGB, with the file's quality, and
with up to two auxiliary images, the Denoising Albedo and Denoising Normal passes
(`input_passes`: colour alone, with albedo, with albedo and normal). Its prefilter:

- ACCURATE (the default): each auxiliary image is denoised first by an RT filter of its
  own, and the main filter is then told they are clean (`cleanAux`);
- FAST: the auxiliary images go in as they are, and OIDN allows for their noise;
- NONE: they go in as they are, and OIDN is told they are clean.

Alpha is not denoised: the denoised colour keeps the noisy image's alpha. Cycles passes
a constant 0.5 albedo where a normal but no albedo is asked for; OIDN needs none then,
since Blender only offers albedo-and-normal, albedo, or neither.

The binding is `pyoidn` (pinned in requirements.txt, bundled in the extension), which
ships OIDN's CPU library; `available()` says why it cannot be used where it cannot.
One OIDN device serves the process (it is created on first use); calls are
serialised, since OIDN uses every core itself.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

INPUT_PASSES = ("RGB", "RGB_ALBEDO", "RGB_ALBEDO_NORMAL")
PREFILTERS = ("NONE", "FAST", "ACCURATE")
QUALITIES = ("HIGH", "BALANCED", "FAST")


@dataclass(frozen=True)
class DenoiseSettings:
    """Cycles' Render > Denoise settings (scene.cycles), at Cycles' defaults."""
    input_passes: str = "RGB_ALBEDO_NORMAL"
    prefilter: str = "ACCURATE"
    quality: str = "HIGH"

    def __post_init__(self):
        for value, allowed, name in ((self.input_passes, INPUT_PASSES, "input passes"),
                                     (self.prefilter, PREFILTERS, "prefilter"),
                                     (self.quality, QUALITIES, "quality")):
            if value not in allowed:
                raise ValueError(f"denoise {name} must be one of {', '.join(allowed)}, "
                                 f"not {value!r}")

    @property
    def uses_albedo(self) -> bool:
        return self.input_passes != "RGB"

    @property
    def uses_normal(self) -> bool:
        return self.input_passes == "RGB_ALBEDO_NORMAL"


_lock = threading.Lock()
_device = None
_load_error = None


def _oidn():
    """The pyoidn module and the process's committed CPU device; raises RuntimeError."""
    global _device, _load_error
    if _load_error is not None:
        raise RuntimeError(_load_error)
    try:
        import pyoidn
    except Exception as e:                     # missing, or its library would not load
        _load_error = f"the OpenImageDenoise binding (pyoidn) could not be loaded: {e}"
        raise RuntimeError(_load_error) from e
    if _device is None:
        device = pyoidn.Device(pyoidn.OIDN_DEVICE_TYPE_CPU)
        device.set_bool("setAffinity", False)      # as Cycles: leave the render's threads be
        device.commit()
        error = device.get_error()
        if error:
            _load_error = f"OpenImageDenoise has no CPU device here: {error}"
            raise RuntimeError(_load_error)
        _device = device
    return pyoidn, _device


def available() -> str | None:
    """None when OIDN can denoise in this process, else the reason it cannot."""
    try:
        with _lock:
            _oidn()
    except RuntimeError as e:
        return str(e)
    return None


def _float3(image, name: str, shape) -> np.ndarray:
    a = np.asarray(image)
    if a.shape[:2] != shape or a.ndim != 3 or a.shape[2] < 3:
        raise ValueError(f"the {name} image must be (height, width, 3) like the colour, "
                         f"not {a.shape}")
    a = np.ascontiguousarray(a[..., :3], dtype=np.float32)
    return np.where(np.isfinite(a), a, np.float32(0.0))   # OIDN propagates NaN


def _run(pyoidn, device, inputs: dict, settings: DenoiseSettings, hdr: bool,
         clean_aux: bool) -> np.ndarray:
    out = np.empty_like(next(iter(inputs.values())))
    flt = pyoidn.Filter(device, pyoidn.OIDN_FILTER_TYPE_RT)
    try:
        for name, image in inputs.items():
            flt.set_image(name, image, pyoidn.OIDN_FORMAT_FLOAT3)
        flt.set_image(pyoidn.OIDN_IMAGE_OUTPUT, out, pyoidn.OIDN_FORMAT_FLOAT3)
        if pyoidn.OIDN_IMAGE_COLOR in inputs:
            flt.set_bool("hdr", hdr)
            flt.set_bool("srgb", False)
            flt.set_bool("cleanAux", clean_aux)
        flt.set_quality({"HIGH": pyoidn.OIDN_QUALITY_HIGH,
                         "BALANCED": pyoidn.OIDN_QUALITY_BALANCED,
                         "FAST": pyoidn.OIDN_QUALITY_FAST}[settings.quality])
        flt.commit()
        flt.execute()
        error = device.get_error()
        if error:
            raise RuntimeError(f"OpenImageDenoise failed: {error}")
    finally:
        flt.release()
    return out


def denoise(color, albedo=None, normal=None, settings: DenoiseSettings = DenoiseSettings()
            ) -> np.ndarray:
    """The denoised colour (h, w, 3) float32 of `color` (h, w, 3 or 4; scene-linear, HDR).
    `albedo` and `normal` (h, w, 3) are used as `settings.input_passes` asks (and must
    then be given). Non-finite input values are taken as 0. Raises RuntimeError when OIDN
    is unavailable or fails, ValueError for bad input."""
    c = np.asarray(color)
    if c.ndim != 3 or c.shape[2] not in (3, 4) or min(c.shape[:2]) == 0:
        raise ValueError(f"the colour image must be (height, width, 3 or 4), not {c.shape}")
    shape = c.shape[:2]
    with _lock:
        pyoidn, device = _oidn()
        inputs = {pyoidn.OIDN_IMAGE_COLOR: _float3(c, "colour", shape)}
        aux = []
        if settings.uses_albedo:
            if albedo is None:
                raise ValueError("denoising with albedo needs the albedo image")
            aux.append((pyoidn.OIDN_IMAGE_ALBEDO, _float3(albedo, "albedo", shape)))
        if settings.uses_normal:
            if normal is None:
                raise ValueError("denoising with normals needs the normal image")
            aux.append((pyoidn.OIDN_IMAGE_NORMAL, _float3(normal, "normal", shape)))
        for name, image in aux:
            if settings.prefilter == "ACCURATE":   # each auxiliary image denoised first
                image = _run(pyoidn, device, {name: image}, settings, False, False)
            inputs[name] = image
        return _run(pyoidn, device, inputs, settings, True,
                    clean_aux=settings.prefilter in ("ACCURATE", "NONE"))
