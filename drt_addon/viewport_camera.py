"""The 3D viewport's view as DRT's camera: what the Rendered viewport (drt_addon.viewport)
traces.

Blender gives a 3D view as two matrices: the view matrix (world to view) and the window
matrix (view to clip space: the projection, with the viewport's zoom and pan, and in
camera view the camera's lens, shift and clipping). `projection_camera` turns them into an
engine.Camera whose rays are exactly the ones through the viewport's pixels: a
perspective or orthographic camera with a horizontal sensor fit, its half-width read off
the window matrix, its off-centre part as a shift, its clip planes from the depth rows.

Render Region: outside camera view, the viewport's own region (View > Render Region,
fractions of the view); in camera view, the scene's (Output > Format > Render Region,
fractions of the camera's frame), as Cycles reads them. Only those pixels are traced,
through `export.camera.window_camera`'s camera of that rectangle.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .engine_link import engine
from .export.camera import RenderRegion, _half_extents, export_camera, window_camera

LENS = 50.0          # mm: any focal length works; the sensor width is set to match it


def projection_camera(view_matrix, window_matrix, dof=None) -> "engine.Camera":
    """engine.Camera of a view (4x4 world-to-view) and a window (4x4 projection) matrix.
    In camera view `dof` is the scene camera (engine.Camera) whose aperture and focus
    the view keeps; elsewhere the view is a pinhole, as in Cycles' viewport."""
    v = np.asarray(view_matrix, dtype=np.float64).reshape(4, 4)
    p = np.asarray(window_matrix, dtype=np.float64).reshape(4, 4)
    if not (np.all(np.isfinite(v)) and np.all(np.isfinite(p))) or p[0, 0] == 0 or p[1, 1] == 0:
        raise ValueError("the 3D view's matrices are not finite and invertible")
    to_world = np.linalg.inv(v)
    perspective = p[3, 3] == 0.0
    half_x = 1.0 / p[0, 0]
    if perspective:
        shift_x, shift_y = 0.5 * p[0, 2], 0.5 * p[1, 2] * p[0, 0] / p[1, 1]
        near, far = p[2, 3] / (p[2, 2] - 1.0), p[2, 3] / (p[2, 2] + 1.0)
        fields = dict(kind="PERSP", lens=LENS, sensor_width=2.0 * half_x * LENS)
    else:
        shift_x, shift_y = -0.5 * p[0, 3], -0.5 * p[1, 3] * p[0, 0] / p[1, 1]
        near, far = (p[2, 3] + 1.0) / p[2, 2], (p[2, 3] - 1.0) / p[2, 2]
        fields = dict(kind="ORTHO", ortho_scale=2.0 * half_x)
    camera = engine.Camera(matrix=to_world, sensor_fit="HORIZONTAL", shift_x=float(shift_x),
                           shift_y=float(shift_y), clip_start=float(near),
                           clip_end=float(far), **fields)
    if dof is not None and perspective and dof.aperture_radius > 0:
        camera = replace(camera, aperture_radius=dof.aperture_radius,
                         focus_distance=dof.focus_distance, blades=dof.blades,
                         blade_rotation=dof.blade_rotation, aperture_ratio=dof.aperture_ratio)
    return camera


@dataclass(frozen=True)
class ViewportView:
    """What the viewport shows: the camera of the whole view at `width` x `height`
    traced pixels (the region's size over Pixel Size), and the rectangle traced
    (`region`, bottom-left origin, in traced pixels). `key` changes when any of it does."""
    camera: "engine.Camera"
    width: int
    height: int
    region: RenderRegion
    pixel_size: int
    key: tuple

    def traced_camera(self) -> "engine.Camera":
        """The camera of the traced rectangle alone."""
        return window_camera(self.camera, self.region, 1.0)


def _pixel_size(scene) -> int:
    """Render > Performance > Viewport > Pixel Size (Automatic: 1 at the usual DPI)."""
    size = getattr(scene.render, "preview_pixel_size", "AUTO")
    return int(size) if size.isdigit() else 1


def _camera_frame(scene, depsgraph, window_matrix):
    """The scene camera's frame in camera view, as (x0, y0, x1, y1) fractions of the
    view: its view-plane corners through the window matrix."""
    from .export import render_size
    cam = export_camera(scene.camera, depsgraph)
    w, h = render_size(scene)
    aspect = scene.render.pixel_aspect_x / max(scene.render.pixel_aspect_y, 1e-9)
    half_x, half_y, half_fit = _half_extents(cam, w, h, aspect)
    cx, cy = cam.shift_x * 2.0 * half_fit, cam.shift_y * 2.0 * half_fit
    p = np.asarray(window_matrix, dtype=np.float64).reshape(4, 4)
    z = -1.0 if cam.kind == "PERSP" else -max(cam.clip_start, 1e-3)
    pts = []
    for sx, sy in ((-1, -1), (1, 1)):
        clip = p @ np.array([cx + sx * half_x, cy + sy * half_y, z, 1.0])
        pts.append((clip[:2] / clip[3] + 1.0) * 0.5)
    return pts[0][0], pts[0][1], pts[1][0], pts[1][1]


def _border(fractions, width, height) -> RenderRegion:
    """The pixels of a border given as (x0, y0, x1, y1) fractions, clipped to the view."""
    x0, y0, x1, y1 = fractions
    px0, px1 = (int(np.clip(round(f * width), 0, width)) for f in (x0, x1))
    py0, py1 = (int(np.clip(round(f * height), 0, height)) for f in (y0, y1))
    if px1 - px0 < 1 or py1 - py0 < 1:
        return RenderRegion(width, height, 0, 0, 0, 0)
    return RenderRegion(width, height, px0, py0, px1 - px0, py1 - py0)


def view_of(context, depsgraph) -> ViewportView:
    """The view the viewport shows now (`context`: the view_draw or view_update context)."""
    scene, region, space, rv3d = (depsgraph.scene, context.region, context.space_data,
                                  context.region_data)
    size = _pixel_size(scene)
    width, height = max(1, region.width // size), max(1, region.height // size)
    in_camera = rv3d.view_perspective == "CAMERA" and scene.camera is not None \
        and scene.camera.type == "CAMERA"
    dof = export_camera(scene.camera, depsgraph) if in_camera else None
    camera = projection_camera(rv3d.view_matrix, rv3d.window_matrix, dof)
    if in_camera and scene.render.use_border:
        fx0, fy0, fx1, fy1 = _camera_frame(scene, depsgraph, rv3d.window_matrix)
        r = scene.render
        rect = _border((fx0 + (fx1 - fx0) * r.border_min_x, fy0 + (fy1 - fy0) * r.border_min_y,
                        fx0 + (fx1 - fx0) * r.border_max_x, fy0 + (fy1 - fy0) * r.border_max_y),
                       width, height)
    elif not in_camera and getattr(space, "use_render_border", False):
        rect = _border((space.render_border_min_x, space.render_border_min_y,
                        space.render_border_max_x, space.render_border_max_y), width, height)
    else:
        rect = RenderRegion(width, height, 0, 0, width, height)
    key = (tuple(map(tuple, camera.matrix.round(12))), camera.kind, camera.sensor_width,
           camera.ortho_scale, camera.shift_x, camera.shift_y, camera.clip_start,
           camera.clip_end, camera.aperture_radius, camera.focus_distance, width, height,
           rect, size)
    return ViewportView(camera, width, height, rect, size, key)
