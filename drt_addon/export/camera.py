"""The scene camera to DRT's camera description, with Blender's meaning of every field."""
from __future__ import annotations

import numpy as np

from ..engine_link import engine
from .errors import ExportError
from .matrices import to_numpy


def export_camera(cam_obj, depsgraph) -> "engine.Camera":
    if cam_obj is None:
        raise ExportError("the scene has no active camera: add a camera and make it active "
                          "(Scene Properties > Camera)")
    if cam_obj.type != "CAMERA":
        raise ExportError(f"the active camera {cam_obj.name!r} is a {cam_obj.type}, not a camera")
    ev = cam_obj.evaluated_get(depsgraph)
    cam = ev.data
    m = to_numpy(ev.matrix_world)
    if cam.type not in ("PERSP", "ORTHO"):
        raise ExportError(f"camera {cam_obj.name!r} is {cam.type}; DRT renders perspective "
                          "and orthographic cameras")
    aperture = 0.0
    focus = float(cam.dof.focus_distance)
    if cam.dof.use_dof and cam.type == "PERSP":
        fstop = float(cam.dof.aperture_fstop)
        if fstop > 0:
            aperture = cam.lens * 1e-3 / (2.0 * fstop)
        if cam.dof.focus_object is not None:
            fo = cam.dof.focus_object.evaluated_get(depsgraph)
            target = np.array(fo.matrix_world.translation, dtype=np.float64)
            view_axis = -m[:3, 2] / np.linalg.norm(m[:3, 2])
            focus = float((target - m[:3, 3]) @ view_axis)
        focus = max(focus, 1e-6)
    return engine.Camera(
        matrix=m, kind=cam.type, lens=float(cam.lens), sensor_width=float(cam.sensor_width),
        sensor_height=float(cam.sensor_height), sensor_fit=cam.sensor_fit,
        ortho_scale=float(cam.ortho_scale), shift_x=float(cam.shift_x),
        shift_y=float(cam.shift_y), clip_start=float(cam.clip_start),
        clip_end=float(cam.clip_end), aperture_radius=aperture, focus_distance=focus,
        blades=int(cam.dof.aperture_blades), blade_rotation=float(cam.dof.aperture_rotation),
        aperture_ratio=float(cam.dof.aperture_ratio))
