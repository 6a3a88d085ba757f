"""The Holdout shader mixed with others (a Mix Shader's Fac of Holdout), as Cycles renders
it: where it weighs H, the camera's alpha has a hole of H and the other shaders keep
their own weights; to every other ray it is no light (engine Material.holdout_weight,
drt_addon/export/closures.py).

- Closed form: a quad filling a narrow camera's view, emitting e, with a Holdout share
  h: the image is (1 - h) e and the alpha 1 - h.
- Against Cycles, with Film > Transparent: a sphere whose Mix Shader takes 35 % Holdout,
  a cube whose Fac is a checker texture (a per-hit mix of a Holdout and a Principled),
  over a grey floor and wall. Colour: means within 2 % per channel and 8 x 8 blocks
  within 5 % of the image mean; alpha: the same on the alpha channel. Measured (DRT 256
  samples, Cycles 512): colour -0.06 / -0.05 / -0.05 %, worst block 0.32 %; alpha
  +0.01 %, worst block 0.13 %. Before, a mixed Holdout rendered black with no hole
  (warned): alpha +12.2 %, worst block 57 %.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from engine import Camera, Material, RenderSettings, Scene, World, render
from engine_scenes import look_at, quad
from conftest import grey_room, read_render_rgba, use_engine
from test_multiscatter_vs_cycles import assert_matches, compare


@pytest.mark.parametrize("h", [0.25, 0.7])
def test_a_holdout_share_is_that_share_of_hole_and_the_rest_shaded(h):
    e = np.array([0.2, 1.0, 0.5])
    mat = Material("part holdout", (0.0, 0.0, 0.0), specular_ior_level=0.0,
                   emission=tuple(e), holdout_weight=h)
    cam = Camera(look_at((0, 0, 0), (0, 0, -1), up=(0, 1, 0)), lens=400.0)
    scene = Scene(cam, 4, 4, [quad((0, 0, -1), (0, 0.3, 0), (0.3, 0, 0), "q", 0)], [mat],
                  [], World((0.0, 0.0, 0.0)))
    film = render(scene, RenderSettings(samples=1024))[0]
    colour, alpha = film.mean().reshape(-1, 3).mean(0), film.mean_alpha().mean()
    print(f"h {h}: colour {colour.round(4)} (want {((1 - h) * e).round(4)}), alpha "
          f"{alpha:.4f} (want {1 - h})")
    np.testing.assert_allclose(colour, (1 - h) * e, rtol=0.01)
    assert abs(alpha - (1 - h)) < 0.01


def _holdout_mix(bpy, name, fac=None):
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.8, 0.15, 0.1, 1.0)
    mix = nt.nodes.new("ShaderNodeMixShader")
    hold = nt.nodes.new("ShaderNodeHoldout")
    nt.links.new(bsdf.outputs["BSDF"], mix.inputs[1])
    nt.links.new(hold.outputs["Holdout"], mix.inputs[2])
    if fac is None:
        checker = nt.nodes.new("ShaderNodeTexChecker")
        checker.inputs["Scale"].default_value = 3.0
        checker.inputs["Color1"].default_value = (0.9, 0.9, 0.9, 1.0)
        checker.inputs["Color2"].default_value = (0.1, 0.1, 0.1, 1.0)
        nt.links.new(checker.outputs["Fac"], mix.inputs["Fac"])
    else:
        mix.inputs["Fac"].default_value = fac
    nt.links.new(mix.outputs["Shader"], nt.nodes["Material Output"].inputs["Surface"])
    return mat


def _render(bpy, engine, samples):
    scene = grey_room(bpy, (48, 32), 0.5, world=0.3)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(-0.7, 0.0, 0.6),
                                         segments=48, ring_count=24)
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(_holdout_mix(bpy, "sphere", 0.35))
    bpy.ops.mesh.primitive_cube_add(size=0.9, location=(0.8, 0.0, 0.45),
                                    rotation=(0.0, 0.0, math.radians(25)))
    bpy.context.object.data.materials.append(_holdout_mix(bpy, "cube"))
    bpy.ops.object.light_add(type="AREA", location=(0.5, -1.5, 3.0))
    bpy.context.object.data.energy = 300.0
    bpy.context.object.data.size = 1.5
    bpy.ops.object.camera_add(location=(0.0, -5.0, 1.6), rotation=(math.radians(80), 0, 0))
    scene.camera = bpy.context.object
    scene.render.film_transparent = True
    use_engine(scene, engine, samples)
    bpy.ops.render.render()
    h, w = scene.render.resolution_y, scene.render.resolution_x
    return read_render_rgba(bpy, scene).reshape(h, w, 4)[::-1]


def test_mixed_holdouts_match_cycles(bpy_drt):
    cycles = _render(bpy_drt, "CYCLES", 512)
    drt = _render(bpy_drt, "DRT", 256)
    from drt_addon import render_engine
    assert render_engine.last_render["ok"], render_engine.last_render["error"]
    assert not any("Holdout" in w for w in render_engine.last_render.get("warnings", []))
    assert_matches(drt[..., :3], cycles[..., :3], 0.02, 0.05)
    a_drt, a_cyc = (np.repeat(x[..., 3:], 3, axis=2) for x in (drt, cycles))
    rel, block = compare(a_drt, a_cyc)
    print(f"alpha: mean {100 * rel[0]:.2f} %, worst block {100 * block:.2f} %; holes: "
          f"{(a_cyc[..., 0] < 0.99).mean():.2f} of the pixels in Cycles")
    assert (a_cyc[..., 0] < 0.99).mean() > 0.1       # the holdouts make holes
    assert abs(rel[0]) <= 0.02 and block <= 0.05
