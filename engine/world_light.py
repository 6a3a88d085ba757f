"""The world as a light: the parameters of what escaped rays see and of how next-event
estimation samples it (engine/kernels/lights/environment.py, environment_map.py).

Two models, one per kind of `engine.scene.World`:
- `EnvironmentLightModel`, a uniform background (colour x strength), as Cycles samples
  it: uniform directions over the sphere, pdf 1 / (4 pi);
- `EnvironmentMapLightModel`, an equirectangular image (`engine.environment_map`),
  directions importance-sampled from the image's luminance.
Both are entries of the `engine.lights.LightSet` with a power, as the lamps. They are never
hit as surfaces (BSDF rays find them by escaping), and weighted by MIS against the BSDF
rays that escape.

Ray visibility (Blender's World > Ray Visibility, `World.visibility`): `seen_by` is the
world's mask (engine.visibility); escaped rays of a kind it lacks see black (camera rays
off: a black background, as Cycles renders it), and `visibility`, the mask next-event
estimation uses, is the same without CAMERA (the world is never hit as a surface) and
with SHADOW. Measured on hdri_world (256 samples, image means): camera, diffuse or
glossy off match Cycles 5.0 within 0.05 %; Cycles ignores the Shadow box.
"""
from __future__ import annotations

import numpy as np

from . import visibility as vis
from .environment_map import EnvironmentMap
from .luminance import luminance


class _World:
    delta = False
    visible = False
    visible_camera = False
    is_environment = True

    def _set_visibility(self, seen_by):
        self.seen_by = int(seen_by)
        # never hit as a surface; always casting shadows: Cycles 5.0 ignores the world's
        # Shadow box (hdri_world renders the same with it off)
        self.visibility = (self.seen_by & ~vis.CAMERA) | vis.SHADOW


class EnvironmentLightModel(_World):
    """The world's uniform background as a light: next-event estimation from every vertex
    (uniform directions over the sphere, pdf 1 / (4 pi))."""

    def __init__(self, radiance, seen_by=vis.ALL):
        self.radiance = np.asarray(radiance, dtype=np.float64)[:3]
        self.pdf_value = 1.0 / (4.0 * np.pi)
        self._set_visibility(seen_by)

    def power(self, scene_radius):
        # irradiance pi L on a scene of cross-section pi R^2 (as for the sun)
        return luminance(self.radiance) * np.pi * np.pi * scene_radius ** 2


class EnvironmentMapLightModel(_World):
    """An environment map as a light (see engine.environment_map)."""

    def __init__(self, env: EnvironmentMap, seen_by=vis.ALL, camera_texture=None):
        self.map = env
        self.camera_texture = camera_texture     # what camera rays see instead, or None
        self._set_visibility(seen_by)

    def power(self, scene_radius):
        return self.map.mean_luminance * np.pi * np.pi * scene_radius ** 2


def world_model(world):
    """The light model of an `engine.scene.World` (its texture, else its colour), or of
    a plain RGB triple (a uniform world)."""
    texture = getattr(world, "texture", None)
    seen_by = getattr(world, "visibility", vis.ALL)
    if texture is not None:
        model = EnvironmentMapLightModel(EnvironmentMap(texture, world.strength, world.mapping),
                                         seen_by, getattr(world, "camera_texture", None))
    else:
        model = EnvironmentLightModel(getattr(world, "color", world), seen_by)
    # World > Settings > Sampling Method None: not sampled as a light (engine.lights)
    model.light_sampling = bool(getattr(world, "light_sampling", True))
    return model
