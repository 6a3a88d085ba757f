"""Cycles' light distribution, used when the light tree is off (Render Properties >
Sampling > Lights > Light Tree; Cycles' scene/light.cpp device_update_distribution):
the probability with which next-event estimation picks each entry of a
`engine.lights.LightSet`.

Cycles weighs every emissive triangle by its area, and every light (a lamp, or the world
when it is sampled) alike: each light weighs the triangles' total area over the number of
lights, 1 when there are no triangles. With both, the triangles share one half of the
picks by area and the lights the other half evenly; a lamp's power does not enter (a 1 mW
lamp is picked as often as a 1 kW one).

A Sky Texture's sun disc is part of the world's light in Cycles (background sampling
sends sun_weight 4 of 5 of the world's samples to the sun, map_weight 1 to the map:
light.cpp device_update_background); DRT renders it as a lamp of its own and gives it
those 4/5 of the world's share.

These probabilities decide more than noise where the two estimators that multiple
importance sampling combines do not estimate the same light. On a bent shading normal
(a Normal Map's, or a Displacement and Bump material's undisplaced one) Cycles' lobes
take light from under the geometric surface when it is sampled from a light, and refuse
those directions when the BSDF samples them (kernel/closure/bsdf.h): the image then
depends on the MIS weights, and so on these picks.
"""
from __future__ import annotations

import numpy as np

# Cycles' weights of the world's own sampling strategies (light.cpp
# device_update_background): its map, and a Sky Texture's sun
MAP_WEIGHT = 1.0
SUN_WEIGHT = 4.0


def cycles_distribution(n_lamps: int, world: int | None, world_sun: int | None,
                        triangle_area) -> np.ndarray:
    """Pick probabilities over n_lamps lamp entries followed by the emissive triangles of
    `triangle_area` (world-space areas): `world`, `world_sun`: the entries of the world
    and of its Sky Texture sun among the lamps (None: not sampled, or none)."""
    area = np.asarray(triangle_area, dtype=np.float64).reshape(-1)
    area = np.where(np.isfinite(area) & (area > 0.0), area, 0.0)
    joint = world is not None and world_sun is not None
    n_lights = n_lamps - 1 if joint else n_lamps       # Cycles' lights
    tri_total = float(area.sum())
    if n_lights > 0:
        light_area = tri_total / n_lights if tri_total > 0.0 else 1.0
    else:
        light_area = 0.0
    weight = np.concatenate([np.full(n_lamps, light_area), area])
    if joint:
        split = MAP_WEIGHT + SUN_WEIGHT
        weight[world] = light_area * MAP_WEIGHT / split
        weight[world_sun] = light_area * SUN_WEIGHT / split
    total = weight.sum()
    return weight / total if total > 0.0 else weight
