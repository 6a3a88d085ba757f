"""The scene description's lamps, in Blender's units: `PointLight` (also spot and
sphere lights), `SunLight` and `AreaLight`."""
from __future__ import annotations

import math

from dataclasses import dataclass
from typing import Optional

import numpy as np

@dataclass
class PointLight:
    """A point light, or a sphere light when radius > 0. strength: RGB watts (Blender's
    colour x power x 2**exposure). Spot lights add a cone: spot_size is the full cone
    angle in radians, spot_blend Blender's 0..1 blend, `direction` the light's -Z axis.

    soft_falloff: Blender's `use_soft_falloff` (on by default). With radius > 0, Cycles
    then does not render a sphere but a disc of the same radius and radiance
    S / (4 pi^2 r^2), centred on the light and always facing the shaded point (sampled
    uniformly by area); only the part above the point's horizon lights it. Far from the
    light both give the intensity S / (4 pi); 1 m from a 0.3 m light the disc gives a
    few percent less. False means a sphere (what `use_soft_falloff` off gives in Cycles)."""
    position: tuple
    strength: tuple
    radius: float = 0.0
    spot_size: Optional[float] = None
    spot_blend: float = 0.0
    direction: tuple = (0.0, 0.0, -1.0)
    name: str = "point"
    soft_falloff: bool = False
    visibility: int = 31           # the ray kinds that see it (engine.visibility)
    motion_slices: Optional[list] = None   # this light at K shutter-slice middles (moving)
    lightgroup: str = ""           # its light group's name (Scene.light_groups; "": none)
    shadow_catcher: bool = True    # the lamp lights shadow catchers (Blender's default)


@dataclass
class SunLight:
    """A distant light. strength: RGB irradiance in W/m^2 at normal incidence; direction
    is where the light travels (the lamp's -Z); angle the full angular diameter, radians."""
    direction: tuple
    strength: tuple
    angle: float = 0.0
    name: str = "sun"
    visibility: int = 31           # the ray kinds that see it (engine.visibility)
    motion_slices: Optional[list] = None   # this light at K shutter-slice middles (moving)
    lightgroup: str = ""           # its light group's name (Scene.light_groups; "": none)
    shadow_catcher: bool = True    # the lamp lights shadow catchers (Blender's default)


@dataclass
class AreaLight:
    """A one-sided area light emitting along its local -Z.

    matrix: 4x4 light-to-world transform (scale allowed), shape one of 'SQUARE',
    'RECTANGLE', 'DISK', 'ELLIPSE'; size_x/size_y in local units; strength RGB watts;
    normalize as Blender's `normalize` (radiance divided by the area when True); spread
    the full angle (radians) of the cone each point emits into, Blender's Spread (pi:
    the whole hemisphere)."""
    matrix: np.ndarray
    strength: tuple
    shape: str = "SQUARE"
    size_x: float = 1.0
    size_y: float = 1.0
    normalize: bool = True
    spread: float = math.pi
    visible_camera: bool = True
    name: str = "area"
    visibility: int = 31           # the ray kinds that see it (engine.visibility)
    motion_slices: Optional[list] = None   # this light at K shutter-slice middles (moving)
    lightgroup: str = ""           # its light group's name (Scene.light_groups; "": none)
    shadow_catcher: bool = True    # the lamp lights shadow catchers (Blender's default)
