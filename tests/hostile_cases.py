"""Hostile and broken input, each case tried the two ways a user meets it: in Blender
(the file opened and rendered with F12: Blender's error, or the RenderEngine's reports)
and with the batch renderer (`python -m drt_addon render`: its stderr lines and exit
code, run in this process through `batch.main`).

`run_cases` builds every case as a tiny .blend (8 x 8 pixels, 2 samples) in a folder and
returns one `Outcome` per case; tests/test_hostile_input.py checks them and
docs/make_robustness_hostile.py writes their messages into docs/robustness_hostile.md
(the test checks the page is what the script writes, so its messages are the real ones).
"""
from __future__ import annotations

import contextlib
import io
import math
import os
from dataclasses import dataclass, field

import numpy as np

from conftest import SAMPLES_DIR

CORNELL = os.path.join(SAMPLES_DIR, "cornell_box.blend")
SKY = (0.2, 0.3, 0.4)              # the lit world's colour (Background strength 1)
SIZE = 8


@dataclass
class Outcome:
    name: str                      # the input, as the catalogue names it
    result: str                    # what the user gets (checked by the tests)
    ui: str                        # the message in Blender ('' when there is none)
    batch: list                    # the batch renderer's "drt:" lines on stderr
    code: int                      # its exit code
    pixels: np.ndarray | None = None       # the DRT render (None: nothing rendered)
    warnings: list = field(default_factory=list)


# --------------------------------------------------------------------------- scenes
def _scene(bpy, camera=True, cube=True, sun=True, world=None):
    """A fresh file: a cube at the origin seen by a camera 4 m away, lit by a sun, 8 x 8
    pixels, 2 DRT samples; `world` None (black) or an RGB colour."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    r = scene.render
    r.resolution_x = r.resolution_y = SIZE
    r.resolution_percentage = 100
    scene.drt.samples = 2
    scene.cycles.use_denoising = False
    if cube:
        bpy.ops.mesh.primitive_cube_add(size=1.0)
        bpy.context.active_object.name = "Cube"
    if sun:
        lamp = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
        lamp.data.energy = 3.0
        lamp.rotation_euler = (0.5, 0.3, 0.0)
        scene.collection.objects.link(lamp)
    if camera:
        cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        cam.location = (0.0, -4.0, 0.0)
        cam.rotation_euler = (math.radians(90.0), 0.0, 0.0)      # looking along +y
        scene.collection.objects.link(cam)
        scene.camera = cam
    if world is not None:
        w = bpy.data.worlds.new("Sky")
        w.color = world
        if w.node_tree is not None:
            bg = w.node_tree.nodes.get("Background")
            bg.inputs["Color"].default_value = (*world, 1.0)
            bg.inputs["Strength"].default_value = 1.0
        scene.world = w
    return scene


def _cube_material(bpy):
    """The cube's material with an empty node tree but its Material Output: (tree, output)."""
    mat = bpy.data.materials.new("Broken")
    tree = mat.node_tree
    if tree is None:                                   # Blender 4.x
        mat.use_nodes = True
        tree = mat.node_tree
    for n in list(tree.nodes):
        tree.nodes.remove(n)
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    bpy.data.objects["Cube"].data.materials.append(mat)
    return tree, out


def _node_loop(bpy):
    """Output <- Mix A <- (Principled, Mix B), and Mix B <- Mix A: a loop of shaders."""
    _scene(bpy)
    tree, out = _cube_material(bpy)
    a, b = tree.nodes.new("ShaderNodeMixShader"), tree.nodes.new("ShaderNodeMixShader")
    a.name, b.name = "Mix A", "Mix B"
    bsdf = tree.nodes.new("ShaderNodeBsdfPrincipled")
    tree.links.new(a.outputs[0], out.inputs["Surface"])
    tree.links.new(bsdf.outputs[0], a.inputs[1])
    tree.links.new(b.outputs[0], a.inputs[2])
    tree.links.new(a.outputs[0], b.inputs[1])           # closes the loop
    tree.links.new(a.outputs[0], b.inputs[2])


def _dangling_reroute(bpy):
    """Principled's Base Color fed by a reroute with nothing linked into it."""
    _scene(bpy)
    tree, out = _cube_material(bpy)
    bsdf = tree.nodes.new("ShaderNodeBsdfPrincipled")
    reroute = tree.nodes.new("NodeReroute")
    reroute.name = "Loose"
    tree.links.new(bsdf.outputs[0], out.inputs["Surface"])
    tree.links.new(reroute.outputs[0], bsdf.inputs["Base Color"])


def _unlinked_surface(bpy):
    """A Principled BSDF beside the Material Output, not linked to it (the cube is seen
    against a lit world)."""
    _scene(bpy, world=SKY)
    _, out = _cube_material(bpy)
    out.id_data.nodes.new("ShaderNodeBsdfPrincipled")


def _nan_vertices(bpy):
    _scene(bpy)
    verts = bpy.data.objects["Cube"].data.vertices
    verts[0].co = (float("nan"), 0.0, 0.0)
    verts[1].co.z = float("inf")


def _empty_as_camera(bpy):
    scene = _scene(bpy, camera=False)
    empty = bpy.data.objects.new("Empty", None)
    scene.collection.objects.link(empty)
    scene.camera = empty                 # Blender allows any object as the camera


def _missing_image(bpy):
    """The cube's Base Color from an Image Texture whose file does not exist."""
    _scene(bpy)
    tree, out = _cube_material(bpy)
    bsdf = tree.nodes.new("ShaderNodeBsdfPrincipled")
    tex = tree.nodes.new("ShaderNodeTexImage")
    image = bpy.data.images.new("gone.png", 4, 4)       # load() refuses a missing file
    image.source, image.filepath = "FILE", "//textures/gone.png"
    tex.image = image
    tree.links.new(bsdf.outputs[0], out.inputs["Surface"])
    tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])


def _behind(bpy, world=SKY):
    scene = _scene(bpy, world=world)
    scene.camera.rotation_euler = (math.radians(90.0), 0.0, math.radians(180.0))  # along -y


def _missing_library(bpy, folder):
    """A cube linked from lib.blend (beside the scene's own), then lib.blend is deleted."""
    lib = os.path.join(folder, "lib.blend")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_cube_add(size=1.0)
    bpy.context.active_object.name = "LibCube"
    bpy.ops.wm.save_as_mainfile(filepath=lib)
    scene = _scene(bpy)
    with bpy.data.libraries.load(lib, link=True, relative=True) as (_, linked):
        linked.objects = ["LibCube"]
    for o in linked.objects:
        scene.collection.objects.link(o)
    return lib


# (name, file name, what the user gets, how the .blend is made: a function of bpy (and the folder)
# or a kind of file that is not a good .blend)
CASES = [
    ("missing file", "missing.blend", "no image", "missing"),
    ("a file that is not a .blend", "notes.blend", "no image", "text"),
    ("a truncated .blend", "truncated.blend", "no image", "truncated"),
    ("a scene with no camera", "no_camera.blend", "no image", lambda bpy: _scene(bpy, camera=False)),
    ("an Empty as the scene's camera", "empty_camera.blend", "no image", _empty_as_camera),
    ("an empty scene (a camera, nothing else)", "empty.blend", "a black image",
     lambda bpy: _scene(bpy, cube=False, sun=False)),
    ("a camera that looks away from everything", "away.blend", "the world's colour",
     _behind),
    ("a camera that looks away from everything, a black world", "away_black.blend",
     "a black image", lambda bpy: _behind(bpy, world=None)),
    ("objects but no light", "unlit.blend", "a black image",
     lambda bpy: _scene(bpy, sun=False)),
    ("NaN and infinite vertex coordinates", "nan.blend", "the mesh without the triangles that touch them",
     _nan_vertices),
    ("a material whose shader nodes are linked in a loop", "loop.blend", "the loop's red links are "
     "ignored, as in Cycles", _node_loop),
    ("a reroute with nothing linked into it", "reroute.blend", "the socket it feeds keeps its own value",
     _dangling_reroute),
    ("a material whose output has nothing linked to Surface", "no_surface.blend", "the object is black, as in "
     "Cycles", _unlinked_surface),
    ("an image texture whose file is missing", "image.blend", "the texture is pink, as in "
     "Cycles", _missing_image),
    ("a linked library that cannot be found", "linked.blend", "the scene without the missing data",
     "library"),
]


def _write_case(bpy, kind, path, folder):
    """Make the .blend of one case at `path`."""
    if kind == "missing":
        return
    if kind == "text":
        with open(path, "w") as f:
            f.write("this is not a .blend file\n")
        return
    if kind == "truncated":
        with open(CORNELL, "rb") as f:
            data = f.read()
        with open(path, "wb") as f:
            f.write(data[:len(data) // 2])
        return
    if kind == "library":
        lib = _missing_library(bpy, folder)
        bpy.ops.wm.save_as_mainfile(filepath=path)
        os.remove(lib)
        return
    kind(bpy)
    bpy.ops.wm.save_as_mainfile(filepath=path)


def _batch(path, out):
    """batch.main on `path`: (exit code, its stderr lines that start with "drt:")."""
    from drt_addon.batch import main
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["render", path, "-o", out, "--no-progress"])
    return code, [l for l in err.getvalue().splitlines() if l.startswith("drt:")]


def _in_blender(bpy, path):
    """Open `path` and render it as F12 does: (Blender's or DRT's message, pixels,
    warnings)."""
    from drt_addon.render_engine import last_render
    try:
        bpy.ops.wm.open_mainfile(filepath=path, load_ui=False)
    except RuntimeError as e:
        return str(e).strip().splitlines()[0].removeprefix("Error: "), None, []
    try:
        bpy.ops.render.render()
    except RuntimeError as e:            # Blender refuses before the engine runs
        return str(e).strip().splitlines()[0].removeprefix("Error: "), None, []
    warnings = [w for w in last_render["warnings"]]
    message = last_render["error"] or "; ".join(warnings)
    return message, last_render["pixels"], warnings


def run_cases(bpy, folder) -> list:
    """Every case of CASES, made in `folder`: a list of Outcome, with the folder's path
    left out of the messages."""
    outcomes = []
    for name, file, result, kind in CASES:
        path = os.path.join(folder, file)
        _write_case(bpy, kind, path, folder)
        code, lines = _batch(path, os.path.join(folder, "out.png"))
        ui, pixels, warnings = _in_blender(bpy, path)
        strip = lambda text: text.replace(os.path.join(folder, ""), "")     # noqa: E731
        outcomes.append(Outcome(name, result, strip(ui), [strip(l) for l in lines], code,
                                pixels, [strip(w) for w in warnings]))
    return outcomes


def markdown_table(outcomes) -> str:
    """The catalogue as a Markdown table."""
    def cell(text):
        return text.replace("|", "\\|") if text else "(none)"
    rows = ["| Input | Result | Message in Blender | Batch renderer (stderr) | Exit code |",
            "|---|---|---|---|---|"]
    for o in outcomes:
        rows.append(f"| {o.name} | {o.result} | {cell(o.ui)} | "
                    f"{cell('<br>'.join(o.batch))} | {o.code} |")
    return "\n".join(rows) + "\n"
