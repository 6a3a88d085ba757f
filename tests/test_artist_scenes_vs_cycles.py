"""Scenes made the way artists make them (sample_blends/artist_scenes.py), at Blender's
defaults, against Cycles: image means within 1 % per channel and every 8 x 8 block
within 3 % of the image mean (tests/test_multiscatter_vs_cycles.py's `compare`).

fog_room: a room of default Principled materials filled with fog (a volume-only cube),
lit through a window by an area lamp and a dim sky, the camera inside the fog.
Measured: mean +0.1 %, worst block 1.9 %. Without its fog the room agrees too (mean
-0.1 %); before a lobe past its bounce limit stopped counting in the sampled weight
(tests/test_lobe_limits.py) that room was 9 % brighter than Cycles'. The control, the
room rendered without its fog against Cycles with fog, fails."""
import os

import numpy as np

from conftest import render_blend
from test_multiscatter_vs_cycles import compare

SAMPLES_DIR = os.path.join(os.path.dirname(os.path.dirname(__file__)), "sample_blends")
CYCLES_SAMPLES = 1024
DRT_SAMPLES = 512
MEAN_TOLERANCE = 0.01
BLOCK_TOLERANCE = 0.03

_renders = {}


def _no_fog(scene):
    import bpy
    bpy.data.objects.remove(bpy.data.objects["Fog"])


def _render(bpy, name, engine, samples, setup=None):
    key = (name, engine, samples, setup)
    if key not in _renders:
        _renders[key] = render_blend(bpy, os.path.join(SAMPLES_DIR, f"{name}.blend"),
                                     engine, samples, percentage=100, setup=setup)
    return _renders[key]


def _agrees(label, drt, cycles):
    means, block = compare(drt, cycles)
    print(f"{label}: mean {np.round(means * 100, 2)} %, worst block {block:.2%}")
    return bool(np.all(np.abs(means) < MEAN_TOLERANCE)) and block < BLOCK_TOLERANCE


def test_fog_room_matches_cycles(bpy_drt):
    cycles = _render(bpy_drt, "fog_room", "CYCLES", CYCLES_SAMPLES)
    assert _agrees("fog_room", _render(bpy_drt, "fog_room", "DRT", DRT_SAMPLES), cycles)
    # the control: the fog left out
    assert not _agrees("fog_room without fog (control)",
                       _render(bpy_drt, "fog_room", "DRT", 128, _no_fog), cycles)


def test_fog_room_without_fog_matches_cycles(bpy_drt):
    """Default materials under many diffuse bounces: the bounce limits' meaning."""
    assert _agrees("fog_room without fog",
                   _render(bpy_drt, "fog_room", "DRT", 256, _no_fog),
                   _render(bpy_drt, "fog_room", "CYCLES", 512, _no_fog))
