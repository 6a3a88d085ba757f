"""Blender's motion-blur settings, read for export.motion: the shutter in frame time
(`MotionSettings`, with its curve) and each object's motion steps and toggles.

Settings read (Blender 5.0 names, with Cycles' meaning):
- `scene.render.use_motion_blur` and `scene.render.motion_blur_shutter` (the shutter's
  length in frames; 0 or less renders like motion blur off);
- `scene.render.motion_blur_position`: START opens the shutter at the frame
  ([f, f + s]), CENTER centres it on the frame ([f - s/2, f + s/2]), END closes it at the
  frame ([f - s, f]), as Cycles' `BlenderSync::sync_motion`;
- `scene.render.motion_blur_shutter_curve`: the shutter's openness over the shutter
  (a CurveMapping). Cycles samples it into a 256-entry table and draws ray times from
  its inverted CDF; the default is flat (a box shutter), exported as `Shutter(None)`;
  any other curve is sampled at the same 256 points into `Shutter(curve)`;
- per object (`obj.cycles`, also on the camera): `use_motion_blur`, `use_deform_motion`
  and `motion_steps`. As in Cycles (`object_motion_steps`), an object with motion
  steps n is sampled at 2**n + 1 times evenly spread over the shutter (n = 1: open,
  middle, close), and an instance needs its instancer's toggles on too (the larger of
  the two step counts is used).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from .errors import ExportError

CURVE_SAMPLES = 256           # Cycles' RAMP_TABLE_SIZE for the shutter curve


@dataclass
class MotionSettings:
    """The shutter in absolute frame time: open at `open`, close at `close`."""
    frame: int
    subframe: float
    length: float             # frames
    position: str             # START, CENTER, END
    curve: Optional[np.ndarray] = None

    @property
    def centre(self) -> float:
        f = self.frame + self.subframe
        if self.position == "START":
            return f + 0.5 * self.length
        if self.position == "END":
            return f - 0.5 * self.length
        return f

    @property
    def open(self) -> float:
        return self.centre - 0.5 * self.length

    @property
    def close(self) -> float:
        return self.centre + 0.5 * self.length

    def frame_time(self, t: float) -> float:
        """Absolute frame time of normalised shutter time t in [0, 1]."""
        return self.open + t * self.length


def read_settings(scene) -> Optional[MotionSettings]:
    """Blender's motion-blur settings, or None when the render has no motion blur.
    (Cycles' rolling shutter is not modelled: export.file_settings warns about it.)"""
    r = scene.render
    if not getattr(r, "use_motion_blur", False):
        return None
    length = float(r.motion_blur_shutter)
    if not (length > 0.0 and math.isfinite(length)):
        return None
    position = getattr(r, "motion_blur_position", None)
    if position is None:                                  # before 4.2: Cycles' setting
        position = getattr(getattr(scene, "cycles", None), "motion_blur_position", "CENTER")
    return MotionSettings(int(scene.frame_current), float(scene.frame_subframe), length,
                          str(position), shutter_curve(r.motion_blur_shutter_curve))


def shutter_curve(mapping) -> Optional[np.ndarray]:
    """The shutter curve sampled as Cycles samples it (`curvemapping_to_array`: 256
    values at i / 255), or None when it is flat (Blender's default, a box shutter)."""
    if mapping is None:
        return None
    try:
        mapping.initialize()
    except (AttributeError, RuntimeError):
        pass
    curve = mapping.curves[0]
    xs = np.arange(CURVE_SAMPLES) / (CURVE_SAMPLES - 1)
    values = np.array([mapping.evaluate(curve, float(x)) for x in xs], dtype=np.float64)
    if np.all(np.abs(values - values[0]) <= 1e-6) and values[0] > 0:
        return None
    values = np.clip(values, 0.0, None)
    if not np.isfinite(values).all() or values.sum() <= 0:
        raise ExportError("the motion-blur shutter curve is zero everywhere: no light "
                          "would reach the film; reset the curve or turn motion blur off")
    return values


def _cycles(obj):
    """The object's Cycles settings, read from the original object (an evaluated copy
    may lag behind a property just changed)."""
    if obj is None:
        return None
    original = getattr(obj, "original", None)
    return getattr(original if original is not None else obj, "cycles", None)


def motion_steps(obj, parent=None) -> int:
    """Number of motion steps of an object (0: not blurred), Cycles' `object_motion_steps`:
    2**motion_steps + 1, gated by the instancer's toggle for instanced objects."""
    c = _cycles(obj)
    if c is not None and not getattr(c, "use_motion_blur", True):
        return 0
    steps = max(1, int(getattr(c, "motion_steps", 1))) if c is not None else 1
    if parent is not None and parent != obj:
        pc = _cycles(parent)
        if pc is not None:
            if not getattr(pc, "use_motion_blur", True):
                return 0
            steps = max(steps, int(getattr(pc, "motion_steps", 1)))
    return (2 << (steps - 1)) + 1


def use_deform_motion(obj, parent=None) -> bool:
    c = _cycles(obj)
    use = bool(getattr(c, "use_deform_motion", True)) if c is not None else True
    if use and parent is not None and parent != obj:
        pc = _cycles(parent)
        if pc is not None:
            use = bool(getattr(pc, "use_deform_motion", True))
    return use
