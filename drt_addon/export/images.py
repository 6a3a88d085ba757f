"""Blender images as engine Textures, once per export: the pixels of an image are read
once (`Image.pixels`) and shared by every Texture made of it (one per interpolation,
extension, colour space and premultiplication)."""
from __future__ import annotations

import importlib
import weakref

import numpy as np

from ..engine_link import engine

textures = importlib.import_module(engine.__name__ + ".textures")

# Image pixels and Textures, once per export: keyed by the export's Reporter (a new one
# per export), so an edited image is read again at the next render.
_image_caches: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def read_pixels(image, ctx):
    """(H, W, 4) float32 RGBA as Blender stores them, rows bottom-up, or None."""
    key = ("pixels", image.name_full)
    if key in ctx.cache:
        return ctx.cache[key]
    px = None
    try:
        if image.source == "TILED":
            ctx.issue(f"image {image.name!r} is a UDIM tiled image; DRT reads its first "
                      f"tile only")
        elif image.source in ("SEQUENCE", "MOVIE"):
            ctx.issue(f"image {image.name!r} is a {image.source.lower()}; DRT reads the "
                      f"frame Blender has loaded")
        w, h = image.size[0], image.size[1]
        c = image.channels
        if w > 0 and h > 0 and c > 0:
            flat = np.empty(w * h * c, dtype=np.float32)
            image.pixels.foreach_get(flat)
            px = flat.reshape(h, w, c)
    except (RuntimeError, ValueError, AttributeError):
        px = None
    if px is None:
        ctx.issue(f"image {image.name!r} has no pixels (missing file?); rendered pink "
                  f"like Cycles")
    ctx.cache[key] = px
    return px


def image_cache(reporter) -> dict:
    """The export's cache of image pixels and Textures (one per Reporter, i.e. export)."""
    return _image_caches.setdefault(reporter, {}) if reporter is not None else {}


def image_texture(image, interpolation, extension, ctx, premultiply):
    """One engine Texture per (image, interpolation, extension, premultiplied) per export;
    the pixel array is read once per image and shared. ctx: anything with `cache` (an
    `image_cache`) and `issue(text)` (the approximations to report)."""
    cs = image.colorspace_settings
    is_data = bool(getattr(cs, "is_data", False)) or cs.name == "Non-Color"
    srgb = (not image.is_float) and cs.name == "sRGB" and not is_data
    if not is_data and not srgb and not image.is_float and cs.name not in (
            "Linear Rec.709", "Working Space", "Linear", "Raw"):
        ctx.issue(f"image {image.name!r} is in the colour space {cs.name!r}, which DRT "
                  f"reads as scene-linear")
    premultiply = premultiply and not is_data and image.alpha_mode in ("STRAIGHT",)
    interp = interpolation if interpolation in ("Linear", "Closest") else "Linear"
    key = ("texture", image.name_full, interp, extension, srgb, premultiply)
    if key in ctx.cache:
        return ctx.cache[key]
    px = read_pixels(image, ctx)
    if px is None:
        # What Cycles samples for an image it cannot load (scene/image.cpp): one texel of
        # its missing colour, in the image's own storage (a byte sRGB image is decoded
        # after the blend), read with the node's interpolation and extension: pink
        # everywhere when repeated, a tent of pink over the UV square when clipped.
        px = np.array(textures.MISSING_RGBA, np.float32).reshape(1, 1, 4)
    elif premultiply and px.shape[2] == 4 and (px[:, :, 3] < 1.0).any():
        px = px.copy()
        px[:, :, :3] *= px[:, :, 3:4]
    tex = textures.Texture(px, interp, extension, srgb=srgb, name=image.name)
    ctx.cache[key] = tex
    return tex
