"""The scene description's `Camera`: a Blender camera reduced to what rays need."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

@dataclass
class Camera:
    """A Blender camera reduced to what rays need.

    matrix: 4x4 camera-to-world (scale is removed by the camera model).
    kind: 'PERSP' or 'ORTHO'. For PERSP, `fov_x`/`fov_y` are implied by
    sensor_width/sensor_height/lens/sensor_fit like Blender; for ORTHO, ortho_scale is
    the extent along the fitted axis. shift_x/shift_y are in units of the fitted
    extent, as in Blender. aperture_radius in metres (0 = pinhole), focus_distance in
    metres, blades 0 for a round aperture.
    """
    matrix: np.ndarray
    kind: str = "PERSP"
    lens: float = 50.0
    sensor_width: float = 36.0
    sensor_height: float = 24.0
    sensor_fit: str = "AUTO"
    ortho_scale: float = 6.0
    shift_x: float = 0.0
    shift_y: float = 0.0
    clip_start: float = 0.1
    clip_end: float = 1000.0
    aperture_radius: float = 0.0
    focus_distance: float = 10.0
    blades: int = 0
    blade_rotation: float = 0.0
    aperture_ratio: float = 1.0
    motion: Optional[object] = None      # engine.motion.RigidMotion of `matrix` over the shutter
    lens_motion: Optional[tuple] = None  # (times (K,), focal lengths in mm (K,)) over the shutter
