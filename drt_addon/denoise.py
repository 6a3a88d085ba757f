"""Render > Denoise, read from Cycles' own settings (`scene.cycles`, the view layer's
`cycles.use_denoising`) and run on DRT's finished Combined pass by engine.denoiser (Intel
Open Image Denoise), as Cycles does for a final render:

- it denoises when the scene's Denoise and the view layer's Denoising are both on (both
  are on in a new file), with the file's Denoiser input passes, prefilter and quality;
- the denoised colour is the Combined pass, with the noisy alpha; the noisy image is kept
  in a "Noisy Image" pass, as Cycles keeps it;
- Cycles' only other denoiser, OptiX, needs an NVIDIA GPU: a file that asks for it is
  denoised with OpenImageDenoise, as Cycles on a CPU does, and says so once;
- without the OpenImageDenoise binding, or when OIDN fails, the render is kept noisy,
  and says why.

The albedo and normal OIDN is given are DRT's Denoising Albedo and Denoising Normal
passes (engine.aov: the first hit's diffuse albedo, its Base Color and Metallic as the
path tracer shades them there, textures and shader programs included, and its
interpolated camera-space normal). Cycles' guides differ in two ways, measured in
docs/denoising.md: its normal is the material's (bump and normal maps), and it follows
paths through mirror-like surfaces to the first rough one.
"""
from __future__ import annotations

from importlib import import_module

NOISY_PASS = "Noisy Image"


def wanted(scene, view_layer) -> bool:
    """Whether Cycles would denoise this view layer's final render."""
    cycles = getattr(scene, "cycles", None)
    layer = getattr(view_layer, "cycles", None)
    return bool(getattr(cycles, "use_denoising", False)) and \
        bool(getattr(layer, "use_denoising", True))


def settings(scene):
    """engine.denoiser.DenoiseSettings of the file's Cycles settings."""
    from .engine_link import engine
    denoiser = import_module(engine.__name__ + ".denoiser")
    c = scene.cycles
    return denoiser.DenoiseSettings(input_passes=c.denoising_input_passes,
                                    prefilter=c.denoising_prefilter,
                                    quality=quality(c, "denoising_quality"))


def quality(cycles, name: str) -> str:
    """Denoise > Quality (`name`), or HIGH, OIDN's own, in a Blender before 4.1 that has
    no such setting."""
    return getattr(cycles, name, "HIGH")


def denoised(scene, image, first_hit, reporter):
    """The denoised (h, w, 3) image, or None (with a warning through `reporter`) when it
    cannot be denoised here. `first_hit()` gives engine.aov's first-hit passes and the
    camera matrix, computed only when the settings ask for albedo or normals."""
    from .engine_link import engine
    denoiser = import_module(engine.__name__ + ".denoiser")
    why = denoiser.available()
    if why is not None:
        reporter.warn(f"DRT: not denoised: {why}", key="denoise unavailable")
        return None
    if getattr(scene.cycles, "denoiser", "OPENIMAGEDENOISE") != "OPENIMAGEDENOISE":
        reporter.warn("DRT: Denoise > Denoiser is OptiX (NVIDIA GPUs); DRT denoises with "
                      "OpenImageDenoise, as Cycles does on a CPU", key="denoiser optix")
    s = settings(scene)
    albedo = normal = None
    if s.uses_albedo:
        passes, camera_matrix = first_hit()
        albedo = passes.albedo
        normal = passes.camera_normal(camera_matrix) if s.uses_normal else None
    try:
        return denoiser.denoise(image, albedo, normal, s)
    except RuntimeError as e:                  # OIDN failed (memory, an unsupported CPU)
        reporter.warn(f"DRT: not denoised: {e}", key="denoise failed")
        return None
