"""Ray Visibility (engine.visibility) on engine-built scenes, flag by flag, each against a
second render that shows what the flag must give:

- an object nobody sees renders as if it were not there;
- an object hidden from the camera still casts its shadow; one without SHADOW is seen
  but casts none; one hidden from glossy rays is missing from a mirror only;
- a lamp hidden from the camera is not in the image but lights the scene; one hidden from
  diffuse rays lights a mirror-like metal but not a diffuse floor; one casting no shadow
  lights through an occluder.

Direct light only (diffuse_bounces 0) where the reference needs it, 32 x 24 pixels.
The Blender side (export, and the comparison with Cycles at its defaults) is in
tests/test_scenes_vs_cycles.py (scene `ray_visibility`) and test_export.py.
"""
import numpy as np

from engine import RenderSettings, render, visibility as V
from engine.kernels import path_vertex
from engine.scene import Camera, Material, PointLight, Scene, World
from engine_scenes import box, look_at, quad

W, H = 32, 24
ALL = V.ALL


def _scene(blocker_vis=ALL, lamp_vis=ALL, floor_material=0, lamp_radius=0.15,
           blocker=True, lamp_in_view=False, world=0.0):
    mats = [Material("grey", (0.6, 0.6, 0.6), specular_ior_level=0.0),
            Material("red", (0.8, 0.1, 0.1), specular_ior_level=0.0),
            Material("mirror", (0.9, 0.9, 0.9), metallic=1.0, roughness=0.0)]
    meshes = [quad((0, 0, 0), (3, 0, 0), (0, 3, 0), name="floor", material=floor_material)]
    if blocker:
        b = box((-0.4, -0.4, 0.6), (0.4, 0.4, 1.0), name="blocker", material=1)
        b.visibility = blocker_vis
        meshes.append(b)
    # a lamp behind the blocker casts its shadow towards the camera, below the blocker's
    # image: no pixel sees both the blocker's edge and its shadow
    lamp_pos = (0.0, -1.2, 0.9) if lamp_in_view else (0.0, 3.0, 2.5)
    power = 150.0 if lamp_in_view else 1000.0
    lamp = PointLight(lamp_pos, (power, power, power), radius=lamp_radius, name="lamp",
                      visibility=lamp_vis)
    cam = Camera(look_at((0.0, -4.0, 2.5), (0.0, 0.0, 0.4)), lens=30.0)
    return Scene(cam, W, H, meshes, mats, [lamp], World((world, world, world)))


def _render(scene, spp=64, bounces=0, seed=3):
    film, _ = render(scene, RenderSettings(samples=spp, diffuse_bounces=bounces,
                                           glossy_bounces=2, max_bounces=4, seed=seed))
    return film.mean()


def test_kernel_bits_are_the_engine_bits():
    assert (path_vertex.DIFFUSE_BIT, path_vertex.GLOSSY_BIT, path_vertex.TRANSMISSION_BIT,
            path_vertex.SHADOW_BIT) == (V.DIFFUSE, V.GLOSSY, V.TRANSMISSION, V.SHADOW)
    assert V.from_flags(camera=False, shadow=False) == V.DIFFUSE | V.GLOSSY | V.TRANSMISSION


def test_an_object_no_ray_sees_is_not_there():
    hidden = _render(_scene(blocker_vis=0), bounces=2)
    absent = _render(_scene(blocker=False), bounces=2)
    present = _render(_scene(), bounces=2)
    # the same paths (no sampler number is spent passing the hidden object), up to the
    # float32 rounding of rays continued from behind it
    np.testing.assert_allclose(hidden, absent, rtol=1e-4, atol=1e-7)
    assert np.abs(present - absent).max() > 0.1        # the blocker shows otherwise


def _masks(shown, no_shadow, absent):
    """(pixels seeing the blocker, pixels of its shadow on the floor), direct light only:
    without its shadow the floor is lit as if the blocker were absent, so the pixels
    that still differ from `absent` see the blocker itself."""
    blocker = np.abs(no_shadow - absent).max(-1) > 1e-5
    shadow = ~blocker & (absent.mean(-1) - shown.mean(-1) > 0.05)
    return blocker, shadow


def test_camera_hidden_object_keeps_its_shadow_and_shadowless_object_casts_none():
    shown = _render(_scene())
    no_camera = _render(_scene(blocker_vis=ALL & ~V.CAMERA))
    no_shadow = _render(_scene(blocker_vis=ALL & ~V.SHADOW))
    absent = _render(_scene(blocker=False))
    blocker, shadow = _masks(shown, no_shadow, absent)
    assert blocker.sum() > 10 and shadow.sum() > 10
    # no shadow: the blocker is seen as before, the floor is lit as if it were absent
    np.testing.assert_allclose(no_shadow[blocker], shown[blocker], rtol=1e-4, atol=1e-7)
    np.testing.assert_allclose(no_shadow[~blocker], absent[~blocker], rtol=1e-4, atol=1e-7)
    # hidden from the camera: the floor behind it shows (no red), and the shadow stays
    assert not ((no_camera[..., 0] - no_camera[..., 1]) > 0.05).any()
    assert ((shown[blocker][:, 0] - shown[blocker][:, 1]) > 0.05).any()
    np.testing.assert_allclose(no_camera[~blocker], shown[~blocker], atol=1e-9)


def _red(img):
    return (img[..., 0] - img[..., 1]) > 0.05


def test_glossy_hidden_object_is_missing_from_a_mirror_only():
    def mirror(vis):          # a grey world lights the blocker's faces the mirror shows
        return _render(_scene(floor_material=2, blocker_vis=vis, world=0.5))

    shown, no_camera = mirror(ALL), mirror(ALL & ~V.CAMERA)
    no_glossy, neither = mirror(ALL & ~V.GLOSSY), mirror(ALL & ~V.GLOSSY & ~V.CAMERA)
    reflection = _red(no_camera)                    # the mirror image alone
    assert reflection.sum() > 5, "the mirror shows no reflection of the blocker"
    assert (_red(shown) & ~_red(no_glossy)).sum() >= reflection.sum() // 2
    assert not (_red(no_glossy) & ~_red(shown)).any()
    assert not _red(neither).any()


def test_lamp_hidden_from_the_camera_still_lights():
    shown = _render(_scene(lamp_in_view=True, blocker=False))
    hidden = _render(_scene(lamp_in_view=True, blocker=False, lamp_vis=ALL & ~V.CAMERA))
    lamp = np.abs(shown - hidden).max(-1) > 1e-6    # the pixels that saw the lamp
    assert shown.max() > 20.0 and 1 <= lamp.sum() <= 30
    assert hidden.max() < 5.0                       # the lamp's radiance is ~170
    lit = ~lamp & (hidden.mean(-1) > 0.05)
    assert lit.sum() > 100                          # while it lights the floor


def test_diffuse_hidden_lamp_lights_only_glossy_surfaces():
    diffuse_floor = _render(_scene(blocker=False, lamp_vis=ALL & ~V.DIFFUSE))
    assert diffuse_floor.max() == 0.0
    rough_metal = Material("metal", (0.9, 0.9, 0.9), metallic=1.0, roughness=0.4)
    scene = _scene(blocker=False, lamp_vis=ALL & ~V.DIFFUSE)
    scene.materials[2] = rough_metal
    scene.meshes[0].material_indices[:] = 2
    lit = _render(scene)
    scene.lights[0].visibility = ALL
    full = _render(scene)
    assert lit.mean() > 0.01
    # a metal has no diffuse lobe: the lamp's diffuse flag changes nothing on it
    np.testing.assert_allclose(lit, full, rtol=1e-9, atol=1e-12)


def test_lamp_casting_no_shadow_lights_through_an_occluder():
    occluded = _render(_scene())
    through = _render(_scene(lamp_vis=ALL & ~V.SHADOW))
    absent = _render(_scene(blocker=False))
    no_shadow = _render(_scene(blocker_vis=ALL & ~V.SHADOW))
    blocker, shadow = _masks(occluded, no_shadow, absent)
    assert shadow.sum() > 10
    np.testing.assert_allclose(through[~blocker], absent[~blocker], rtol=1e-4, atol=1e-7)
