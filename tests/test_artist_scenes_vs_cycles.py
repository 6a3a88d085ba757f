"""Scenes made the way artists make them (sample_blends/artist_scenes.py), at Blender's
defaults, against Cycles: image means within 1 % per channel and every 8 x 8 block
within 3 % of the image mean (tests/test_multiscatter_vs_cycles.py's `compare`).

fog_room: a room of default Principled materials filled with fog (a volume-only cube),
lit through a window by an area lamp and a dim sky, the camera inside the fog. Measured:
mean +0.1 %, worst block 1.9 %. Without its fog the room agrees too (mean +0.07 % at
most, worst block 1.8 %, at the same 512 and 1024 samples; DRT at 256 against Cycles at
512 left blocks of 1.8 to 3.8 % over seeds 0-3, noise alone); before a lobe past its
bounce limit stopped counting in the sampled weight (tests/test_lobe_limits.py) that
room was 9 % brighter than Cycles'. The control, the room rendered without its fog
against Cycles with fog, fails.

product_shot: an HDRI-lit still life (a smooth subdivided Suzanne of red plastic with a
hammered Voronoi -> Bump finish on a bevelled metal pedestal with a Noise -> Bump
finish, a Noise -> Color Ramp backdrop, an Environment Texture world with a small,
very bright sun, a soft area key lamp). Measured (64 x 48, DRT 512 against Cycles 1024):
mean -0.06 %, block MAD 0.24 %, worst block 2.1 %. The worst block is the sun's glint in
the bumped rough metal of the pedestal's rim, which is noisy in both engines: against
Cycles at 4096 samples, at 512 samples and seeds 0-3, DRT's worst block is 1.6, 3.4, 2.8
and 3.9 % and Cycles' own 1.7, 1.8, 1.0 and 4.4 %, both in the glint. DRT's renders of
4096 samples in all (seeds 0-3 at 512 and seed 0 at 2048) are there 1.6 % darker than
Cycles' 4096 (mean -0.08 %, every other block within 0.7 %): about 2.4 standard
deviations of the two references' (heavy-tailed) noise there, so a bias of that size in
that one block is possible and not resolved. This scene's worst block is allowed 6 % and
its block MAD 1 %. The control, both Bump nodes left out (DRT 128), fails both: worst
block 9.6 %, block MAD 1.3 %."""
import os

import numpy as np

from conftest import render_blend
from test_multiscatter_vs_cycles import compare

SAMPLES_DIR = os.path.join(os.path.dirname(os.path.dirname(__file__)), "sample_blends")
CYCLES_SAMPLES = 1024
DRT_SAMPLES = 512
MEAN_TOLERANCE = 0.01
BLOCK_TOLERANCE = 0.03
PRODUCT_BLOCK_TOLERANCE = 0.06       # the noise of the pedestal's sun glint (above)
PRODUCT_BLOCK_MAD_TOLERANCE = 0.01

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


def _block_mad(drt, cycles, size=8):
    """Mean absolute difference of the size x size block means, over Cycles' mean."""
    h, w, _ = cycles.shape
    d = (drt - cycles).mean(axis=2).reshape(h // size, size, w // size, size).mean(axis=(1, 3))
    return float(np.abs(d).mean() / cycles.mean())


def _agrees(label, drt, cycles, block_tolerance=BLOCK_TOLERANCE, mad_tolerance=None):
    means, block = compare(drt, cycles)
    mad = _block_mad(drt, cycles)
    print(f"{label}: mean {np.round(means * 100, 2)} %, worst block {block:.2%}, "
          f"block MAD {mad:.2%}")
    return (bool(np.all(np.abs(means) < MEAN_TOLERANCE)) and block < block_tolerance
            and (mad_tolerance is None or mad < mad_tolerance))


def test_fog_room_matches_cycles(bpy_drt):
    cycles = _render(bpy_drt, "fog_room", "CYCLES", CYCLES_SAMPLES)
    assert _agrees("fog_room", _render(bpy_drt, "fog_room", "DRT", DRT_SAMPLES), cycles)
    # the control: the fog left out
    assert not _agrees("fog_room without fog (control)",
                       _render(bpy_drt, "fog_room", "DRT", 128, _no_fog), cycles)


def test_fog_room_without_fog_matches_cycles(bpy_drt):
    """Default materials under many diffuse bounces: the bounce limits' meaning."""
    assert _agrees("fog_room without fog",
                   _render(bpy_drt, "fog_room", "DRT", DRT_SAMPLES, _no_fog),
                   _render(bpy_drt, "fog_room", "CYCLES", CYCLES_SAMPLES, _no_fog))


def _no_bump(scene):
    """Every Bump node left out: the Principled BSDFs' Normal inputs unlinked."""
    import bpy
    for mat in bpy.data.materials:
        normal = mat.node_tree.nodes["Principled BSDF"].inputs["Normal"]
        for link in list(normal.links):
            mat.node_tree.links.remove(link)


def test_product_shot_matches_cycles(bpy_drt):
    def agrees(label, drt):
        return _agrees(label, drt, cycles, PRODUCT_BLOCK_TOLERANCE, PRODUCT_BLOCK_MAD_TOLERANCE)
    cycles = _render(bpy_drt, "product_shot", "CYCLES", CYCLES_SAMPLES)
    assert cycles.shape == (48, 64, 3) and cycles.std() > 0.3 * cycles.mean()
    assert agrees("product_shot", _render(bpy_drt, "product_shot", "DRT", DRT_SAMPLES))
    # the control: the bumps left out
    assert not agrees("product_shot without bumps (control)",
                      _render(bpy_drt, "product_shot", "DRT", 128, _no_bump))
