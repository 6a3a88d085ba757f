"""Colour nodes. Opcodes 200-299. Colours are three registers.

  COL_MIX out, fac, color1, color2, blend, clamp   Mix (Color) / MixRGB, every blend
                                                    mode (BLEND_MODES), result clamped
                                                    to [0, 1] when clamp is 1
  COL_RAMP_COLOR out, fac | table                   Color Ramp: Cycles' 256-entry table
  COL_RAMP_ALPHA out, fac | table                   (field 6: its start in the program
                                                    data, field 5: 1 = interpolate)
  COL_INVERT out, fac, color
  COL_GAMMA out, color, gamma
  COL_BRIGHT_CONTRAST out, color, bright, contrast
  COL_HSV out, hue, saturation, value, fac, color   Hue/Saturation/Value
  COL_CURVES out, fac, color | table                RGB Curves: Cycles' table (field 6:
                                                    its start, after the curves' x range
                                                    min, max), extrapolated linearly
  COL_TABLE out, x | table                          a colour tabulated over x (field 6:
                                                    its start: x0, x1, n, then n RGB
                                                    rows evenly spaced from x0 to x1),
                                                    linear between rows, the end rows
                                                    beyond them (Blackbody of a varying
                                                    temperature)

The blend modes follow Cycles' node functions (kernel/svm/color_util.h); the factor is
clamped by the compiler where the node clamps it.
"""
from __future__ import annotations

import math

from ..kernels.jit import kernel

COL_MIX = 200
COL_RAMP_COLOR = 201
COL_RAMP_ALPHA = 202
COL_INVERT = 203
COL_GAMMA = 204
COL_BRIGHT_CONTRAST = 205
COL_HSV = 206
COL_CURVES = 207
COL_TABLE = 208
DATA_OPS = (COL_RAMP_COLOR, COL_RAMP_ALPHA, COL_CURVES, COL_TABLE)

BLEND_MODES = ("MIX", "DARKEN", "MULTIPLY", "BURN", "LIGHTEN", "SCREEN", "DODGE", "ADD",
               "OVERLAY", "SOFT_LIGHT", "LINEAR_LIGHT", "DIFFERENCE", "EXCLUSION",
               "SUBTRACT", "DIVIDE", "HUE", "SATURATION", "VALUE", "COLOR")
RAMP_TABLE_SIZE = 256


@kernel(allocates=False)
def rgb_to_hsv(r, g, b):
    cmax = max(r, g, b)
    cmin = min(r, g, b)
    cdelta = cmax - cmin
    v = cmax
    s = cdelta / cmax if cmax != 0.0 else 0.0
    h = 0.0
    if s != 0.0:
        cr, cg, cb = (cmax - r) / cdelta, (cmax - g) / cdelta, (cmax - b) / cdelta
        if r == cmax:
            h = cb - cg
        elif g == cmax:
            h = 2.0 + cr - cb
        else:
            h = 4.0 + cg - cr
        h /= 6.0
        if h < 0.0:
            h += 1.0
    return h, s, v


@kernel(allocates=False)
def hsv_to_rgb(h, s, v):
    if s == 0.0:
        return v, v, v
    if h == 1.0:
        h = 0.0
    h *= 6.0
    i = math.floor(h)
    f = h - i
    p = v * (1.0 - s)
    q = v * (1.0 - s * f)
    t = v * (1.0 - s * (1.0 - f))
    if i == 0.0:
        return v, t, p
    if i == 1.0:
        return q, v, p
    if i == 2.0:
        return p, v, t
    if i == 3.0:
        return p, q, v
    if i == 4.0:
        return t, p, v
    return v, p, q


@kernel(allocates=False)
def _lerp(a, b, t):
    return (1.0 - t) * a + t * b


@kernel(allocates=False)
def _dodge(a, b, t):
    if a == 0.0:
        return a
    tmp = 1.0 - t * b
    if tmp <= 0.0:
        return 1.0
    tmp = a / tmp
    return 1.0 if tmp > 1.0 else tmp


@kernel(allocates=False)
def _burn(a, b, t):
    tmp = (1.0 - t) + t * b
    if tmp <= 0.0:
        return 0.0
    tmp = 1.0 - (1.0 - a) / tmp
    return min(max(tmp, 0.0), 1.0)


@kernel(allocates=False)
def _overlay(a, b, t):
    if a < 0.5:
        return a * ((1.0 - t) + 2.0 * t * b)
    return 1.0 - ((1.0 - t) + 2.0 * t * (1.0 - b)) * (1.0 - a)


@kernel(allocates=False)
def _channel(mode, a, b, t):
    """The per-channel blend modes."""
    if mode == 0:
        return _lerp(a, b, t)
    if mode == 1:
        return _lerp(a, min(a, b), t)
    if mode == 2:
        return _lerp(a, a * b, t)
    if mode == 3:
        return _burn(a, b, t)
    if mode == 4:
        return _lerp(a, max(a, b), t)
    if mode == 5:
        return 1.0 - ((1.0 - t) + t * (1.0 - b)) * (1.0 - a)
    if mode == 6:
        return _dodge(a, b, t)
    if mode == 7:
        return _lerp(a, a + b, t)
    if mode == 8:
        return _overlay(a, b, t)
    if mode == 9:
        scr = 1.0 - (1.0 - b) * (1.0 - a)
        return (1.0 - t) * a + t * ((1.0 - a) * b * a + a * scr)
    if mode == 10:
        return a + t * (2.0 * b - 1.0)
    if mode == 11:
        return _lerp(a, abs(a - b), t)
    if mode == 12:
        return max(_lerp(a, a + b - 2.0 * a * b, t), 0.0)
    if mode == 13:
        return _lerp(a, a - b, t)
    # 14: DIVIDE
    if b != 0.0:
        return (1.0 - t) * a + t * a / b
    return a


@kernel(allocates=False)
def mix(mode, t, r1, g1, b1, r2, g2, b2):
    if mode < 15:
        return (_channel(mode, r1, r2, t), _channel(mode, g1, g2, t),
                _channel(mode, b1, b2, t))
    h2, s2, v2 = rgb_to_hsv(r2, g2, b2)
    h1, s1, v1 = rgb_to_hsv(r1, g1, b1)
    if mode == 15 or mode == 18:             # HUE, COLOR
        if s2 == 0.0:
            return r1, g1, b1
        r, g, b = hsv_to_rgb(h2, s2 if mode == 18 else s1, v1)
        return _lerp(r1, r, t), _lerp(g1, g, t), _lerp(b1, b, t)
    if mode == 16:                           # SATURATION
        if s1 == 0.0:
            return r1, g1, b1
        return hsv_to_rgb(h1, (1.0 - t) * s1 + t * s2, v1)
    return hsv_to_rgb(h1, s1, (1.0 - t) * v1 + t * v2)     # VALUE


@kernel(allocates=False)
def ramp(data, start, f, interpolate, channel):
    """Cycles' rgb_ramp_lookup (no extrapolation) of one RGBA channel."""
    n = RAMP_TABLE_SIZE
    if not math.isfinite(f):
        f = 0.0
    f = min(max(f, 0.0), 1.0) * (n - 1)
    i = min(max(int(f), 0), n - 1)
    t = f - i
    v = data[start + 4 * i + channel]
    if interpolate != 0 and t > 0.0 and i + 1 < n:
        v = (1.0 - t) * v + t * data[start + 4 * (i + 1) + channel]
    return v


@kernel(allocates=False)
def extrapolated(data, start, f, channel):
    """Cycles' rgb_ramp_lookup with extrapolation: linear beyond [0, 1] from the end
    entries' slope, interpolated inside."""
    n = RAMP_TABLE_SIZE
    if not math.isfinite(f):
        f = 0.0
    if f < 0.0:
        t0 = data[start + channel]
        return t0 + (t0 - data[start + 4 + channel]) * (-f) * (n - 1)
    if f > 1.0:
        t0 = data[start + 4 * (n - 1) + channel]
        return t0 + (t0 - data[start + 4 * (n - 2) + channel]) * (f - 1.0) * (n - 1)
    return ramp(data, start, f, 1, channel)


@kernel(allocates=False)
def tabulated(data, start, x, channel):
    """Channel `channel` of the COL_TABLE table at `start`, at x (0 for NaN)."""
    x0, x1, n = data[start], data[start + 1], int(data[start + 2])
    if not math.isfinite(x) or n < 1:
        return 0.0 if n < 1 else data[start + 3 + channel]
    f = (x - x0) / (x1 - x0) * (n - 1) if x1 != x0 else 0.0
    f = min(max(f, 0.0), n - 1.0)
    i = min(int(f), n - 2) if n > 1 else 0
    t = f - i
    v = data[start + 3 + 3 * i + channel]
    if n > 1 and t > 0.0:
        v = (1.0 - t) * v + t * data[start + 3 + 3 * (i + 1) + channel]
    return v


@kernel(allocates=False)
def execute(ins, regs, data):
    code, out = ins[0], ins[1]
    if code == COL_MIX:
        t = regs[ins[2]]
        c1, c2 = ins[3], ins[4]
        r, g, b = mix(ins[5], t, regs[c1], regs[c1 + 1], regs[c1 + 2], regs[c2],
                      regs[c2 + 1], regs[c2 + 2])
        if ins[6] != 0:
            r, g, b = min(max(r, 0.0), 1.0), min(max(g, 0.0), 1.0), min(max(b, 0.0), 1.0)
        regs[out], regs[out + 1], regs[out + 2] = r, g, b
    elif code == COL_RAMP_COLOR:
        f = regs[ins[2]]
        for k in range(3):
            regs[out + k] = ramp(data, ins[6], f, ins[5], k)
    elif code == COL_RAMP_ALPHA:
        regs[out] = ramp(data, ins[6], regs[ins[2]], ins[5], 3)
    elif code == COL_INVERT:
        t, c = regs[ins[2]], ins[3]
        for k in range(3):
            regs[out + k] = _lerp(regs[c + k], 1.0 - regs[c + k], t)
    elif code == COL_GAMMA:
        c, gamma = ins[2], regs[ins[3]]
        for k in range(3):
            x = regs[c + k]
            regs[out + k] = x ** gamma if x > 0.0 else x
    elif code == COL_BRIGHT_CONTRAST:
        c, bright, contrast = ins[2], regs[ins[3]], regs[ins[4]]
        a = 1.0 + contrast
        b = bright - contrast * 0.5
        for k in range(3):
            regs[out + k] = max(a * regs[c + k] + b, 0.0)
    elif code == COL_TABLE:
        x = regs[ins[2]]
        for k in range(3):
            regs[out + k] = tabulated(data, ins[6], x, k)
    elif code == COL_CURVES:
        t, c, start = regs[ins[2]], ins[3], ins[6]
        lo, hi = data[start], data[start + 1]
        span = hi - lo if hi != lo else 1.0
        for k in range(3):
            x = regs[c + k]
            y = extrapolated(data, start + 2, (x - lo) / span, k)
            regs[out + k] = (1.0 - t) * x + t * y
    elif code == COL_HSV:
        c = ins[6]
        r0, g0, b0 = regs[c], regs[c + 1], regs[c + 2]
        h, s, v = rgb_to_hsv(r0, g0, b0)
        h = h + regs[ins[2]] + 0.5
        h = h - math.floor(h)
        s = min(max(s * regs[ins[3]], 0.0), 1.0)
        v = v * regs[ins[4]]
        r, g, b = hsv_to_rgb(h, s, v)
        t = regs[ins[5]]
        regs[out] = max(_lerp(r0, r, t), 0.0)
        regs[out + 1] = max(_lerp(g0, g, t), 0.0)
        regs[out + 2] = max(_lerp(b0, b, t), 0.0)
