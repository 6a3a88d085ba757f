"""Converter nodes and the socket conversions. Opcodes 300-399.

  CV_MATH out, a, b, c, operation, clamp     Math: every operation (MATH_OPS)
  CV_LUMINANCE out, color                    colour -> float (Rec.709 luminance, as
                                             Cycles converts a colour link to a float)
  CV_AVERAGE out, vector                     vector -> float (the average, as Cycles)
  CV_BROADCAST out, value                    float -> colour / vector
  CV_SEPARATE out, triple, component         Separate XYZ / Color (RGB)
  CV_COMBINE out, x, y, z                    Combine XYZ / Color (RGB)
  CV_RGB_TO_HSV out, color ; CV_HSV_TO_RGB out, hsv   Separate / Combine Color (HSV)
  CV_RGB_TO_HSL out, color ; CV_HSL_TO_RGB out, hsl   Separate / Combine Color (HSL)
  CV_MAP_RANGE out, value, from_min, from_max, to (to_min, to_max, steps), mode
                                             Map Range (float); mode = 2 x
                                             interpolation (MAP_RANGE_TYPES) + clamp
  CV_CLAMP out, value, min, max, range       Clamp (range 1: min and max may swap)
  CV_MIX_FLOAT out, fac, a, b                Mix (Float)
  CV_MIX_VECTOR out, fac, a, b, per_axis     Mix (Vector); fac a float, or a vector
                                             when per_axis is 1
"""
from __future__ import annotations

import math

from ..kernels.jit import kernel
from ..textures import LUMINANCE
from .color_nodes import hsv_to_rgb, rgb_to_hsv

CV_MATH = 300
CV_LUMINANCE = 301
CV_AVERAGE = 302
CV_BROADCAST = 303
CV_SEPARATE = 304
CV_COMBINE = 305
CV_RGB_TO_HSV = 306
CV_HSV_TO_RGB = 307
CV_MAP_RANGE = 308
CV_CLAMP = 309
CV_MIX_FLOAT = 310
CV_MIX_VECTOR = 311
CV_RGB_TO_HSL = 312
CV_HSL_TO_RGB = 313

MATH_OPS = ("ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "POWER", "LOGARITHM",
            "SQRT", "INVERSE_SQRT", "ABSOLUTE", "EXPONENT", "MINIMUM", "MAXIMUM",
            "LESS_THAN", "GREATER_THAN", "SIGN", "COMPARE", "SMOOTH_MIN", "SMOOTH_MAX",
            "ROUND", "FLOOR", "CEIL", "TRUNC", "FRACT", "MODULO", "FLOORED_MODULO", "WRAP",
            "SNAP", "PINGPONG", "SINE", "COSINE", "TANGENT", "ARCSINE", "ARCCOSINE",
            "ARCTANGENT", "ARCTAN2", "SINH", "COSH", "TANH", "RADIANS", "DEGREES")
MAP_RANGE_TYPES = ("LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP")
LUM_R, LUM_G, LUM_B = (float(x) for x in LUMINANCE)


@kernel(allocates=False)
def safe_divide(a, b):
    return a / b if b != 0.0 else 0.0


@kernel(allocates=False)
def smoothmin(a, b, c):
    if c != 0.0:
        h = max(c - abs(a - b), 0.0) / c
        return min(a, b) - h * h * h * c * (1.0 / 6.0)
    return min(a, b)


@kernel(allocates=False)
def wrap(value, hi, lo):
    rng = hi - lo
    if rng != 0.0:
        return value - rng * math.floor((value - lo) / rng)
    return lo


@kernel(allocates=False)
def fract(x):
    return x - math.floor(x)


@kernel(allocates=False)
def pingpong(a, b):
    if b != 0.0:
        return abs(fract((a - b) / (b * 2.0)) * b * 2.0 - b)
    return 0.0


@kernel(allocates=False)
def safe_modulo(a, b):
    if b == 0.0:
        return 0.0
    r = abs(a) - math.floor(abs(a) / abs(b)) * abs(b)      # C's fmod: the sign of a
    return -r if a < 0.0 else r


@kernel(allocates=False)
def math_op(op, a, b, c):
    """Cycles' svm_math of operation MATH_OPS[op] (the safe variants: no NaN from a
    division by zero, a negative root or logarithm)."""
    if op == 0:
        return a + b
    if op == 1:
        return a - b
    if op == 2:
        return a * b
    if op == 3:
        return safe_divide(a, b)
    if op == 4:
        return a * b + c
    if op == 5:                                   # safe_powf
        if a < 0.0 and b != math.floor(b):
            return 0.0
        if a == 0.0 and b < 0.0:
            return 0.0
        return a ** b
    if op == 6:                                   # safe_logf
        if a <= 0.0 or b <= 0.0 or b == 1.0:
            return 0.0
        return math.log(a) / math.log(b)
    if op == 7:
        return math.sqrt(a) if a > 0.0 else 0.0
    if op == 8:
        return 1.0 / math.sqrt(a) if a > 0.0 else 0.0
    if op == 9:
        return abs(a)
    if op == 10:
        return math.exp(min(a, 700.0))
    if op == 11:
        return min(a, b)
    if op == 12:
        return max(a, b)
    if op == 13:
        return 1.0 if a < b else 0.0
    if op == 14:
        return 1.0 if a > b else 0.0
    if op == 15:
        return 1.0 if a > 0.0 else (-1.0 if a < 0.0 else 0.0)
    if op == 16:
        return 1.0 if abs(a - b) <= max(c, 1e-5) else 0.0
    if op == 17:
        return smoothmin(a, b, c)
    if op == 18:
        return -smoothmin(-a, -b, c)
    if op == 19:
        return math.floor(a + 0.5)
    if op == 20:
        return math.floor(a)
    if op == 21:
        return math.ceil(a)
    if op == 22:
        return math.floor(a) if a >= 0.0 else math.ceil(a)
    if op == 23:
        return fract(a)
    if op == 24:
        return safe_modulo(a, b)
    if op == 25:
        return a - math.floor(a / b) * b if b != 0.0 else 0.0
    if op == 26:
        return wrap(a, b, c)
    if op == 27:
        return math.floor(safe_divide(a, b)) * b
    if op == 28:
        return pingpong(a, b)
    if op == 29:
        return math.sin(a) if math.isfinite(a) else 0.0
    if op == 30:
        return math.cos(a) if math.isfinite(a) else 0.0
    if op == 31:
        return math.tan(a) if math.isfinite(a) else 0.0
    if op == 32:
        return math.asin(min(max(a, -1.0), 1.0))
    if op == 33:
        return math.acos(min(max(a, -1.0), 1.0))
    if op == 34:
        return math.atan(a)
    if op == 35:
        return math.atan2(a, b)
    if op == 36:
        return math.sinh(min(max(a, -700.0), 700.0))
    if op == 37:
        return math.cosh(min(max(a, -700.0), 700.0))
    if op == 38:
        return math.tanh(a)
    if op == 39:
        return a * (math.pi / 180.0)
    return a * (180.0 / math.pi)


@kernel(allocates=False)
def smoothstep(e0, e1, x):
    if x < e0:
        return 0.0
    if x >= e1:
        return 1.0
    t = (x - e0) / (e1 - e0)
    return t * t * (3.0 - 2.0 * t)


@kernel(allocates=False)
def smootherstep(e0, e1, x):
    x = min(max(safe_divide(x - e0, e1 - e0), 0.0), 1.0)
    return x * x * x * (x * (x * 6.0 - 15.0) + 10.0)


@kernel(allocates=False)
def map_range(value, fmin, fmax, tmin, tmax, steps, kind, clamp):
    if fmax == fmin:
        return 0.0
    if kind == 0 or kind == 1:
        factor = (value - fmin) / (fmax - fmin)
        if kind == 1:
            factor = math.floor(factor * (steps + 1.0)) / steps if steps > 0.0 else 0.0
    elif kind == 2:
        factor = (1.0 - smoothstep(fmax, fmin, value) if fmin > fmax
                  else smoothstep(fmin, fmax, value))
    else:
        factor = (1.0 - smootherstep(fmax, fmin, value) if fmin > fmax
                  else smootherstep(fmin, fmax, value))
    result = tmin + factor * (tmax - tmin)
    if clamp != 0 and kind < 2:
        lo, hi = min(tmin, tmax), max(tmin, tmax)
        result = min(max(result, lo), hi)
    return result


@kernel(allocates=False)
def _hue_to_rgb(p, q, t):
    if t < 0.0:
        t += 1.0
    if t > 1.0:
        t -= 1.0
    if t < 1.0 / 6.0:
        return p + (q - p) * 6.0 * t
    if t < 0.5:
        return q
    if t < 2.0 / 3.0:
        return p + (q - p) * (2.0 / 3.0 - t) * 6.0
    return p


@kernel(allocates=False)
def rgb_to_hsl(r, g, b):
    cmax, cmin = max(r, g, b), min(r, g, b)
    l = min((cmax + cmin) * 0.5, 1.0)
    if cmax == cmin:
        return 0.0, 0.0, l
    d = cmax - cmin
    s = d / (2.0 - cmax - cmin) if l > 0.5 else d / (cmax + cmin)
    if cmax == r:
        h = (g - b) / d + (6.0 if g < b else 0.0)
    elif cmax == g:
        h = (b - r) / d + 2.0
    else:
        h = (r - g) / d + 4.0
    return h / 6.0, s, l


@kernel(allocates=False)
def hsl_to_rgb(h, s, l):
    if s == 0.0:
        return l, l, l
    q = l * (1.0 + s) if l < 0.5 else l + s - l * s
    p = 2.0 * l - q
    return (_hue_to_rgb(p, q, h + 1.0 / 3.0), _hue_to_rgb(p, q, h),
            _hue_to_rgb(p, q, h - 1.0 / 3.0))


@kernel(allocates=False)
def execute(ins, regs):
    code, out = ins[0], ins[1]
    a = ins[2]
    if code == CV_MATH:
        r = math_op(ins[5], regs[a], regs[ins[3]], regs[ins[4]])
        if ins[6] != 0:
            r = min(max(r, 0.0), 1.0)
        regs[out] = r
    elif code == CV_LUMINANCE:
        regs[out] = regs[a] * LUM_R + regs[a + 1] * LUM_G + regs[a + 2] * LUM_B
    elif code == CV_AVERAGE:
        regs[out] = (regs[a] + regs[a + 1] + regs[a + 2]) / 3.0
    elif code == CV_BROADCAST:
        regs[out] = regs[out + 1] = regs[out + 2] = regs[a]
    elif code == CV_SEPARATE:
        regs[out] = regs[a + ins[3]]
    elif code == CV_COMBINE:
        regs[out], regs[out + 1], regs[out + 2] = regs[a], regs[ins[3]], regs[ins[4]]
    elif code == CV_RGB_TO_HSV:
        regs[out], regs[out + 1], regs[out + 2] = rgb_to_hsv(regs[a], regs[a + 1], regs[a + 2])
    elif code == CV_HSV_TO_RGB:
        regs[out], regs[out + 1], regs[out + 2] = hsv_to_rgb(regs[a], regs[a + 1], regs[a + 2])
    elif code == CV_RGB_TO_HSL:
        regs[out], regs[out + 1], regs[out + 2] = rgb_to_hsl(regs[a], regs[a + 1], regs[a + 2])
    elif code == CV_HSL_TO_RGB:
        regs[out], regs[out + 1], regs[out + 2] = hsl_to_rgb(regs[a], regs[a + 1], regs[a + 2])
    elif code == CV_MAP_RANGE:
        to = ins[5]
        regs[out] = map_range(regs[a], regs[ins[3]], regs[ins[4]], regs[to], regs[to + 1],
                              regs[to + 2], ins[6] // 2, ins[6] % 2)
    elif code == CV_CLAMP:
        lo, hi = regs[ins[3]], regs[ins[4]]
        if ins[5] != 0 and lo > hi:
            lo, hi = hi, lo
        regs[out] = min(max(regs[a], lo), hi)
    elif code == CV_MIX_FLOAT:
        t = regs[a]
        regs[out] = (1.0 - t) * regs[ins[3]] + t * regs[ins[4]]
    elif code == CV_MIX_VECTOR:
        x, y = ins[3], ins[4]
        for k in range(3):
            t = regs[a + k] if ins[5] != 0 else regs[a]
            regs[out + k] = (1.0 - t) * regs[x + k] + t * regs[y + k]
