"""Baking (Blender's bake operator with DRT as the render engine) against Cycles' bake of
the same scene: a floor plane with a textured-looking Principled material (a colour, some
gloss, a little emission) baked to a 32 x 32 float image, an orange cube standing on it,
a sun and a world. Pass types Combined, Diffuse (all, Direct only, and Color only),
Glossy, Emit, Normal (tangent space) and Ambient Occlusion, both engines at 64 samples.

Held to (measured: the printed lines, docs/bake.md): the image's mean within 0.02 of
Cycles' (relative to Cycles' mean) and its worst 8 x 8 block within 0.08; Glossy, a
faint pass here (mean 0.014), within 0.03 and 0.25; Emit, Normal and Diffuse Color,
which carry no light, within 0.002 and 0.01. The cube rests on the floor, as an artist
leaves it: DRT's rays, like Cycles', start on the floor and meet the cube's coplanar
bottom face (engine.embree.self_hits); until 2026-11-30 they passed it and the floor's
indirect light was 9 % below Cycles' (Diffuse mean -0.004; since: -0.0011)."""
import numpy as np
import pytest

SIZE = 32
SAMPLES = 64
CASES = {
    "combined": ("COMBINED", {}),
    "diffuse": ("DIFFUSE", {}),
    "diffuse direct": ("DIFFUSE", {"use_pass_indirect": False}),
    "diffuse color": ("DIFFUSE", {"use_pass_direct": False, "use_pass_indirect": False}),
    "glossy": ("GLOSSY", {}),
    "emit": ("EMIT", {}),
    "normal": ("NORMAL", {}),
    "ao": ("AO", {}),
}
QUIET = ("emit", "normal", "diffuse color")
LIMITS = {**{name: (0.002, 0.01) for name in QUIET}, "glossy": (0.03, 0.25)}


def _scene(bpy, lift=0.0):
    import math
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.cycles.samples = SAMPLES
    scene.cycles.seed = 1
    scene.drt.samples = SAMPLES
    scene.world = bpy.data.worlds.new("sky")
    scene.world.color = (0.2, 0.25, 0.3)
    if bpy.app.version < (5, 0, 0):
        scene.world.use_nodes = False
    bpy.ops.mesh.primitive_plane_add(size=4.0)
    floor = bpy.context.active_object
    mat = bpy.data.materials.new("floor")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.8, 0.5, 0.3, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.35
    bsdf.inputs["Emission Color"].default_value = (0.2, 0.4, 0.6, 1.0)
    bsdf.inputs["Emission Strength"].default_value = 0.25
    image = bpy.data.images.new("baked", SIZE, SIZE, alpha=True, float_buffer=True)
    node = mat.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    mat.node_tree.nodes.active = node
    floor.data.materials.append(mat)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.4, 0.3, 0.5 + lift))
    cube = bpy.context.active_object
    orange = bpy.data.materials.new("orange")
    if bpy.app.version < (5, 0, 0):
        orange.use_nodes = True
    orange.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (
        0.8, 0.35, 0.1, 1.0)
    cube.data.materials.append(orange)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(35), 0.0, math.radians(30))
    scene.collection.objects.link(sun)
    for obj in bpy.context.selected_objects:
        obj.select_set(False)
    floor.select_set(True)
    bpy.context.view_layer.objects.active = floor
    return image


def _bake(bpy, engine, kind, filters, lift=0.0):
    """The image (SIZE, SIZE, 4), row 0 at the bottom, that `engine` bakes."""
    image = _scene(bpy, lift)
    bpy.context.scene.render.engine = engine
    bake = bpy.context.scene.render.bake
    for key, value in filters.items():
        setattr(bake, key, value)
    bpy.ops.object.bake(type=kind, margin=0, use_clear=True)
    px = np.empty(SIZE * SIZE * 4, np.float32)
    image.pixels.foreach_get(px)
    return px.reshape(SIZE, SIZE, 4)


@pytest.fixture(scope="module")
def baked(bpy_drt):
    bpy = bpy_drt
    return {name: (_bake(bpy, "DRT", kind, f), _bake(bpy, "CYCLES", kind, f))
            for name, (kind, f) in CASES.items()}


def _blocks(img):
    return img.reshape(SIZE // 8, 8, SIZE // 8, 8, -1).mean(axis=(1, 3))


@pytest.mark.parametrize("name", list(CASES))
def test_bake_matches_cycles(baked, name):
    drt, cycles = baked[name]
    d, c = drt[..., :3].astype(float), cycles[..., :3].astype(float)
    scale = max(c.mean(), 1e-3)
    mean = (d.mean() - c.mean()) / scale
    block = np.abs(_blocks(d) - _blocks(c)).max() / scale
    print(f"{name}: DRT {d.mean():.4f}, Cycles {c.mean():.4f}, mean {mean:+.4f}, "
          f"worst block {block:.4f}")
    limits = LIMITS.get(name, (0.02, 0.08))
    assert abs(mean) < limits[0] and block < limits[1]
    # the whole plane is baked (its UVs fill the image): alpha 1 everywhere
    np.testing.assert_array_equal(drt[..., 3], 1.0)


def test_bake_refuses_what_it_cannot_bake(bpy_drt):
    bpy = bpy_drt
    _scene(bpy)
    bpy.context.scene.render.engine = "DRT"
    with pytest.raises(RuntimeError, match="DRT cannot bake"):
        bpy.ops.object.bake(type="ROUGHNESS")
