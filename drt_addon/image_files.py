"""Image files and Blender's Render Result as scene-linear NumPy arrays (through bpy, so
every format Blender reads works: OpenEXR, PNG, JPEG, TIFF, Radiance HDR, ...).

Float files (OpenEXR, HDR) are read as stored (scene-linear). 8- and 16-bit files in
the sRGB colour space (PNG, JPEG, ...) are decoded from sRGB to linear values; for a
PNG Blender saved through a view transform those are the display image's linear values,
not the scene's, so compare such files only with each other.
"""
from __future__ import annotations

import os
import tempfile
from importlib import import_module

import numpy as np

from .engine_link import engine

image_error = import_module(engine.__name__ + ".image_error")
textures = import_module(engine.__name__ + ".textures")


class ImageFileError(Exception):
    """An image that cannot be read, with a message meant for the user."""


def read_image(path: str) -> np.ndarray:
    """(h, w, 3) float64, row 0 at the top."""
    import bpy
    if not os.path.exists(path):
        raise ImageFileError(f"file not found: {path}")
    if os.path.isdir(path):
        raise ImageFileError(f"{path} is a directory, not an image")
    try:
        img = bpy.data.images.load(os.path.abspath(path), check_existing=False)
    except RuntimeError as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else "unreadable file"
        raise ImageFileError(f"cannot read {path}: {first}") from None
    try:
        w, h = img.size
        channels = img.channels
        if w == 0 or h == 0 or channels == 0:
            raise ImageFileError(f"cannot read {path}: not an image Blender can load")
        px = np.empty(w * h * channels, dtype=np.float32)
        img.pixels.foreach_get(px)
        srgb = (not img.is_float) and img.colorspace_settings.name == "sRGB"
    finally:
        bpy.data.images.remove(img)
    px = px.reshape(h, w, channels)[::-1].astype(np.float64)
    rgb = image_error.as_rgb(px if channels != 2 else px[..., 0])
    return textures.srgb_to_linear(rgb) if srgb else rgb


def render_result(scene) -> np.ndarray:
    """Blender's Render Result (any engine) as (h, w, 3) scene-linear float64: written
    as a 32-bit OpenEXR, the way Blender saves it, and read back."""
    import bpy
    settings = scene.render.image_settings
    if getattr(settings, "media_type", "IMAGE") != "IMAGE":
        settings.media_type = "IMAGE"
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "render.exr")
        bpy.data.images["Render Result"].save_render(filepath=out, scene=scene)
        return read_image(out)
