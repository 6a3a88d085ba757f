"""Blender's blackbody colour: the RGB of a black body at a temperature in Kelvin, in
Blender's scene linear space, scaled to luminance 1 (what a light's Temperature and the
Blackbody node give).

Blender computes it from Planck's law and the CIE colour matching functions in its colour
management (`Light.temperature_color` shows it), which Python cannot call for an arbitrary
temperature during a render. `TABLE` holds it every 25 K from 800 K to 12000 K, read from
Blender itself by `python -m drt_addon.export.blackbody` (which rewrites
data/blackbody.npz); between rows it is interpolated linearly (within 0.1% of Blender's
own values, tests/test_light_nodes.py), outside them clamped to the end rows.
"""
from __future__ import annotations

import os

import numpy as np

PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "blackbody.npz")
LOW, HIGH, STEP = 800.0, 12000.0, 25.0

_table = None


def table() -> tuple[np.ndarray, np.ndarray]:
    """(temperatures (n,), RGB (n, 3))."""
    global _table
    if _table is None:
        with np.load(PATH) as f:
            _table = (f["kelvin"], f["rgb"])
    return _table


def blackbody_rgb(kelvin: float) -> tuple:
    """Blender's blackbody colour at `kelvin` (luminance 1)."""
    t, rgb = table()
    k = float(np.clip(kelvin, t[0], t[-1])) if np.isfinite(kelvin) else t[0]
    return tuple(float(np.interp(k, t, rgb[:, c])) for c in range(3))


def _read_from_blender() -> tuple[np.ndarray, np.ndarray]:
    import bpy
    light = bpy.data.lights.new("drt blackbody probe", "POINT")
    try:
        light.use_temperature = True
        kelvin = np.arange(LOW, HIGH + STEP / 2, STEP)
        rgb = np.empty((len(kelvin), 3))
        for i, k in enumerate(kelvin):
            light.temperature = float(k)
            rgb[i] = light.temperature_color[:3]
        return kelvin, rgb
    finally:
        bpy.data.lights.remove(light)


if __name__ == "__main__":
    kelvin, rgb = _read_from_blender()
    os.makedirs(os.path.dirname(PATH), exist_ok=True)
    np.savez_compressed(PATH, kelvin=kelvin, rgb=rgb)
    print(f"wrote {PATH}: {len(kelvin)} temperatures, {kelvin[0]:.0f} K to {kelvin[-1]:.0f} K")
