"""How many samples each pixel took in a Cycles render with adaptive sampling.

Cycles' Debug Sample Count pass holds each pixel's share of the samples the render took:
all of Samples, or fewer when every pixel converged before (the render then ends at that
check, and neither the file's "cycles.<layer>.samples" nor anything the bpy module prints
says where). The samples taken, N, follow from the shares: each pixel's count N x share
is a whole number on Cycles' schedule (the first check after (Min Samples + 1) | 15 + 1
samples, one every 16 after it, or Samples), and N itself is one of those checks. The
one N under Samples for which every pixel's count is so is the answer; if several are,
this says so rather than guess. The pass comes from a multilayer OpenEXR
(exr_channels), since Blender's Python API gives a render's pixels only through a file.
"""
from __future__ import annotations

import math
import os
import tempfile

import numpy as np

from exr_channels import read_channel

STEP = 16


def first_check(cycles) -> int:
    """Cycles' first adaptive filter: after (min + 1) | (STEP - 1) + 1 samples, with its
    automatic threshold and Min Samples (scene/integrator.cpp)."""
    threshold = cycles.adaptive_threshold or max(0.001, 1.0 / cycles.samples)
    least = cycles.adaptive_min_samples or math.ceil(16.0 / threshold ** 0.3)
    return ((max(4, least) + 1) | (STEP - 1)) + 1


def counts_from_shares(share: np.ndarray, first: int, samples: int) -> np.ndarray:
    """Each pixel's samples from its share of the N the render took (above)."""
    def fits(n):
        c = share * n
        whole = np.rint(c)
        return (np.abs(c - whole).max() < 1e-2 and whole.min() >= first
                and bool(np.all((whole == n) | ((whole - first) % STEP == 0))))
    ends = [n for n in list(range(first, samples, STEP)) + [samples] if fits(n)]
    if len(ends) != 1:
        raise ValueError(f"cannot tell how many samples Cycles took: {ends or 'none'} fit")
    return np.rint(share * ends[0]).astype(np.int64)


def cycles_sample_counts(bpy, scene) -> np.ndarray:
    """(h, w) samples per pixel of a Cycles render of `scene` as it is set up (adaptive
    sampling on), rendered here with the Debug Sample Count pass on."""
    layer = next(v for v in scene.view_layers if v.use)
    layer.cycles.pass_debug_sample_count = True
    settings = scene.render.image_settings
    try:
        bpy.ops.render.render(write_still=False)
        if hasattr(settings, "media_type"):               # Blender 5
            settings.media_type = "MULTI_LAYER_IMAGE"
        settings.file_format = "OPEN_EXR_MULTILAYER"
        settings.color_depth = "32"
        settings.exr_codec = "NONE"
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "counts.exr")
            bpy.data.images["Render Result"].save_render(filepath=path, scene=scene)
            share = read_channel(path, f"{layer.name}.Debug Sample Count.X")
    finally:
        layer.cycles.pass_debug_sample_count = False
    return counts_from_shares(share, first_check(scene.cycles), scene.cycles.samples)
