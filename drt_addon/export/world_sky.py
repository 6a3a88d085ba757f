"""A Sky Texture node behind the world's Background: the sky as an equirectangular
environment map and its sun disc as a distant light (`engine.sky_texture`).

Read from the node: Sky Type, Sun Disc, Sun Size, Sun Intensity, Sun Elevation, Sun
Rotation, Altitude, Air, Aerosol (Dust), Ozone; for Preetham, Sun Direction and
Turbidity. Everything is multiplied by the Background's Strength. The node's Vector (a
Mapping node on Generated / Object coordinates, as for an Environment Texture) turns
the map and the sun together; Blender 5.0 makes that socket unavailable on the physical
skies (Cycles does not read it there), so only a Preetham sky is turned.
Not modelled, and reported: Hosek / Wilkie (the Background's own colour is used), the
Single Scattering atmosphere (rendered with the Multiple Scattering one), and the node's
own texture mapping panel when it is not the identity.
"""
from __future__ import annotations

import numpy as np

from ..engine_link import engine

SUN_NAME = "World sun"


def _parameters(node):
    """engine.sky_texture.SkyParameters of the node's settings."""
    get = lambda name, default: getattr(node, name, default)  # noqa: E731
    return engine.sky_texture.SkyParameters(
        sky_type=node.sky_type, sun_disc=bool(get("sun_disc", True)),
        sun_size=float(get("sun_size", 0.009512)),
        sun_intensity=float(get("sun_intensity", 1.0)),
        sun_elevation=float(get("sun_elevation", np.radians(15.0))),
        sun_rotation=float(get("sun_rotation", 0.0)),
        altitude=float(get("altitude", 100.0)),
        air_density=float(get("air_density", 1.0)),
        aerosol_density=float(get("aerosol_density", get("dust_density", 1.0))),
        ozone_density=float(get("ozone_density", 1.0)),
        sun_direction=tuple(float(c) for c in get("sun_direction", (0.0, 0.0, 1.0))),
        turbidity=float(get("turbidity", 2.2)))


def _texture_mapping_is_identity(node):
    tm = getattr(node, "texture_mapping", None)
    if tm is None:
        return True
    return (tuple(tm.translation) == (0.0, 0.0, 0.0) and tuple(tm.rotation) == (0.0, 0.0, 0.0)
            and tuple(tm.scale) == (1.0, 1.0, 1.0) and not tm.use_min and not tm.use_max
            and (tm.mapping_x, tm.mapping_y, tm.mapping_z) == ("X", "Y", "Z"))


def sky_world(node, strength, vis, mapping, ctx):
    """engine.World of a Sky Texture node times `strength` (None: not modelled, the
    caller uses the Background's own colour). `mapping`: the node's Vector input as a
    3x3 matrix (None = identity)."""
    kind = node.sky_type
    if kind == "HOSEK_WILKIE":
        ctx.issue(f"{node.name!r} is a Hosek / Wilkie sky, which DRT does not model; "
                  f"using the Background's own colour")
        return None
    if kind == "SINGLE_SCATTERING":
        ctx.issue(f"{node.name!r} is a Single Scattering sky; DRT renders the Multiple "
                  f"Scattering atmosphere instead")
    if not _texture_mapping_is_identity(node):
        ctx.issue(f"{node.name!r} has its own texture mapping, which DRT ignores")
    params = _parameters(node)
    if kind == "SINGLE_SCATTERING":
        params = engine.sky_texture.SkyParameters(
            **{**params.__dict__, "sky_type": "MULTIPLE_SCATTERING"})
    try:
        texture, sun = engine.sky_texture.sky_world(params)
    except (ValueError, NotImplementedError) as exc:       # a sky type of a newer Blender
        ctx.issue(f"{node.name!r}: {exc}; using the Background's own colour")
        return None
    rgb = (float(strength),) * 3
    mean = tuple(float(c) * strength for c in texture.mean_rgba()[:3])
    world = engine.World(mean, texture=texture, strength=rgb, mapping=mapping,
                         visibility=vis)
    if sun is not None and strength != 0.0:
        world.sun = _sun_light(sun, strength, mapping, vis)
    return world


def _sun_light(sun, strength, mapping, vis):
    """The sun disc as an engine.SunLight: irradiance = mean radiance x pi sin^2(size/2)
    (engine.lights' sun convention), seen by the rays that see the world; it always
    casts shadows (Cycles ignores the world's Shadow box)."""
    to_sun, radiance, size = sun
    if mapping is not None:
        to_sun = np.linalg.solve(np.asarray(mapping, np.float64), to_sun)
        to_sun = to_sun / np.linalg.norm(to_sun)
    irradiance = radiance * (np.pi * np.sin(0.5 * size) ** 2) * strength
    return engine.SunLight(tuple(-to_sun), tuple(float(c) for c in irradiance), angle=size,
                           name=SUN_NAME, visibility=vis | engine.visibility.SHADOW)
