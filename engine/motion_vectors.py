"""Cycles' Vector pass, for the compositor's Vector Blur node: per pixel, how far the
surface its centre sees moves on the image from the previous frame to this one and from
this one to the next, in pixels.

Four values, as Cycles writes them (measured against Cycles in tests/test_vector_pass.py):
(x, y) of previous - now, then (x, y) of now - next, x to the right and y up; 0 where the
pixel sees no surface (Cycles writes no motion for the world). Cycles writes the pass only
with motion blur off (zeros with it on), and so does drt_addon.

The scene given is the *vector scene*: exported with motion over the frames f - 1 to
f + 1 (shutter times 0, 0.5 and 1; drt_addon.export, `motion=`), so that where a surface
point was and will be comes from the same motion data motion blur uses: rigid
transforms and deformation, of the objects and of the camera. Each pixel's centre is
traced at time 0.5 (this frame); the surface point hit is placed at times 0 and 1 by
the surface builder (the same triangle, the same barycentrics), and each of the three
places is projected through the camera of its own time.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .camera import CameraModel

CHUNK = 1 << 16


def _camera_matrices(camera, t: float, n: int) -> np.ndarray:
    """(n, 4, 4) camera-to-world at shutter time t (the camera's motion, if it moves)."""
    if camera.motion is not None:
        return camera.motion.at(np.full(n, t))
    return np.broadcast_to(np.asarray(camera.matrix, np.float64), (n, 4, 4))


def raster_positions(model: CameraModel, matrices: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(n, 2) image positions in pixels (x right from the left edge, y up from the bottom
    edge) of world `points` (n, 3) seen through cameras placed by `matrices` (n, 4, 4)
    with `model`'s projection (lens, sensor, shift; object scale ignored, as Blender)."""
    rot = matrices[:, :3, :3]
    rot = rot / np.linalg.norm(rot, axis=1)[:, None, :]
    local = np.einsum("nji,nj->ni", rot, points - matrices[:, :3, 3])     # R^T (p - o)
    if model.camera.kind == "PERSP":
        plane = local[:, :2] / np.maximum(-local[:, 2:3], 1e-12)
    else:
        plane = local[:, :2]
    half = np.array([model.half_x, model.half_y])
    return (plane - model.shift + half) / (2.0 * half) * np.array([model.width, model.height])


def vector_pass(ctx) -> np.ndarray:
    """(height, width, 4) float64, rows top-down: the Vector pass of `ctx`'s vector scene
    (an engine.RenderContext)."""
    scene = ctx.scene
    w, h = scene.width, scene.height
    out = np.zeros((w * h, 4))
    if not ctx.has_motion:
        return out.reshape(h, w, 4)             # nothing moves: no motion anywhere
    pinhole = CameraModel(replace(scene.camera, aperture_radius=0.0), w, h,
                          scene.pixel_aspect)
    for start in range(0, w * h, CHUNK):
        pix = np.arange(start, min(start + CHUNK, w * h))
        xy = np.stack([pix % w + 0.5, pix // w + 0.5], axis=1).astype(np.float64)
        middle = np.full(len(pix), 0.5)
        rays = pinhole.generate(xy, time=middle)
        hits = ctx.accel.intersect(rays.origins, rays.directions, rays.tmax, time=middle)
        hit = np.nonzero(hits.hit)[0]
        if not hit.size:
            continue
        places = []
        for t in (0.0, 0.5, 1.0):
            si = ctx.surfaces.build(hits, hit, rays.directions, time=np.full(len(pix), t),
                                    origins=rays.origins)
            places.append(raster_positions(
                pinhole, _camera_matrices(scene.camera, t, len(hit)), si.position))
        before, now, after = places
        out[pix[hit], 0:2] = before - now
        out[pix[hit], 2:4] = now - after
    return out.reshape(h, w, 4)
