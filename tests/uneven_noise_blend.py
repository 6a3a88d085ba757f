"""The scene whose noise is uneven as a .blend, for both engines: tests/test_adaptive_
sampling.py's engine scene made from sample_blends/cornell_box.blend, the Cornell box seen
from further back in a grey world, so the world around the box is noise-free and the
box's indirect light is noisy (tests/test_adaptive_sampling_vs_cycles.py,
docs/adaptive_benchmark.py)."""
from __future__ import annotations

import os

CORNELL = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                       "sample_blends", "cornell_box.blend")


def open_uneven(bpy):
    """Open the Cornell box and step back into a grey world; the scene."""
    bpy.ops.wm.open_mainfile(filepath=CORNELL, load_ui=False)
    scene = bpy.context.scene
    scene.camera.location = (0.0, -6.5, 1.0)
    scene.camera.data.lens = 22.0
    background = next(n for n in scene.world.node_tree.nodes
                      if n.bl_idname == "ShaderNodeBackground")
    background.inputs["Color"].default_value = (0.4, 0.4, 0.4, 1.0)
    background.inputs["Strength"].default_value = 1.0
    return scene
