"""Many lights against Cycles: sample_blends/night_street.blend (light_tree_scenes.py), a
street at night with 48 street lamps, 12 small shop-sign lamps, 36 lit windows and a
night sky, at Blender's defaults (Light Tree on), DRT 512 against Cycles 1024 samples at
64 x 48: image means within 1 % per channel and every 8 x 8 block within 3 % of the
image mean, as the artist scenes (tests/test_artist_scenes_vs_cycles.py).

Measured against Cycles at 4096 samples: means -0.14, -0.09, -0.09 %, worst block
1.3 %, block MAD 0.29 %. The control leaves out the 12 sign lamps (2 to 6 W among lamps
of 40 to 120 W: the small lights a pick by power neglects) and fails: worst block 10 %.
"""
import os

from conftest import render_blend
from test_artist_scenes_vs_cycles import _agrees

PATH = os.path.join(os.path.dirname(os.path.dirname(__file__)), "sample_blends",
                    "night_street.blend")


def _no_signs(scene):
    import bpy
    for obj in list(bpy.data.objects):
        if obj.name.startswith("Sign"):
            bpy.data.objects.remove(obj)


def test_night_street_matches_cycles(bpy_drt):
    cycles = render_blend(bpy_drt, PATH, "CYCLES", 1024, percentage=100)
    drt = render_blend(bpy_drt, PATH, "DRT", 512, percentage=100)
    assert bpy_drt.context.scene.cycles.use_light_tree       # the file's, Cycles' default
    assert _agrees("night_street", drt, cycles, mad_tolerance=0.01)
    control = render_blend(bpy_drt, PATH, "DRT", 128, percentage=100, setup=_no_signs)
    assert not _agrees("night_street without its sign lamps (control)", control, cycles)
