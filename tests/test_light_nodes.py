"""Blender's blackbody colour as DRT reads it (drt_addon/export/blackbody.py: a table read
from Blender, interpolated), against Blender's own value between the table's rows."""
import numpy as np
import pytest

from drt_addon.export.blackbody import blackbody_rgb


def test_blackbody_between_rows_is_blenders_own(bpy_drt):
    """Temperatures off the table's 25 K grid: within 0.1% of Light.temperature_color
    (Blender's blackbody, luminance 1); the ends clamp."""
    light = bpy_drt.data.lights.new("probe", "POINT")
    try:
        light.use_temperature = True
        for kelvin in (812.5, 1234.0, 2700.0, 3333.3, 5003.0, 6504.0, 9876.0, 11990.0):
            light.temperature = kelvin
            np.testing.assert_allclose(blackbody_rgb(kelvin), light.temperature_color[:3],
                                       rtol=1e-3, atol=1e-4)
        lum = np.dot(blackbody_rgb(4000.0), (0.2126, 0.7152, 0.0722))
        assert lum == pytest.approx(1.0, abs=1e-3)
        assert blackbody_rgb(100.0) == blackbody_rgb(800.0)
        assert blackbody_rgb(1e6) == blackbody_rgb(12000.0)
    finally:
        bpy_drt.data.lights.remove(light)
