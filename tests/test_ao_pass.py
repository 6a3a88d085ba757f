"""The Ambient Occlusion pass (engine.ambient_occlusion): a closed form, bad input, and
Cycles' own AO pass.

Closed form: a floor under an infinite parallel ceiling at height h. A cosine-weighted
direction at angle theta from the floor's normal meets the ceiling at distance
h / cos(theta), so within AO distance D it escapes exactly when cos(theta) < h / D, which
a cosine-weighted direction does with probability (h / D)^2 (1 when D <= h). The image mean (32 x 24
pixels x 64 rays) is held to 0.003 of it; measured within 0.0003.

Against Cycles: a cube on a floor before a wall (occlusion in the corners and under the
cube's edges), AO distance 0.5 m, both at 64 samples: image means held to 0.005 and
every 8 x 8 block to 0.03 (measured: -0.0002 and 0.0076); the control, DRT with twice
the distance, is off by 0.21 in its worst block.
"""
import math

import numpy as np
import pytest

from engine import RenderContext, RenderSettings
from engine.ambient_occlusion import AmbientOcclusion
from engine.aov import first_hit_passes
from engine.scene import Camera, Material, Scene, World
from engine_scenes import look_at, quad
from figures import AGAINST_CYCLES, record

W, H = 32, 24


def _between_planes(h: float) -> Scene:
    """A 10 m floor at z = 0 under a 10 m ceiling at z = h (its front side down), the
    camera between them looking down at the floor: every AO ray (at most 1.2 m long)
    that leaves the floor's visible part below the ceiling's height meets the ceiling."""
    meshes = [quad((0, 0, 0), (5, 0, 0), (0, 5, 0), "floor"),
              quad((0, 0, h), (0, 5, 0), (5, 0, 0), "ceiling")]
    cam = Camera(look_at((0.0, -0.3 * h, 0.6 * h), (0.0, 0.0, 0.0)), lens=35.0)
    return Scene(cam, W, H, meshes, [Material("grey", (0.5, 0.5, 0.5))], [],
                 World((0.0, 0.0, 0.0)))


def _ao(scene: Scene, ao: AmbientOcclusion, samples: int = 64) -> np.ndarray:
    ctx = RenderContext(scene, RenderSettings(samples=samples, threads=1))
    return first_hit_passes(ctx, ao=ao).ambient_occlusion


@pytest.mark.parametrize("h, distance", [(0.5, 1.0), (0.3, 1.2), (1.0, 0.8)])
def test_floor_under_a_ceiling_sees_the_closed_form(h, distance):
    ao = _ao(_between_planes(h), AmbientOcclusion(distance=distance))
    expected = min(1.0, (h / distance) ** 2)
    assert ao.shape == (H, W, 3) and np.isfinite(ao).all()
    assert ao.min() >= 0.0 and ao.max() <= 1.0
    np.testing.assert_allclose(ao[..., 0], ao[..., 2])     # grey: RGB alike
    print(f"h {h}, distance {distance}: mean {ao.mean():.4f}, expected {expected:.4f}")
    assert abs(ao.mean() - expected) < 0.003


def test_no_distance_occludes_nothing_and_no_pass_costs_nothing():
    scene = _between_planes(0.5)
    assert _ao(scene, AmbientOcclusion(distance=0.0)) == pytest.approx(1.0)
    ctx = RenderContext(scene, RenderSettings(samples=4, threads=1))
    assert first_hit_passes(ctx).ambient_occlusion is None


def test_rays_per_pixel_follow_the_samples_up_to_the_cap():
    ao = AmbientOcclusion()
    assert ao.rays_per_sample(4, 4) == 1
    assert ao.rays_per_sample(1024, 16) == 4            # 64 rays a pixel
    assert ao.rays_per_sample(32, 16) == 2
    assert AmbientOcclusion(max_rays=256).rays_per_sample(1024, 16) == 16


@pytest.mark.parametrize("bad", [dict(distance=-1.0), dict(distance=math.inf),
                                 dict(distance=math.nan), dict(max_rays=0)])
def test_bad_settings_are_refused(bad):
    with pytest.raises(ValueError):
        AmbientOcclusion(**bad)


def _cube_scene(bpy, engine, distance):
    import math as m
    from conftest import grey_room
    from test_passes import composite
    from drt_addon.blender_compat import AO_PASS
    scene = grey_room(bpy, (48, 32), 0.6)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 1.2, 0.5))
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, -3.5, 2.2)
    cam.rotation_euler = (m.radians(65.0), 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.world.light_settings.distance = distance
    scene.view_layers[0].use_pass_ambient_occlusion = True
    scene.render.engine = engine
    scene.cycles.samples = scene.drt.samples = 64
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    composite(bpy, scene, AO_PASS)
    return scene


def _blocks(img, size=8):
    h, w = img.shape
    return img.reshape(h // size, size, w // size, size).mean(axis=(1, 3))


def test_ao_pass_matches_cycles(bpy_drt):
    from conftest import render_current
    bpy = bpy_drt
    out = {}
    for engine, distance in (("CYCLES", 0.5), ("DRT", 0.5), ("DRT", 1.0)):
        scene = _cube_scene(bpy, engine, distance)
        out[engine, distance] = render_current(bpy, scene).mean(axis=2)
    cycles = out["CYCLES", 0.5]
    assert cycles.max() > 0.9 and cycles.min() < 0.6       # open floor and dark corners
    diff = _blocks(out["DRT", 0.5] - cycles)
    control = _blocks(out["DRT", 1.0] - cycles)
    mean = out["DRT", 0.5].mean() - cycles.mean()
    print(f"AO vs Cycles: mean {mean:+.4f}, worst block {np.abs(diff).max():.4f}; "
          f"control (twice the distance): worst block {np.abs(control).max():.4f}")
    record(AGAINST_CYCLES + " (AO, of its full 1)", mean=abs(mean), block=np.abs(diff).max())
    record("control: twice the distance (AO, of its full 1)", block=np.abs(control).max())
    assert abs(mean) < 0.005 and np.abs(diff).max() < 0.03
    assert np.abs(control).max() > 0.1
