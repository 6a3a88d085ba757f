"""Film > Transparent: alpha 0 where the camera sees the background, premultiplied colour,
the world still lighting the scene; against Cycles' alpha."""
import os

import numpy as np

from conftest import SAMPLES_DIR, read_render_rgba
from engine import Camera, Material, RenderSettings, Scene, World, render
from engine_scenes import look_at, quad


def _scene(transparent):
    plane = quad((0, 0, 0), (0.5, 0, 0), (0, 0.5, 0), "plane", 0)
    cam = Camera(look_at((0, -0.01, 3.0), (0, 0, 0), up=(0, 1, 0)), lens=50.0)
    return Scene(cam, 24, 24, [plane], [Material("m", (0.8, 0.8, 0.8), specular_ior_level=0.0)],
                 [], World((0.5, 0.6, 0.7)), film_transparent=transparent)


def test_background_is_transparent_and_still_lights_the_scene():
    settings = RenderSettings(samples=16, seed=4, filter_type="BOX", filter_width=1.0)
    opaque, _ = render(_scene(False), settings)
    clear, _ = render(_scene(True), settings)
    a = clear.mean_alpha()
    corner, centre = (slice(0, 3), slice(0, 3)), (slice(10, 14), slice(10, 14))
    assert (a[corner] == 0).all() and (clear.mean()[corner] == 0).all()
    assert (opaque.mean()[corner] > 0.4).all()               # the world, seen directly
    assert (a[centre] == 1).all()
    # The plane is lit by the world exactly as before (same samples, same paths).
    np.testing.assert_allclose(clear.mean()[centre], opaque.mean()[centre], rtol=1e-12)
    edge = (a > 0) & (a < 1)
    assert edge.any()                                         # anti-aliased coverage
    assert (opaque.mean_alpha() == 1).all()


def test_alpha_merges_exactly_across_sample_ranges():
    settings = RenderSettings(samples=8, seed=2)
    whole, _ = render(_scene(True), settings)
    a, _ = render(_scene(True), settings, sample_start=0, sample_end=5)
    b, _ = render(_scene(True), settings, sample_start=5, sample_end=8)
    np.testing.assert_allclose(a.merge(b).alpha_sum, whole.alpha_sum, rtol=1e-12)


def test_alpha_matches_cycles(bpy_drt):
    bpy = bpy_drt
    alphas = {}
    for engine in ("DRT", "CYCLES"):
        bpy.ops.wm.open_mainfile(filepath=os.path.join(SAMPLES_DIR, "world_light.blend"),
                                 load_ui=False)
        scene = bpy.context.scene
        scene.render.use_motion_blur = False
        scene.render.film_transparent = True
        scene.render.engine = engine
        scene.cycles.samples = 64
        scene.drt.samples = 64
        bpy.ops.render.render()
        alphas[engine] = read_render_rgba(bpy, scene)[:, 3]
    print("mean alpha DRT", alphas["DRT"].mean(), "Cycles", alphas["CYCLES"].mean())
    assert 0.05 < alphas["CYCLES"].mean() < 0.95           # the view has background
    assert abs(alphas["DRT"].mean() - alphas["CYCLES"].mean()) < 0.01
    assert np.abs(alphas["DRT"] - alphas["CYCLES"]).mean() < 0.05


def test_holdout_matches_cycles(bpy_drt):
    """The Cornell box's tall block as a holdout: a zero-alpha hole with no colour for the
    camera (film opaque), while it still shadows and reflects light for everything else;
    compared with Cycles' RGBA."""
    bpy = bpy_drt
    out = {}
    for engine in ("DRT", "CYCLES"):
        bpy.ops.wm.open_mainfile(filepath=os.path.join(SAMPLES_DIR, "cornell_box.blend"),
                                 load_ui=False)
        scene = bpy.context.scene
        bpy.data.objects["TallBlock"].is_holdout = True
        scene.render.engine = engine
        scene.render.resolution_percentage = 25
        scene.cycles.samples = 256
        scene.cycles.use_denoising = False
        scene.drt.samples = 64
        scene.cycles.diffuse_bounces = scene.cycles.diffuse_bounces = 0
        bpy.ops.render.render()
        out[engine] = read_render_rgba(bpy, scene)
    a_drt, a_cyc = out["DRT"][:, 3], out["CYCLES"][:, 3]
    hole = a_cyc < 0.01
    print("hole pixels", hole.sum(), "alpha MAD", np.abs(a_drt - a_cyc).mean())
    assert hole.sum() > 50                                   # the block is a hole in Cycles
    assert (a_drt[hole] < 0.05).mean() > 0.95                # ... and in DRT
    assert (out["DRT"][hole, :3] < 0.02).all()               # with no colour
    assert np.abs(a_drt - a_cyc).mean() < 0.02
    rgb_drt, rgb_cyc = out["DRT"][:, :3].mean(0), out["CYCLES"][:, :3].mean(0)
    assert np.all(np.abs(rgb_drt - rgb_cyc) / rgb_cyc < 0.05), (rgb_drt, rgb_cyc)


def _holdout_box(bpy, engine, shader):
    """The Cornell box, its tall block a hole: by a Holdout shader as its material
    (shader=True) or by its object's Holdout flag; Blender's default bounces."""
    bpy.ops.wm.open_mainfile(filepath=os.path.join(SAMPLES_DIR, "cornell_box.blend"),
                             load_ui=False)
    scene = bpy.context.scene
    block = bpy.data.objects["TallBlock"]
    if shader:
        mat = bpy.data.materials.new("Hole")
        if bpy.app.version < (5, 0, 0):
            mat.use_nodes = True
        nt = mat.node_tree
        for node in list(nt.nodes):
            if node.bl_idname != "ShaderNodeOutputMaterial":
                nt.nodes.remove(node)
        hole = nt.nodes.new("ShaderNodeHoldout")
        nt.links.new(hole.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
        block.data.materials.clear()
        block.data.materials.append(mat)
    else:
        block.is_holdout = True
    scene.render.engine = engine
    scene.render.resolution_percentage = 25
    scene.cycles.samples = 256
    scene.cycles.use_denoising = False
    scene.drt.samples = 128
    bpy.ops.render.render()
    return read_render_rgba(bpy, scene)


def test_holdout_shader_matches_cycles(bpy_drt):
    """A Holdout shader as the tall block's material: a zero-alpha hole with no colour for
    the camera, as the object flag makes one, but black to every other ray (it reflects
    no light onto the walls); Cycles' RGBA against DRT's. The control: the object flag's
    hole, whose block still lights the walls, is brighter than Cycles' Holdout shader."""
    bpy = bpy_drt
    drt, cycles = (_holdout_box(bpy, engine, True) for engine in ("DRT", "CYCLES"))
    a_drt, a_cyc = drt[:, 3], cycles[:, 3]
    hole = a_cyc < 0.01
    assert hole.sum() > 50 and (a_drt[hole] < 0.05).mean() > 0.95
    assert (drt[hole, :3] < 0.02).all()
    assert np.abs(a_drt - a_cyc).mean() < 0.02
    rgb_drt, rgb_cyc = drt[:, :3].mean(0), cycles[:, :3].mean(0)
    flagged = _holdout_box(bpy, "DRT", False)[:, :3].mean(0)
    print(f"Holdout shader: DRT {rgb_drt}, Cycles {rgb_cyc}; the object flag {flagged}")
    assert np.all(np.abs(rgb_drt - rgb_cyc) / rgb_cyc < 0.03), (rgb_drt, rgb_cyc)
    assert np.all(flagged / rgb_cyc - 1.0 > 0.03), (flagged, rgb_cyc)


def _environment(bpy, engine, strength=1.0):
    """The Environment pass of world_light.blend (an HDRI world, no lamps; the view shows
    background around the objects), and its Combined."""
    from drt_addon.blender_compat import ENVIRONMENT_PASS
    from test_passes import composite
    bpy.ops.wm.open_mainfile(filepath=os.path.join(SAMPLES_DIR, "world_light.blend"),
                             load_ui=False)
    scene = bpy.context.scene
    scene.render.use_motion_blur = False
    scene.render.resolution_percentage = 25
    scene.render.engine = engine
    scene.cycles.samples = scene.drt.samples = 32
    scene.cycles.use_denoising = False
    background = scene.world.node_tree.nodes["Background"].inputs["Strength"]
    background.default_value *= strength
    scene.view_layers[0].use_pass_environment = True
    composite(bpy, scene, ENVIRONMENT_PASS)
    bpy.ops.render.render()
    return read_render_rgba(bpy, scene)[:, :3]


def test_environment_pass_matches_cycles(bpy_drt):
    """Cycles' Environment pass against DRT's at 32 samples: the world where the camera
    sees it, 0 on the objects. Measured: DRT's image mean 0.7 % above Cycles', per pixel
    3 % of the mean (the edges' samples); the control, the world 10 % stronger, is
    10.8 % above."""
    bpy = bpy_drt
    cycles = _environment(bpy, "CYCLES")
    drt = _environment(bpy, "DRT")
    brighter = _environment(bpy, "DRT", 1.1)
    seen = (cycles.max(axis=1) > 0).mean()
    assert 0.05 < seen < 0.95                            # background and objects
    ratio = drt.mean() / cycles.mean()
    mad = np.abs(drt - cycles).mean() / cycles.mean()
    print(f"Environment: DRT/Cycles {ratio:.4f}, per pixel {mad:.4f} of the mean, "
          f"the world 10 % stronger {brighter.mean() / cycles.mean():.4f}")
    assert abs(ratio - 1.0) < 0.02 and mad < 0.05
    assert brighter.mean() / cycles.mean() > 1.06
