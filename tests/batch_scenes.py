"""Small animated .blend files for the batch renderer's tests, built from the Cornell box
at test time: 32 x 24 pixels, frames 1..3 with the short block sliding along x (so every
frame differs), 4 DRT samples, seed 5, output `//out/anim_####` as PNG."""
from __future__ import annotations

import os

from conftest import SAMPLES_DIR

CORNELL = os.path.join(SAMPLES_DIR, "cornell_box.blend")
FRAMES = (1, 2, 3)


def build_animated_cornell(bpy, path, video_output=False) -> str:
    """Save the small animated Cornell box to `path` (the session's open file changes)."""
    bpy.ops.wm.open_mainfile(filepath=CORNELL, load_ui=False)
    scene = bpy.context.scene
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = 32, 24, 100
    scene.frame_start, scene.frame_end, scene.frame_current = FRAMES[0], FRAMES[-1], 1
    scene.drt.samples, scene.cycles.seed = 4, 5
    block = bpy.data.objects["ShortBlock"]
    for frame, x in zip(FRAMES, (0.0, 0.3, 0.6)):
        block.location.x = x
        block.keyframe_insert("location", index=0, frame=frame)
    r.filepath = "//out/anim_####"
    settings = r.image_settings
    if video_output:
        settings.media_type = "VIDEO"
        settings.file_format = "FFMPEG"
    else:
        settings.file_format = "PNG"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    return str(path)
