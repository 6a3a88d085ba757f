"""Blender lights to DRT lights, keeping Blender's units (see engine.lights).

Checked against Cycles 5.0 renders (tests/test_lights_vs_cycles.py), per light type:
- strength S = colour x blackbody colour (when `use_temperature`) x energy x 2^exposure,
  times its node tree's Emission colour x strength (light_nodes.py);
- `normalize` (on every light type since Blender 4.4): Cycles divides a point or spot
  light's power by the area of its sphere (4 pi r^2, or 4 when r = 0) and a sun's by the
  area of its disc (pi sin^2(angle / 2), or 1 when the angle is 0); with `normalize` off
  it does not. DRT's point and sun lights always normalise, so with `normalize` off the
  exporter multiplies the strength by that same area, which gives Cycles' radiance.
  Area lights carry the flag to the engine.
"""
from __future__ import annotations

import math

import numpy as np

from ..engine_link import engine
from .errors import Reporter
from .light_nodes import emission_factor
from .matrices import to_numpy


def light_strength(light) -> tuple:
    """RGB strength S = colour x energy x 2^exposure (x blackbody colour)."""
    scale = float(light.energy) * 2.0 ** float(getattr(light, "exposure", 0.0))
    color = np.array(light.color[:3], dtype=np.float64)
    if getattr(light, "use_temperature", False):
        color = color * np.array(light.temperature_color[:3], dtype=np.float64)
    return tuple(float(c) * scale for c in color)


def _normalize(light) -> bool:
    return bool(getattr(light, "normalize", True))


def _point_area(radius: float) -> float:
    """The area Cycles divides a point or spot light's power by when normalising."""
    return 4.0 * math.pi * radius * radius if radius > 0.0 else 4.0


def _sun_area(angle: float) -> float:
    half = 0.5 * angle
    return math.pi * math.sin(half) ** 2 if half > 0.0 else 1.0


def _scaled(strength, factor):
    return tuple(c * factor for c in strength)


visibility = engine.visibility


def object_visibility(obj) -> int:
    """Object Properties > Visibility > Ray Visibility as an engine.visibility mask."""
    return visibility.from_flags(
        camera=bool(getattr(obj, "visible_camera", True)),
        diffuse=bool(getattr(obj, "visible_diffuse", True)),
        glossy=bool(getattr(obj, "visible_glossy", True)),
        transmission=bool(getattr(obj, "visible_transmission", True)),
        shadow=bool(getattr(obj, "visible_shadow", True)))


def lamp_visibility(obj) -> int:
    """A lamp's mask: its object's ray visibility, with SHADOW from the light's Cast
    Shadow (`use_shadow`), as Cycles reads them."""
    mask = object_visibility(obj) | visibility.SHADOW
    if not getattr(obj.data, "use_shadow", True):
        mask &= ~visibility.SHADOW
    return mask


def export_light(obj, matrix_world, reporter: Reporter):
    light = obj.data
    m = to_numpy(matrix_world)
    strength = light_strength(light)
    direction = -m[:3, 2] / max(np.linalg.norm(m[:3, 2]), 1e-300)
    factor, why = emission_factor(light)          # its node tree (light_nodes.py)
    if factor is None:
        reporter.warn(f"DRT: light {obj.name!r}: {why}; its colour and power are used as "
                      "set on the light", key=(obj.name, "nodes"))
    else:
        strength = tuple(c * f for c, f in zip(strength, factor))
    vis = lamp_visibility(obj)
    if light.type in ("POINT", "SPOT"):
        radius = max(float(light.shadow_soft_size), 0.0)
        if not _normalize(light):
            strength = _scaled(strength, _point_area(radius))
        kwargs = dict(radius=radius, soft_falloff=bool(getattr(light, "use_soft_falloff", False)),
                      name=obj.name, visibility=vis)
        if light.type == "SPOT":
            sx, sy = np.linalg.norm(m[:3, 0]), np.linalg.norm(m[:3, 1])
            if abs(sx - sy) > 1e-4 * max(sx, sy):
                reporter.warn(f"DRT: spot light {obj.name!r} is scaled unevenly in X and Y; "
                              "Cycles then makes its cone elliptical, DRT keeps it round",
                              key=(obj.name, "spot scale"))
            kwargs.update(spot_size=float(light.spot_size), spot_blend=float(light.spot_blend),
                          direction=tuple(direction))
        return engine.PointLight(tuple(m[:3, 3]), strength, **kwargs)
    if light.type == "SUN":
        angle = float(light.angle)
        if not _normalize(light):
            strength = _scaled(strength, _sun_area(angle))
        return engine.SunLight(tuple(direction), strength, angle=angle, name=obj.name,
                               visibility=vis)
    if light.type == "AREA":
        sx = float(light.size)
        sy = float(light.size_y) if light.shape in ("RECTANGLE", "ELLIPSE") else sx
        scale = np.linalg.norm(m[:3, :2], axis=0)
        if not (sx * scale[0] > 0.0 and sy * scale[1] > 0.0
                and math.isfinite(sx * sy * scale[0] * scale[1])):
            reporter.warn(f"DRT: area light {obj.name!r} has zero size; it is skipped, as "
                          "Cycles does", key=(obj.name, "zero size"))
            return None
        return engine.AreaLight(m, strength, shape=light.shape, size_x=float(light.size),
                                size_y=float(light.size_y), normalize=_normalize(light),
                                spread=float(getattr(light, "spread", math.pi)),
                                visible_camera=bool(vis & visibility.CAMERA),
                                name=obj.name, visibility=vis)
    reporter.warn(f"DRT: light {obj.name!r} of type {light.type} is not supported; skipped")
    return None
