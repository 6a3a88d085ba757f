"""Image-texture lookups, scalar: the compiled twin of engine/textures.py (`Texture.lookup`,
`apply_channel`, `TextureInput.evaluate`) and of the textured part of
`engine.bsdf.material_table.MaterialTable` (`lookup`, `emission_at`, `alpha_at`).

Same operations in the same order as the NumPy code (float32 texels widened to float64,
the same bilinear blend, the CLIP taps multiplied by 0 / 1, sRGB decoded after
interpolation on r, g, b only), so results agree bit for bit where the maths library
does (the sRGB curve's pow; Rec.709 luminance, which NumPy computes with `@`).

`pack_textures(table)` returns the tuple T (one Numba argument; always the same array
types, so one compilation serves every scene):

  T[PIXELS]    float32 (n_floats,): RGBA texels of every distinct image, concatenated;
               image k's texel (x, y) (x = column, y = row, row 0 at v = 0) channel c is
               at TEXTURES[k, X_OFFSET] + (y W + x) 4 + c. Textures sharing one pixel
               array (one image, different node settings) share one block.
  T[TEXTURES]  int64 (n_tex, 6): per texture (index = `MaterialTable.texture_index`):
               X_OFFSET (float index into PIXELS), X_WIDTH, X_HEIGHT, X_INTERP
               (INTERP_* code), X_EXTENSION (EXT_* code), X_SRGB (0 / 1).
  T[INPUTS]    int64 (n_mat, 5, 2): per (material, parameter TEX_*): I_TEXTURE (texture
               id, -1 = not textured), I_CHANNEL (CH_* code; 0 when not textured).
  T[SCALE_OFFSET]  float64 (n_mat, 5, 6): scale r, g, b then offset r, g, b of the
               `TextureInput` (a scalar parameter's number repeated; 0 when not textured).
  T[PLAIN]     float64 (n_mat, 5, 3): the parameter's plain value as `MaterialTable.lookup`
               returns it where it is not textured (scalars in column 0; emission is
               `MaterialTable.emission`); only the array wrappers read it -- the render
               kernels keep their own material rows / emission and alpha tables.

A table without textures packs to empty PIXELS / TEXTURES and INPUTS of -1.
"""
from __future__ import annotations

import math

import numpy as np

from ..textures import CHANNELS, EXTENSIONS, LUMINANCE
from .jit import kernel

# ---------------------------------------------------------------- parameter ids
TEX_BASE_COLOR = 0
TEX_METALLIC = 1
TEX_ROUGHNESS = 2
TEX_EMISSION = 3
TEX_ALPHA = 4
N_PARAMS = 5
PARAM_NAMES = ("base_color", "metallic", "roughness", "emission", "alpha")  # = PARAMS
COLOR_PARAMS = (TEX_BASE_COLOR, TEX_EMISSION)

# ---------------------------------------------------------------- fields of the tuple T
PIXELS = 0
TEXTURES = 1
INPUTS = 2
SCALE_OFFSET = 3
PLAIN = 4

# TEXTURES columns
X_OFFSET = 0
X_WIDTH = 1
X_HEIGHT = 2
X_INTERP = 3
X_EXTENSION = 4
X_SRGB = 5
# INPUTS columns
I_TEXTURE = 0
I_CHANNEL = 1

# codes
INTERP_LINEAR = 0
INTERP_CLOSEST = 1
EXT_REPEAT = 0           # the order of engine.textures.EXTENSIONS
EXT_EXTEND = 1
EXT_CLIP = 2
EXT_MIRROR = 3
CH_RGB = 0               # the order of engine.textures.CHANNELS
CH_LUMINANCE = 1
CH_ALPHA = 2
CH_ALPHA_RGB = 3

LUM_R, LUM_G, LUM_B = (float(x) for x in LUMINANCE)
# Cycles' colour for an image it cannot load: what a texture id out of range reads
MISSING_R, MISSING_G, MISSING_B, MISSING_A = 1.0, 0.0, 1.0, 1.0


def _triple(value, what):
    a = np.asarray(value, np.float64)
    try:
        return np.broadcast_to(a, (3,)).copy()
    except ValueError:
        raise ValueError(f"{what} must be a number or a triple, got {value!r}") from None


def pack_textures(table) -> tuple:
    """The tuple T (see the module docstring) of an `engine.bsdf.material_table.MaterialTable`.

    Raises ValueError for an input `MaterialTable.lookup` cannot evaluate either: a
    colour channel ('rgb', 'alpha_rgb') or a per-channel scale / offset on a scalar
    parameter. A scalar channel on a colour parameter is taken as grey (channel value
    times each channel's scale, plus its offset)."""
    textures = list(table.textures)
    info = np.zeros((len(textures), 6), np.int64)
    blocks, start, pos = [], {}, 0
    for k, t in enumerate(textures):
        key = id(t.pixels)
        if key not in start:
            px = np.ascontiguousarray(t.pixels, dtype=np.float32)
            if px.shape != (t.height, t.width, 4):
                raise ValueError(f"texture {t.name!r}: pixels {px.shape} are not "
                                 f"({t.height}, {t.width}, 4)")
            start[key] = pos
            blocks.append(px.reshape(-1))
            pos += px.size
        info[k] = texture_info(t, start[key])
    pixels = np.concatenate(blocks) if blocks else np.zeros(0, np.float32)

    m = len(table.metallic)
    inputs = np.zeros((m, N_PARAMS, 2), np.int64)
    inputs[:, :, I_TEXTURE] = -1
    scale_offset = np.zeros((m, N_PARAMS, 6), np.float64)
    plain = np.zeros((m, N_PARAMS, 3), np.float64)
    plain[:, TEX_BASE_COLOR] = np.asarray(table.base_color, np.float64).reshape(m, 3)
    plain[:, TEX_METALLIC, 0] = table.metallic
    plain[:, TEX_ROUGHNESS, 0] = table.roughness
    plain[:, TEX_EMISSION] = np.asarray(table.emission, np.float64).reshape(m, 3)
    plain[:, TEX_ALPHA, 0] = table.alpha

    all_inputs = getattr(table, "_inputs", {})
    for p, name in enumerate(PARAM_NAMES):
        for i, inp in enumerate(all_inputs.get(name) or ()):
            if inp is None:
                continue
            what = f"material {i} {name}"
            ch = CHANNELS.index(inp.channel)
            scale, offset = _triple(inp.scale, what), _triple(inp.offset, what)
            if p not in COLOR_PARAMS:
                if ch in (CH_RGB, CH_ALPHA_RGB):
                    raise ValueError(f"{what}: a scalar parameter cannot take the colour "
                                     f"channel {inp.channel!r}")
                if np.any(scale != scale[0]) or np.any(offset != offset[0]):
                    raise ValueError(f"{what}: a scalar parameter needs one scale and one "
                                     f"offset, got {inp.scale!r}, {inp.offset!r}")
            inputs[i, p, I_TEXTURE] = table.texture_index[id(inp.texture)]
            inputs[i, p, I_CHANNEL] = ch
            scale_offset[i, p, :3] = scale
            scale_offset[i, p, 3:] = offset
    return (pixels, info, inputs, scale_offset, plain)


def texture_info(t, offset) -> tuple:
    """The T[TEXTURES] row of `engine.textures.Texture` t whose texels start at
    T[PIXELS][offset]."""
    interp = INTERP_CLOSEST if t.interpolation == "Closest" else INTERP_LINEAR
    return (offset, t.width, t.height, interp, EXTENSIONS.index(t.extension),
            int(bool(t.srgb)))


# ---------------------------------------------------------------- texel lookup
@kernel(allocates=False)
def srgb_to_linear(c):
    """The sRGB decoding curve (engine.textures.srgb_to_linear), one value."""
    if c <= 0.04045:
        return c / 12.92
    return ((max(c, 0.04045) + 0.055) / 1.055) ** 2.4


@kernel(allocates=False)
def wrap(i, n, extension):
    """(texel index in [0, n), 1.0 or 0.0): `engine.textures._wrap` for one tap; the
    factor is 0 for a CLIP tap outside the image (it reads zero)."""
    if extension == EXT_REPEAT:
        return i % n, 1.0
    if extension == EXT_MIRROR:
        m = i % (2 * n)
        if m >= n:
            m = 2 * n - 1 - m
        return m, 1.0
    j = min(max(i, 0), n - 1)
    if extension == EXT_CLIP and not (i >= 0 and i < n):
        return j, 0.0
    return j, 1.0


@kernel(allocates=False)
def _texel(px, base, w, x, y, f):
    """RGBA of texel (x, y) times f (1 or 0: exactly what NumPy's mask product gives)."""
    k = base + (y * w + x) * 4
    return (np.float64(px[k]) * f, np.float64(px[k + 1]) * f,
            np.float64(px[k + 2]) * f, np.float64(px[k + 3]) * f)


@kernel(allocates=False)
def _blend(tx, ty, a, b, c, d):
    """Bilinear blend of taps a = (x0, y0), b = (x1, y0), c = (x0, y1), d = (x1, y1)."""
    return (1.0 - ty) * ((1.0 - tx) * a + tx * b) + ty * ((1.0 - tx) * c + tx * d)


@kernel(allocates=False)
def texture_rgba(T, tex_id, u, v):
    """`Texture.lookup` of texture `tex_id` at (u, v): scene-linear (r, g, b, a) float64.
    Non-finite coordinates read as 0; an id out of range reads Cycles' missing-image
    colour (1, 0, 1, 1)."""
    info = T[TEXTURES]
    if tex_id < 0 or tex_id >= info.shape[0]:
        return MISSING_R, MISSING_G, MISSING_B, MISSING_A
    px = T[PIXELS]
    base = info[tex_id, X_OFFSET]
    w = info[tex_id, X_WIDTH]
    h = info[tex_id, X_HEIGHT]
    ext = info[tex_id, X_EXTENSION]
    if not math.isfinite(u):
        u = 0.0
    if not math.isfinite(v):
        v = 0.0
    if info[tex_id, X_INTERP] == INTERP_CLOSEST:
        jx, mx = wrap(np.int64(np.floor(u * w)), w, ext)
        jy, my = wrap(np.int64(np.floor(v * h)), h, ext)
        r, g, b, a = _texel(px, base, w, jx, jy, mx * my)
    else:
        x = u * w - 0.5
        y = v * h - 0.5
        fx = np.floor(x)
        fy = np.floor(y)
        tx = x - fx
        ty = y - fy
        ix = np.int64(fx)
        iy = np.int64(fy)
        x0, m0 = wrap(ix, w, ext)
        x1, m1 = wrap(ix + 1, w, ext)
        y0, n0 = wrap(iy, h, ext)
        y1, n1 = wrap(iy + 1, h, ext)
        r00, g00, b00, a00 = _texel(px, base, w, x0, y0, m0 * n0)
        r10, g10, b10, a10 = _texel(px, base, w, x1, y0, m1 * n0)
        r01, g01, b01, a01 = _texel(px, base, w, x0, y1, m0 * n1)
        r11, g11, b11, a11 = _texel(px, base, w, x1, y1, m1 * n1)
        r = _blend(tx, ty, r00, r10, r01, r11)
        g = _blend(tx, ty, g00, g10, g01, g11)
        b = _blend(tx, ty, b00, b10, b01, b11)
        a = _blend(tx, ty, a00, a10, a01, a11)
    if info[tex_id, X_SRGB] != 0:
        r = srgb_to_linear(r)
        g = srgb_to_linear(g)
        b = srgb_to_linear(b)
    return r, g, b, a


@kernel(allocates=False)
def apply_channel(r, g, b, a, channel):
    """`engine.textures.apply_channel` of one RGBA: (x, y, z), the scalar channels
    ('luminance', 'alpha') repeated in all three."""
    if channel == CH_RGB:
        return r, g, b
    if channel == CH_LUMINANCE:
        y = r * LUM_R + g * LUM_G + b * LUM_B
        return y, y, y
    return a, a, a          # CH_ALPHA, CH_ALPHA_RGB


# ---------------------------------------------------------------- material parameters
@kernel(allocates=False)
def is_textured(T, material, param):
    """Whether parameter `param` (TEX_*) of `material` comes from a texture."""
    return T[INPUTS][material, param, I_TEXTURE] >= 0


@kernel(allocates=False)
def textured_value(T, material, param, u, v):
    """`TextureInput.evaluate` of (material, param) at (u, v): channel x scale + offset.
    Colour parameters (TEX_BASE_COLOR, TEX_EMISSION): (r, g, b); scalar ones: (value, 0,
    0). An untextured (material, param) gives (0, 0, 0)."""
    inp = T[INPUTS]
    so = T[SCALE_OFFSET]
    r, g, b, a = texture_rgba(T, inp[material, param, I_TEXTURE], u, v)
    x, y, z = apply_channel(r, g, b, a, inp[material, param, I_CHANNEL])
    if param == TEX_BASE_COLOR or param == TEX_EMISSION:
        return (x * so[material, param, 0] + so[material, param, 3],
                y * so[material, param, 1] + so[material, param, 4],
                z * so[material, param, 2] + so[material, param, 5])
    return x * so[material, param, 0] + so[material, param, 3], 0.0, 0.0


@kernel(allocates=False)
def apply_to_row(T, material, u, v, row, P_BASE, P_METALLIC, P_ROUGHNESS):
    """Overwrite the textured base colour (row[P_BASE:P_BASE + 3]), metallic and
    roughness of `material` at (u, v) in its float64 parameter row (engine.kernels.bsdf
    .params layout); untextured parameters are left as they are."""
    inp = T[INPUTS]
    if inp[material, TEX_BASE_COLOR, I_TEXTURE] >= 0:
        x, y, z = textured_value(T, material, TEX_BASE_COLOR, u, v)
        row[P_BASE] = x
        row[P_BASE + 1] = y
        row[P_BASE + 2] = z
    if inp[material, TEX_METALLIC, I_TEXTURE] >= 0:
        row[P_METALLIC] = textured_value(T, material, TEX_METALLIC, u, v)[0]
    if inp[material, TEX_ROUGHNESS, I_TEXTURE] >= 0:
        row[P_ROUGHNESS] = textured_value(T, material, TEX_ROUGHNESS, u, v)[0]


@kernel(allocates=False)
def emission_at(T, emission_table, material, u, v):
    """`MaterialTable.emission_at` of one hit: (r, g, b); `emission_table` is
    `MaterialTable.emission` (n_mat, 3) (zero where the emission is textured)."""
    if T[INPUTS][material, TEX_EMISSION, I_TEXTURE] >= 0:
        return textured_value(T, material, TEX_EMISSION, u, v)
    return (emission_table[material, 0], emission_table[material, 1],
            emission_table[material, 2])


@kernel(allocates=False)
def alpha_at(T, alpha_table, material, u, v):
    """`MaterialTable.alpha_at` of one hit: coverage clipped to [0, 1] (NaN stays NaN, as
    with np.clip); `alpha_table` is `MaterialTable.alpha` (n_mat,)."""
    if T[INPUTS][material, TEX_ALPHA, I_TEXTURE] >= 0:
        a = textured_value(T, material, TEX_ALPHA, u, v)[0]
    else:
        a = alpha_table[material]
    if a < 0.0:
        return 0.0
    if a > 1.0:
        return 1.0
    return a
