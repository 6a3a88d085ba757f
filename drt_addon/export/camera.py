"""The scene camera to DRT's camera description, with Blender's meaning of every field.

Border render: Blender renders only the border rectangle of the frame, so DRT describes
that rectangle as a camera of its own (`window_camera`): the same lens, aperture and
focus, a view plane cut down to the rectangle (a narrower sensor) and moved to it (a
shift). Its rays are exactly the full camera's rays through those pixels.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..engine_link import engine
from .errors import ExportError
from .matrices import to_numpy


@dataclass(frozen=True)
class RenderRegion:
    """The pixels Blender asks for: the full frame (`full_width` x `full_height`, after
    the resolution percentage) and the rectangle to render, `x`, `y` its bottom-left
    corner in pixels from the frame's bottom-left (Blender's convention)."""
    full_width: int
    full_height: int
    x: int
    y: int
    width: int
    height: int

    @property
    def is_full_frame(self) -> bool:
        return (self.x, self.y, self.width, self.height) == (0, 0, self.full_width,
                                                              self.full_height)


def render_region(scene) -> RenderRegion:
    """Blender's render size and border rectangle, with the render pipeline's arithmetic:
    size = resolution x percentage // 100 in integers; border edges = int(fraction x size)
    in float32."""
    r = scene.render
    full_w = max(1, r.resolution_x * r.resolution_percentage // 100)
    full_h = max(1, r.resolution_y * r.resolution_percentage // 100)
    if not r.use_border:
        return RenderRegion(full_w, full_h, 0, 0, full_w, full_h)
    # Blender multiplies in float32: 0.7 (stored as 0.69999999) x 40 gives 28, not 27.
    f32 = np.float32
    x0, x1 = int(f32(r.border_min_x) * f32(full_w)), int(f32(r.border_max_x) * f32(full_w))
    y0, y1 = int(f32(r.border_min_y) * f32(full_h)), int(f32(r.border_max_y) * f32(full_h))
    if x1 - x0 < 1 or y1 - y0 < 1:
        raise ExportError(f"the render border ({x1 - x0} x {y1 - y0} pixels) is empty; "
                          "draw a larger border or turn Render Region off")
    return RenderRegion(full_w, full_h, x0, y0, x1 - x0, y1 - y0)


def focus_distance(cam_obj, depsgraph) -> float:
    """Blender's focus distance: the focus object's distance along the camera's view axis
    (absolute, as BKE_camera_object_dof_distance) when set, else dof.focus_distance."""
    cam = cam_obj.data
    fo = cam.dof.focus_object
    if fo is None:
        return float(cam.dof.focus_distance)
    m = to_numpy(cam_obj.evaluated_get(depsgraph).matrix_world)
    fo_ev = fo.evaluated_get(depsgraph)
    target = to_numpy(fo_ev.matrix_world)[:3, 3]
    bone = getattr(cam.dof, "focus_subtarget", "")
    if bone and fo.type == "ARMATURE" and fo_ev.pose is not None and bone in fo_ev.pose.bones:
        head = np.append(np.array(fo_ev.pose.bones[bone].head, dtype=np.float64), 1.0)
        target = (to_numpy(fo_ev.matrix_world) @ head)[:3]
    axis = m[:3, 2] / np.linalg.norm(m[:3, 2])
    return float(abs((target - m[:3, 3]) @ axis))


def export_camera(cam_obj, depsgraph) -> "engine.Camera":
    if cam_obj is None:
        raise ExportError("the scene has no active camera: add a camera and make it active "
                          "(Scene Properties > Camera)")
    if cam_obj.type != "CAMERA":
        raise ExportError(f"the scene's camera {cam_obj.name!r} is an object of type "
                          f"{cam_obj.type}, not a camera; set a camera object as the "
                          f"scene's camera")
    ev = cam_obj.evaluated_get(depsgraph)
    cam = ev.data
    m = to_numpy(ev.matrix_world)
    if not np.all(np.isfinite(m)):
        raise ExportError(f"camera {cam_obj.name!r} has a non-finite transform")
    if cam.type not in ("PERSP", "ORTHO"):
        raise ExportError(f"camera {cam_obj.name!r} is {cam.type}; DRT renders perspective "
                          "and orthographic cameras")
    aperture = 0.0
    focus = float(cam.dof.focus_distance)
    if cam.dof.use_dof and cam.type == "PERSP":
        fstop = float(cam.dof.aperture_fstop)
        if fstop > 0:
            aperture = cam.lens * 1e-3 / (2.0 * fstop)
        focus = max(focus_distance(cam_obj, depsgraph), 1e-6)
    return engine.Camera(
        matrix=m, kind=cam.type, lens=float(cam.lens), sensor_width=float(cam.sensor_width),
        sensor_height=float(cam.sensor_height), sensor_fit=cam.sensor_fit,
        ortho_scale=float(cam.ortho_scale), shift_x=float(cam.shift_x),
        shift_y=float(cam.shift_y), clip_start=float(cam.clip_start),
        clip_end=float(cam.clip_end), aperture_radius=aperture, focus_distance=focus,
        blades=int(cam.dof.aperture_blades), blade_rotation=float(cam.dof.aperture_rotation),
        aperture_ratio=float(cam.dof.aperture_ratio))


def _half_extents(camera: "engine.Camera", width: int, height: int, pixel_aspect: float):
    """Half-extents of the view plane (at distance 1 for perspective) and the half fitted
    extent shifts are measured in, with Blender's sensor fit."""
    x_ratio, y_ratio = width * pixel_aspect, float(height)
    fit = camera.sensor_fit
    if fit == "AUTO":
        horizontal, sensor = x_ratio >= y_ratio, camera.sensor_width
    elif fit == "HORIZONTAL":
        horizontal, sensor = True, camera.sensor_width
    else:
        horizontal, sensor = False, camera.sensor_height
    half_fit = (0.5 * sensor / camera.lens if camera.kind == "PERSP"
                else 0.5 * camera.ortho_scale)
    if horizontal:
        return half_fit, half_fit * y_ratio / x_ratio, half_fit
    return half_fit * x_ratio / y_ratio, half_fit, half_fit


def window_camera(camera: "engine.Camera", region: RenderRegion,
                  pixel_aspect: float) -> "engine.Camera":
    """The camera whose `region.width` x `region.height` image is the region of the full
    camera's image (horizontal sensor fit, sensor or ortho scale and shift adjusted)."""
    if region.is_full_frame:
        return camera
    W, H = region.full_width, region.full_height
    half_x, half_y, half_fit = _half_extents(camera, W, H, pixel_aspect)
    top = H - (region.y + region.height)              # rows counted from the top
    cx = ((region.x + 0.5 * region.width) / W * 2.0 - 1.0) * half_x \
        + camera.shift_x * 2.0 * half_fit
    cy = (1.0 - (top + 0.5 * region.height) / H * 2.0) * half_y \
        + camera.shift_y * 2.0 * half_fit
    hx = half_x * region.width / W
    fields = dict(sensor_fit="HORIZONTAL", shift_x=cx / (2.0 * hx), shift_y=cy / (2.0 * hx))
    if camera.kind == "PERSP":
        fields["sensor_width"] = 2.0 * hx * camera.lens
    else:
        fields["ortho_scale"] = 2.0 * hx
    return replace(camera, **fields)
