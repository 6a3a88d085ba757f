"""Image textures: Blender's Image Texture node (flat projection) as Cycles samples it.

A `Texture` holds one image's pixels as a float32 array (H, W, C), row 0 at the BOTTOM
(v = 0), exactly as Blender's `Image.pixels` lays them out, plus the node's settings:

interpolation ('Linear', 'Closest'; Cycles' 'Cubic' and 'Smart' are taken as 'Linear')
    Cycles' CPU kernel (intern/cycles/kernel/device/cpu/image.h): texel (i, j) is centred
    at ((i + 0.5) / W, (j + 0.5) / H). 'Closest' reads texel floor(u W), floor(v H);
    'Linear' blends the four texels around (u W - 0.5, v H - 0.5) bilinearly.
extension ('REPEAT', 'EXTEND', 'CLIP', 'MIRROR')
    what lies outside [0, 1]^2: the image tiled; its border texels stretched; transparent
    black (0, 0, 0, 0) -- with 'Linear', each of the four taps outside the image reads
    zero, so the border fades over half a texel as in Cycles; the image mirrored every
    other tile.
srgb
    True for 8-bit images whose colour space is 'sRGB': `Image.pixels` then holds the
    encoded values (byte / 255), which Cycles keeps compressed and decodes to scene-linear
    AFTER interpolation (NODE_IMAGE_COMPRESS_AS_SRGB in kernel/svm/image.h). The lookup
    does the same, with the exact sRGB curve, on the colour channels only (not alpha).
    Float images and 'Non-Color' data are already what the shader reads (srgb False).

`TextureInput` is how a material parameter refers to a texture: value = channel(texture
at the hit's UV) x scale + offset, which also represents Blender's Emission Colour x
Strength and parameters blended by a Mix Shader with a constant (linear in the texture).
Channels: 'rgb' (a colour socket fed by the Color output), 'luminance' (a scalar socket
fed by the Color output: Cycles converts colour to float with the scene's luminance
coefficients, Rec.709 Y for Blender's default OCIO config), 'alpha' (the Alpha output),
'alpha_rgb' (the Alpha output into a colour socket: grey).

All lookups are vectorised over the hit points; nothing loops over pixels.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

INTERPOLATIONS = ("Linear", "Closest")
EXTENSIONS = ("REPEAT", "EXTEND", "CLIP", "MIRROR")
CHANNELS = ("rgb", "luminance", "alpha", "alpha_rgb")
# Rec.709 luminance, Cycles' rgb_to_y for Blender's default colour management
LUMINANCE = np.array([0.2126729, 0.7151522, 0.0721750])
# Cycles' colour for an image it cannot load (TEX_IMAGE_MISSING_R/G/B/A)
MISSING_RGBA = (1.0, 0.0, 1.0, 1.0)


def srgb_to_linear(c):
    """The sRGB electro-optical transfer function (IEC 61966-2-1), elementwise."""
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92,
                    ((np.maximum(c, 0.04045) + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(c):
    """Inverse of `srgb_to_linear` (for tests and for writing images)."""
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.0031308, c * 12.92,
                    1.055 * np.maximum(c, 0.0031308) ** (1.0 / 2.4) - 0.055)


def _wrap(i, n, extension):
    """Texel indices i (int64 array) wrapped into [0, n) per extension; for CLIP also a
    mask of the taps that fall inside the image (the others read zero)."""
    if extension == "REPEAT":
        return np.mod(i, n), None
    if extension == "MIRROR":
        m = np.mod(i, 2 * n)
        return np.where(m >= n, 2 * n - 1 - m, m), None
    inside = (i >= 0) & (i < n)
    j = np.clip(i, 0, n - 1)
    return j, (inside if extension == "CLIP" else None)


class Texture:
    """One image and the Image Texture node's sampling settings (see the module doc)."""

    def __init__(self, pixels, interpolation: str = "Linear", extension: str = "REPEAT",
                 srgb: bool = False, name: str = "texture"):
        px = np.asarray(pixels, dtype=np.float32)
        if px.ndim == 2:
            px = px[:, :, None]
        if px.ndim != 3 or px.shape[0] < 1 or px.shape[1] < 1 or not 1 <= px.shape[2] <= 4:
            raise ValueError(f"texture {name!r}: pixels must be (H, W, 1..4), got {px.shape}")
        if interpolation in ("Cubic", "Smart"):
            interpolation = "Linear"
        if interpolation not in INTERPOLATIONS:
            raise ValueError(f"texture {name!r}: interpolation must be one of "
                             f"{INTERPOLATIONS}, got {interpolation!r}")
        if extension not in EXTENSIONS:
            raise ValueError(f"texture {name!r}: extension must be one of {EXTENSIONS}, "
                             f"got {extension!r}")
        # Non-finite texels (a broken EXR) would poison every path that reads them.
        if not np.isfinite(px).all():
            px = np.where(np.isfinite(px), px, 0.0).astype(np.float32)
        # Always RGBA inside: grey images repeat their channel, alpha defaults to 1. An
        # RGBA float32 array is used as it is (no copy: Textures of one image share it).
        h, w, c = px.shape
        if c == 4:
            rgba = px
        else:
            rgba = np.ones((h, w, 4), np.float32)
            if c in (1, 2):
                rgba[:, :, :3] = px[:, :, :1]
                if c == 2:
                    rgba[:, :, 3] = px[:, :, 1]
            else:
                rgba[:, :, :3] = px
        self.pixels = np.ascontiguousarray(rgba)
        self.height, self.width = h, w
        self.interpolation = interpolation
        self.extension = extension
        self.srgb = bool(srgb)
        self.name = name
        self._mean = None

    def __repr__(self):
        return (f"Texture({self.name!r}, {self.width}x{self.height}, {self.interpolation}, "
                f"{self.extension}, srgb={self.srgb})")

    def lookup(self, uv) -> np.ndarray:
        """Scene-linear RGBA (n, 4) float64 at texture coordinates uv (n, 2)."""
        uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
        uv = np.where(np.isfinite(uv), uv, 0.0)
        w, h = self.width, self.height
        px = self.pixels
        if self.interpolation == "Closest":
            ix = np.floor(uv[:, 0] * w).astype(np.int64)
            iy = np.floor(uv[:, 1] * h).astype(np.int64)
            jx, mx = _wrap(ix, w, self.extension)
            jy, my = _wrap(iy, h, self.extension)
            out = px[jy, jx].astype(np.float64)
            if mx is not None:
                out *= (mx & my)[:, None]
        else:
            x = uv[:, 0] * w - 0.5
            y = uv[:, 1] * h - 0.5
            fx, fy = np.floor(x), np.floor(y)
            tx, ty = (x - fx)[:, None], (y - fy)[:, None]
            ix, iy = fx.astype(np.int64), fy.astype(np.int64)
            x0, m0 = _wrap(ix, w, self.extension)
            x1, m1 = _wrap(ix + 1, w, self.extension)
            y0, n0 = _wrap(iy, h, self.extension)
            y1, n1 = _wrap(iy + 1, h, self.extension)
            t00 = px[y0, x0].astype(np.float64)
            t10 = px[y0, x1].astype(np.float64)
            t01 = px[y1, x0].astype(np.float64)
            t11 = px[y1, x1].astype(np.float64)
            if m0 is not None:
                t00 *= (m0 & n0)[:, None]
                t10 *= (m1 & n0)[:, None]
                t01 *= (m0 & n1)[:, None]
                t11 *= (m1 & n1)[:, None]
            out = ((1.0 - ty) * ((1.0 - tx) * t00 + tx * t10)
                   + ty * ((1.0 - tx) * t01 + tx * t11))
        if self.srgb:
            out[:, :3] = srgb_to_linear(out[:, :3])
        return out

    def mean_rgba(self) -> np.ndarray:
        """The image's average scene-linear RGBA (texel average, decoded per texel): the
        constant a parameter falls back to where a texture cannot be evaluated (e.g. the
        material's power estimate)."""
        if self._mean is None:
            px = self.pixels.reshape(-1, 4).astype(np.float64)
            if self.srgb:
                rgb = srgb_to_linear(px[:, :3]).mean(0)
            else:
                rgb = px[:, :3].mean(0)
            self._mean = np.concatenate([rgb, [px[:, 3].mean()]])
        return self._mean


def apply_channel(rgba, channel: str) -> np.ndarray:
    """(n, 3) for the colour channels 'rgb'/'alpha_rgb', (n,) for 'luminance'/'alpha'."""
    rgba = np.asarray(rgba, dtype=np.float64)
    if channel == "rgb":
        return rgba[..., :3]
    if channel == "luminance":
        return rgba[..., :3] @ LUMINANCE
    if channel == "alpha":
        return rgba[..., 3]
    if channel == "alpha_rgb":
        return np.repeat(rgba[..., 3:4], 3, axis=-1)
    raise ValueError(f"channel must be one of {CHANNELS}, got {channel!r}")


@dataclass
class TextureInput:
    """A material parameter driven by a texture: channel(texture(uv)) * scale + offset.

    scale/offset are per-channel triples for colour parameters and numbers for scalar
    ones. The Texture object is shared by every input that uses the same image (the
    exporter reads each image's pixels once); `engine.bsdf.material_table.MaterialTable`
    gives each distinct Texture an index."""
    texture: Texture
    channel: str = "rgb"
    scale: object = 1.0
    offset: object = 0.0
    uv_map: str = ""                 # informational: '' = the mesh's default UV map

    def __post_init__(self):
        if self.channel not in CHANNELS:
            raise ValueError(f"channel must be one of {CHANNELS}, got {self.channel!r}")

    @property
    def is_color(self) -> bool:
        return self.channel in ("rgb", "alpha_rgb")

    def evaluate(self, uv) -> np.ndarray:
        v = apply_channel(self.texture.lookup(uv), self.channel)
        return v * np.asarray(self.scale, np.float64) + np.asarray(self.offset, np.float64)

    def mean(self):
        """The parameter's average over the image (tuple for colours, float otherwise)."""
        v = apply_channel(self.texture.mean_rgba()[None], self.channel)[0]
        v = v * np.asarray(self.scale, np.float64) + np.asarray(self.offset, np.float64)
        return tuple(float(x) for x in v) if np.ndim(v) else float(v)

    def scaled(self, factor, add=0.0) -> "TextureInput":
        """This input times `factor` plus `add` (both broadcast per channel)."""
        f = np.asarray(factor, np.float64)
        scale = np.asarray(self.scale, np.float64) * f
        offset = np.asarray(self.offset, np.float64) * f + np.asarray(add, np.float64)
        return TextureInput(self.texture, self.channel, _plain(scale), _plain(offset),
                            self.uv_map)


def _plain(a):
    a = np.asarray(a, np.float64)
    return tuple(float(x) for x in a) if a.ndim else float(a)
