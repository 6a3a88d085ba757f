"""Blender lights to DRT lights, keeping Blender's units (see engine.lights)."""
from __future__ import annotations

import numpy as np

from ..engine_link import engine
from .errors import Reporter
from .matrices import to_numpy


def _strength(light) -> tuple:
    scale = float(light.energy) * 2.0 ** float(getattr(light, "exposure", 0.0))
    return tuple(c * scale for c in light.color)


def export_light(obj, matrix_world, reporter: Reporter):
    light = obj.data
    m = to_numpy(matrix_world)
    if getattr(light, "use_temperature", False):
        reporter.warn(f"DRT: light {obj.name!r} uses a colour temperature, which DRT does not "
                      f"model yet; using its colour", key=(obj.name, "temperature"))
    strength = _strength(light)
    direction = -m[:3, 2] / max(np.linalg.norm(m[:3, 2]), 1e-300)
    if light.type == "POINT":
        return engine.PointLight(tuple(m[:3, 3]), strength, radius=float(light.shadow_soft_size),
                                 name=obj.name)
    if light.type == "SPOT":
        return engine.PointLight(tuple(m[:3, 3]), strength, radius=float(light.shadow_soft_size),
                                 spot_size=float(light.spot_size),
                                 spot_blend=float(light.spot_blend),
                                 direction=tuple(direction), name=obj.name)
    if light.type == "SUN":
        return engine.SunLight(tuple(direction), tuple(c for c in strength),
                               angle=float(light.angle), name=obj.name)
    if light.type == "AREA":
        return engine.AreaLight(m, strength, shape=light.shape, size_x=float(light.size),
                                size_y=float(light.size_y),
                                normalize=bool(getattr(light, "normalize", True)),
                                visible_camera=bool(getattr(obj, "visible_camera", True)),
                                name=obj.name)
    reporter.warn(f"DRT: light {obj.name!r} of type {light.type} is not supported; skipped")
    return None
