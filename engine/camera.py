"""Camera rays with Blender's camera model: perspective and orthographic, sensor fit,
shift, clipping and an optional thin lens.

Raster convention: pixel (x, y) with y = 0 the top row; pixel id = y * width + x. The
camera looks down its local -Z with +Y up. The view plane follows Cycles' construction:
the sensor (or ortho scale) spans the fitted axis, and shift_x/shift_y are fractions of
the fitted axis's full extent. Clip distances are measured along the view axis, so the
clip planes are planes, as in Blender.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .scene import Camera
from .thin_lens import sample_aperture


@dataclass
class CameraRays:
    origins: np.ndarray      # (n, 3) float64, already moved to the near clip plane
    directions: np.ndarray   # (n, 3) float64, unit
    tmax: np.ndarray         # (n,) float64, distance to the far clip plane


class CameraModel:
    def __init__(self, camera: Camera, width: int, height: int, pixel_aspect: float = 1.0):
        m = np.asarray(camera.matrix, dtype=np.float64)
        if m.shape != (4, 4) or not np.all(np.isfinite(m)):
            raise ValueError("camera matrix must be a finite 4x4 matrix")
        rot = m[:3, :3]
        scale = np.linalg.norm(rot, axis=0)
        if np.any(scale < 1e-12):
            raise ValueError("camera matrix is degenerate (zero scale)")
        self.rotation = rot / scale            # Blender ignores camera object scale
        self.position = m[:3, 3].copy()
        self.camera = camera
        self.width, self.height = int(width), int(height)
        if camera.kind not in ("PERSP", "ORTHO"):
            raise ValueError(f"unsupported camera type {camera.kind!r} (perspective and "
                             "orthographic are supported)")
        # A clip end not beyond the clip start, or an orthographic scale of 0: Cycles
        # renders the world alone (measured; tests/test_fuzz_renders.py), and so do these
        # rays, of length 0.
        self.sees_nothing = bool(camera.clip_end <= camera.clip_start or
                                 (camera.kind == "ORTHO" and not camera.ortho_scale > 0))
        self.clip_start = float(camera.clip_start)
        self.clip_end = self.clip_start if self.sees_nothing else float(camera.clip_end)

        x_ratio = self.width * pixel_aspect
        y_ratio = float(self.height)
        fit = camera.sensor_fit
        if fit == "AUTO":
            horizontal = x_ratio >= y_ratio
            sensor = camera.sensor_width
        elif fit == "HORIZONTAL":
            horizontal, sensor = True, camera.sensor_width
        elif fit == "VERTICAL":
            horizontal, sensor = False, camera.sensor_height
        else:
            raise ValueError(f"unknown sensor fit {fit!r}")

        if camera.kind == "PERSP":
            if camera.lens <= 0 or sensor <= 0:
                raise ValueError("camera lens and sensor size must be positive")
            half_fit = 0.5 * sensor / camera.lens           # on the plane z = -1
        else:
            half_fit = 0.5 * max(camera.ortho_scale, 0.0)
        if horizontal:
            self.half_x, self.half_y = half_fit, half_fit * y_ratio / x_ratio
        else:
            self.half_x, self.half_y = half_fit * x_ratio / y_ratio, half_fit
        self.shift = np.array([camera.shift_x, camera.shift_y]) * 2.0 * half_fit
        self.has_lens = camera.kind == "PERSP" and camera.aperture_radius > 0.0
        self.lens_motion = None
        if camera.lens_motion is not None and camera.kind == "PERSP":
            times, lenses = (np.asarray(a, dtype=np.float64).reshape(-1) for a in camera.lens_motion)
            if len(times) != len(lenses) or len(times) < 1 or np.any(lenses <= 0) \
                    or not np.all(np.isfinite(lenses)) or np.any(np.diff(times) <= 0):
                raise ValueError("camera lens motion needs increasing times and positive "
                                 "focal lengths")
            self.lens_motion = (times, lenses)

    def plane_points(self, film_xy: np.ndarray) -> np.ndarray:
        """Raster positions (continuous, in pixels, y down) to view-plane x, y."""
        ndc_x = film_xy[:, 0] / self.width * 2.0 - 1.0
        ndc_y = 1.0 - film_xy[:, 1] / self.height * 2.0
        return np.stack([ndc_x * self.half_x + self.shift[0],
                         ndc_y * self.half_y + self.shift[1]], axis=-1)

    def generate(self, film_xy: np.ndarray, lens_u: np.ndarray | None = None,
                 time: np.ndarray | None = None) -> CameraRays:
        """Rays through continuous raster positions; lens_u (n, 2) only with an aperture;
        time (n,) shutter times only when the camera moves (its transform is then
        interpolated per ray, see engine.motion)."""
        cam = self.camera
        p = self.plane_points(film_xy)
        n = len(p)
        if time is not None and self.lens_motion is not None:
            # Zooming: the view plane (shift included) scales as 1 / focal length.
            lens_t = np.interp(time, *self.lens_motion)
            p = p * (cam.lens / lens_t)[:, None]
        if cam.kind == "PERSP":
            d_cam = np.concatenate([p, -np.ones((n, 1))], axis=1)
            o_cam = np.zeros((n, 3))
            if self.has_lens:
                if lens_u is None:
                    raise ValueError("a camera with an aperture needs lens samples")
                # Point on the plane of focus, then a ray from the aperture through it.
                focus = d_cam * cam.focus_distance        # z = -focus_distance
                lens = sample_aperture(lens_u, cam.aperture_radius, cam.blades,
                                       cam.blade_rotation, cam.aperture_ratio)
                o_cam = np.concatenate([lens, np.zeros((n, 1))], axis=1)
                d_cam = focus - o_cam
        else:
            o_cam = np.concatenate([p, np.zeros((n, 1))], axis=1)
            d_cam = np.tile([0.0, 0.0, -1.0], (n, 1))
        d_cam /= np.linalg.norm(d_cam, axis=1, keepdims=True)
        cos_axis = -d_cam[:, 2]                           # > 0 for every camera ray
        t_near = self.clip_start / cos_axis
        t_far = self.clip_end / cos_axis
        if time is not None and cam.motion is not None:
            m = cam.motion.at(time)
            rot = m[:, :3, :3] / np.linalg.norm(m[:, :3, :3], axis=1, keepdims=True)
            origins = np.einsum("nij,nj->ni", rot, o_cam) + m[:, :3, 3]
            dirs = np.einsum("nij,nj->ni", rot, d_cam)
        else:
            origins = o_cam @ self.rotation.T + self.position
            dirs = d_cam @ self.rotation.T
        origins = origins + dirs * t_near[:, None]
        return CameraRays(origins, dirs, t_far - t_near)
