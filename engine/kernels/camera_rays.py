"""Camera rays of a work unit in one kernel: the sub-pixel position from the pixel
filter, a point on the lens only when there is an aperture, and the ray through both,
clipped to the camera's near and far planes. The compiled twin of
`engine.render.camera_rays` for a camera that does not move (moving cameras and zooms
keep the NumPy path); the same formulas as engine/camera.py, engine/pixel_filter.py and
engine/thin_lens.py, one ray at a time.

`cam` is a float64 vector (see `pack_camera`); the filter is given by its inverse-CDF
table (xs, cdf) and that table's guide (`guide_table`), or empty tables for the box
filter of radius cam[C_BOX_RADIUS].
"""
from __future__ import annotations

import math

import numpy as np

from ..sampling import dimensions as D
from ..sampling.dispatch import sample_2d
from .cdf_search import guide_table, last_at_most
from .jit import kernel
from .warp import concentric_disk

# cam vector layout
(C_W, C_H, C_HALF_X, C_HALF_Y, C_SHIFT_X, C_SHIFT_Y, C_PERSP, C_LENS, C_APERTURE, C_FOCUS,
 C_BLADES, C_ROTATION, C_RATIO, C_CLIP_START, C_CLIP_END, C_BOX_RADIUS) = range(16)
C_ROT = 16          # 9 values, row-major camera-to-world rotation
C_POS = 25          # 3 values
N_CAM = 28
GUIDE_CELLS = 1024  # the pixel filter's CDF guide (cdf_search)


def pack_camera(model, pixel_filter) -> tuple:
    """(cam vector, filter xs, filter cdf, the cdf's guide) of an
    engine.camera.CameraModel and an engine.pixel_filter.PixelFilter."""
    c = model.camera
    cam = np.zeros(N_CAM)
    cam[C_W], cam[C_H] = model.width, model.height
    cam[C_HALF_X], cam[C_HALF_Y] = model.half_x, model.half_y
    cam[C_SHIFT_X], cam[C_SHIFT_Y] = model.shift
    cam[C_PERSP] = c.kind == "PERSP"
    cam[C_LENS] = model.has_lens
    cam[C_APERTURE], cam[C_FOCUS] = c.aperture_radius, c.focus_distance
    cam[C_BLADES], cam[C_ROTATION], cam[C_RATIO] = c.blades, c.blade_rotation, c.aperture_ratio
    cam[C_CLIP_START], cam[C_CLIP_END] = model.clip_start, model.clip_end
    cam[C_ROT:C_ROT + 9] = model.rotation.reshape(-1)
    cam[C_POS:C_POS + 3] = model.position
    if pixel_filter.kind == "BOX":
        cam[C_BOX_RADIUS] = pixel_filter.radius
        return cam, np.zeros(0), np.zeros(0), np.zeros(0, np.int32)
    cdf = np.ascontiguousarray(pixel_filter._cdf)
    return cam, np.ascontiguousarray(pixel_filter._xs), cdf, guide_table(cdf, GUIDE_CELLS)


@kernel(allocates=False)
def interp_guided(x, xp, fp, guide):
    """np.interp(x, xp, fp) for one x, for xp increasing from 0 to 1 (a CDF; ties
    allowed) and its guide (cdf_search): the last interval with xp[j] <= x, slope times
    the distance plus fp[j] (NumPy's rule), without a binary search over all of the
    pixel filter's 4097 entries per ray."""
    n = xp.shape[0]
    if x < xp[0]:
        return fp[0]
    if x >= xp[n - 1]:
        return fp[n - 1]
    lo = last_at_most(xp, x, guide)
    slope = (fp[lo + 1] - fp[lo]) / (xp[lo + 1] - xp[lo])
    return slope * (x - xp[lo]) + fp[lo]


@kernel(allocates=False)
def filter_offset(cam, xs, cdf, guide, u):
    if xs.shape[0] == 0:
        return (u - 0.5) * (2.0 * cam[C_BOX_RADIUS])
    return interp_guided(u, cdf, xs, guide)


@kernel(allocates=False)
def aperture_point(cam, u0, u1):
    """engine.thin_lens.sample_aperture for one point."""
    blades = int(cam[C_BLADES])
    radius = cam[C_APERTURE]
    if blades >= 3:
        k = min(math.floor(u0 * blades), blades - 1)
        r0 = u0 * blades - k
        s = math.sqrt(r0)
        b1 = s * (1.0 - u1)
        b2 = s * u1
        a0 = cam[C_ROTATION] + math.pi * (2.0 * k + 1.0) / blades
        a1 = a0 + 2.0 * math.pi / blades
        x = b1 * math.cos(a0) + b2 * math.cos(a1)
        y = b1 * math.sin(a0) + b2 * math.sin(a1)
    else:
        x, y = concentric_disk(u0, u1)
    x, y = x * radius, y * radius
    if cam[C_RATIO] != 1.0:
        x /= cam[C_RATIO]
    return x, y


@kernel(allocates=False)
def generate(cam, xs, cdf, guide, kind, spp, pkey, pixel, index, origins, dirs, tmax):
    """The camera ray of every (pixel, sample index) of a unit into origins, dirs, tmax."""
    w, h = int(cam[C_W]), int(cam[C_H])
    r = cam[C_ROT:C_ROT + 9]
    for i in range(pixel.shape[0]):
        u0, u1 = sample_2d(kind, pkey[i], spp, index[i], D.PIXEL)
        fx = pixel[i] % w + 0.5 + filter_offset(cam, xs, cdf, guide, u0)
        fy = pixel[i] // w + 0.5 + filter_offset(cam, xs, cdf, guide, u1)
        px = (fx / w * 2.0 - 1.0) * cam[C_HALF_X] + cam[C_SHIFT_X]
        py = (1.0 - fy / h * 2.0) * cam[C_HALF_Y] + cam[C_SHIFT_Y]
        if cam[C_PERSP] != 0.0:
            ox, oy, oz = 0.0, 0.0, 0.0
            dx, dy, dz = px, py, -1.0
            if cam[C_LENS] != 0.0:
                l0, l1 = sample_2d(kind, pkey[i], spp, index[i], D.LENS)
                lx, ly = aperture_point(cam, l0, l1)
                f = cam[C_FOCUS]
                ox, oy = lx, ly
                dx, dy, dz = dx * f - lx, dy * f - ly, dz * f
        else:
            ox, oy, oz = px, py, 0.0
            dx, dy, dz = 0.0, 0.0, -1.0
        ln = math.sqrt(dx * dx + dy * dy + dz * dz)
        dx, dy, dz = dx / ln, dy / ln, dz / ln
        cos_axis = -dz
        t_near = cam[C_CLIP_START] / cos_axis
        t_far = cam[C_CLIP_END] / cos_axis
        wx = r[0] * dx + r[1] * dy + r[2] * dz
        wy = r[3] * dx + r[4] * dy + r[5] * dz
        wz = r[6] * dx + r[7] * dy + r[8] * dz
        origins[i, 0] = r[0] * ox + r[1] * oy + r[2] * oz + cam[C_POS] + wx * t_near
        origins[i, 1] = r[3] * ox + r[4] * oy + r[5] * oz + cam[C_POS + 1] + wy * t_near
        origins[i, 2] = r[6] * ox + r[7] * oy + r[8] * oz + cam[C_POS + 2] + wz * t_near
        dirs[i, 0], dirs[i, 1], dirs[i, 2] = wx, wy, wz
        tmax[i] = t_far - t_near
