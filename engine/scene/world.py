"""The scene description's `World`: the background escaped rays see, which also
lights the scene."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from .lights import SunLight

@dataclass
class World:
    """The background seen by escaped rays, which also lights the scene.

    Without a texture: uniform radiance `color` (Blender's colour x strength). With one:
    an equirectangular environment map (`engine.textures.Texture`, REPEAT extension, as
    Cycles' Environment Texture reads it) times `strength` (RGB), looked up along
    `mapping` @ direction (a 3x3 matrix, Blender's Mapping node; None = identity); see
    `engine.environment_map` for the projection. `color` is then not used.
    visibility: the ray kinds that see it (engine.visibility; Blender's World > Ray
    Visibility); see `engine.world_light`.
    camera_texture: what camera rays see instead of `texture` (same strength and
    mapping), when the world's node graph shows the camera another background than the
    one that lights the scene (a Light Path node's Is Camera Ray); None = the same.
    sun: a `SunLight` that belongs to the world (a Sky Texture's sun disc,
    `engine.sky_texture`), rendered as one more lamp; None = none.
    light_sampling: whether next-event estimation samples the world (Blender's World >
    Settings > Sampling Method, not None; see engine.lights.LightSet for a uniform
    world, which Cycles never samples)."""
    color: tuple = (0.0, 0.0, 0.0)
    texture: Optional[object] = None
    strength: tuple = (1.0, 1.0, 1.0)
    mapping: Optional[np.ndarray] = None
    visibility: int = 31
    volume: Optional[object] = None      # Volume filling the space outside every mesh
    camera_texture: Optional[object] = None
    sun: Optional[SunLight] = None
    light_sampling: bool = True
    lightgroup: str = ""           # its light's group (Scene.light_groups; "": none)
