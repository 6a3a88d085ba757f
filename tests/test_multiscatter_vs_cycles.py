"""Multiscatter GGX against Cycles: five metal spheres (roughness 0.05, 0.2, 0.4, 0.6, 0.8;
copper-like base colour; Principled BSDF at Blender's default distribution, Multiscatter
GGX) on a grey Lambertian plane under a 4 m square area lamp, 64 x 48 pixels, built here
with bpy. Cycles renders 2048 samples per pixel, DRT 1024.

Checks (`compare`, in the style of tests/test_scenes_vs_cycles.py): the image means
agree within MEAN_TOLERANCE = 1 % per channel, and every 8 x 8 block mean within
BLOCK_TOLERANCE = 3 % of the image mean.

Light paths:
  * `test_metal_spheres_match_cycles_at_the_defaults`: everything at Blender's defaults
    (12 bounces, 4 diffuse, Filter Glossy 1, caustics, clamps). Measured: mean -0.07 %,
    worst block 1.05 %. This needs Filter Glossy to widen only the lobes, after the BSDF
    setup, as Cycles' closure blur does (its energy compensation and layering keep the
    material's roughness): widening the material's roughness before the setup, as DRT
    did at first, gave +0.97 % (red) and 3.3 %.
  * `test_metal_spheres_match_cycles_without_filter_glossy`: the same with Filter Glossy
    0 in both engines (scene.cycles.blur_glossy, which DRT reads). Measured: mean
    -0.1 %, worst block 1.1 %.
  * `test_metal_spheres_match_cycles`: direct light and the light one or two glossy
    bounces carry (two bounces in total, no diffuse bounce: the plane seen in the
    spheres, the spheres in each other), where Filter Glossy hardly acts: Cycles with
    Filter Glossy 0 differs from Cycles at 1 by 0.2 % (mean) and 1.3 % (worst block),
    which this test checks. Measured, DRT Multiscatter GGX: mean 0.04 %, worst block
    1.1 %. With DRT's previous single-scattering GGX (the same scene with the
    distribution set to GGX): mean -4.4 % (red; -1.9 % green, -1.4 % blue), worst block
    38 % (the rough spheres): it fails both checks
    (`test_single_scatter_fails_the_comparison`). Why not one bounce: at its last bounce
    DRT samples only the lamp, not the BSDF (a noisier estimator of the same value),
    which leaves the lamp's highlight in the smooth spheres seen in their neighbours
    about 6 % low in a block at these samples, for single and multiple scattering
    alike; with two bounces that path is not the last.

The Principled layering per distribution (`test_plastic_layering_matches_cycles`): a
plastic sphere (base colour 0.8, default specular) in a white world, the mean over the
sphere within PLASTIC_TOLERANCE = 0.5 % of Cycles' for GGX and Multiscatter GGX at
roughness 0.3, 0.7 and 1.0. Measured: within 0.06 % everywhere. Before, DRT gave the
diffuse what its single-scattering layer's actual albedo leaves, for both distributions
(0.8427, 0.8362, 0.8324 in docs/comparisons.md, known difference 6): +0.2 %, +1.4 %,
+2.3 % against Cycles' GGX, and -0.02 %, 0.0 %, -0.06 % against Cycles' Multiscatter
GGX (0.8429, 0.8362, 0.8329 here), which that energy-conserving layering happened to
match.
"""
import math

import numpy as np
import pytest

from conftest import render_current

MEAN_TOLERANCE = 0.01
PLASTIC_TOLERANCE = 0.005
BLOCK_TOLERANCE = 0.03
BLOCK = 8
CYCLES_SAMPLES = 2048
DRT_SAMPLES = 1024
ROUGHNESS = (0.05, 0.2, 0.4, 0.6, 0.8)
BASE_COLOR = (0.95, 0.64, 0.54, 1.0)
FEW_BOUNCES = dict(max_bounces=2, diffuse_bounces=0)
DEFAULT_BOUNCES = dict(max_bounces=12, diffuse_bounces=4)

_renders = {}


def build_scene(bpy, distribution="MULTI_GGX"):
    """The spheres, plane, lamp and camera in a fresh file; the metals' distribution."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = 64, 48
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("Black")
    if bpy.app.version < (5, 0, 0):
        scene.world.use_nodes = True
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, -6.5, 2.6)
    cam.rotation_euler = (math.radians(72.0), 0.0, 0.0)
    cam.data.lens = 40.0
    scene.collection.objects.link(cam)
    scene.camera = cam
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "AREA"))
    lamp.data.size = 4.0
    lamp.data.energy = 200.0          # radiance 200 / (pi 16) = 4: no sample reaches a clamp
    lamp.location = (0.5, -1.5, 4.0)
    scene.collection.objects.link(lamp)
    mesh = bpy.data.meshes.new("Plane")
    mesh.from_pydata([(-8, -8, 0), (8, -8, 0), (8, 8, 0), (-8, 8, 0)], [], [(0, 1, 2, 3)])
    plane = bpy.data.objects.new("Plane", mesh)
    scene.collection.objects.link(plane)
    grey = bpy.data.materials.new("Grey")
    if bpy.app.version < (5, 0, 0):
        grey.use_nodes = True
    p = grey.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    p.inputs["Specular IOR Level"].default_value = 0.0          # Lambertian
    mesh.materials.append(grey)
    for k, r in enumerate(ROUGHNESS):
        bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=0.5,
                                             location=(-2.2 + 1.1 * k, 0.0, 0.5))
        sphere = bpy.context.active_object
        bpy.ops.object.shade_smooth()
        mat = bpy.data.materials.new(f"Metal{r}")
        if bpy.app.version < (5, 0, 0):
            mat.use_nodes = True
        q = mat.node_tree.nodes["Principled BSDF"]
        q.inputs["Base Color"].default_value = BASE_COLOR
        q.inputs["Metallic"].default_value = 1.0
        q.inputs["Roughness"].default_value = r
        q.distribution = distribution
        sphere.data.materials.append(mat)
    return scene


def _render(bpy, engine, bounces, distribution="MULTI_GGX", blur_glossy=None):
    key = (engine, tuple(sorted(bounces.items())), distribution, blur_glossy)
    if key not in _renders:
        scene = build_scene(bpy, distribution)
        scene.render.engine = engine
        c, d = scene.cycles, scene.drt
        c.samples, d.samples = CYCLES_SAMPLES, DRT_SAMPLES
        c.use_denoising = False
        c.use_adaptive_sampling = False
        c.device = "CPU"
        for name, value in bounces.items():
            setattr(c, name, value)
            setattr(d, name, value)
        if blur_glossy is not None:
            c.blur_glossy = blur_glossy
        _renders[key] = render_current(bpy, scene)
    return _renders[key]


def compare(image, reference):
    """(relative difference of the means per channel (3,), largest |block mean
    difference| over the reference's image mean)."""
    m_img, m_ref = image.mean(axis=(0, 1)), reference.mean(axis=(0, 1))
    h, w, _ = reference.shape

    def blocks(img):
        return img.mean(axis=2).reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK).mean(axis=(1, 3))
    block = np.abs(blocks(image) - blocks(reference)).max() / reference.mean()
    return (m_img - m_ref) / m_ref, float(block)


def assert_matches(drt, cycles, mean_tolerance, block_tolerance):
    """A DRT render against Cycles': finite, and within the tolerances of `compare`
    (printed first)."""
    assert np.isfinite(drt).all() and cycles.mean() > 0.02
    rel, block = compare(drt, cycles)
    print(f"DRT vs Cycles: mean {np.round(100 * rel, 2)} %, worst block {100 * block:.2f} %")
    assert (np.abs(rel) <= mean_tolerance).all(), rel
    assert block <= block_tolerance, block


def within(image, reference):
    rel, block = compare(image, reference)
    return bool((np.abs(rel) <= MEAN_TOLERANCE).all() and block <= BLOCK_TOLERANCE)


def _report(label, image, reference):
    rel, block = compare(image, reference)
    print(f"{label}: mean difference {np.round(100 * rel, 2)} %, worst block "
          f"{100 * block:.2f} % of the image mean")


def test_metal_spheres_match_cycles(bpy_drt):
    cycles = _render(bpy_drt, "CYCLES", FEW_BOUNCES)
    drt = _render(bpy_drt, "DRT", FEW_BOUNCES)
    assert drt.shape == cycles.shape == (48, 64, 3) and np.isfinite(drt).all()
    assert cycles.mean() > 0.05 and cycles.std() > 0.3 * cycles.mean()   # lit, structured
    _report("Multiscatter GGX, DRT vs Cycles", drt, cycles)
    # the premise: Filter Glossy hardly acts on these paths
    no_blur = _render(bpy_drt, "CYCLES", FEW_BOUNCES, blur_glossy=0.0)
    _report("Cycles, Filter Glossy 0 vs 1", no_blur, cycles)
    rel, block = compare(no_blur, cycles)
    assert np.abs(rel).max() < 0.005 and block < 0.015
    rel, block = compare(drt, cycles)
    assert (np.abs(rel) <= MEAN_TOLERANCE).all(), rel
    assert block <= BLOCK_TOLERANCE, block


def test_single_scatter_fails_the_comparison(bpy_drt):
    """The negative control: DRT's previous model, single-scattering GGX, is too dark in
    the rough spheres for these checks."""
    cycles = _render(bpy_drt, "CYCLES", FEW_BOUNCES)
    single = _render(bpy_drt, "DRT", FEW_BOUNCES, distribution="GGX")
    _report("single-scatter GGX, DRT vs Cycles", single, cycles)
    rel, block = compare(single, cycles)
    assert not within(single, cycles)
    assert rel[0] < -MEAN_TOLERANCE and block > 3 * BLOCK_TOLERANCE


def test_metal_spheres_match_cycles_without_filter_glossy(bpy_drt):
    """Every light path at Cycles' defaults, with Filter Glossy off in both engines
    (scene.cycles.blur_glossy = 0, which DRT reads too)."""
    cycles = _render(bpy_drt, "CYCLES", DEFAULT_BOUNCES, blur_glossy=0.0)
    drt = _render(bpy_drt, "DRT", DEFAULT_BOUNCES, blur_glossy=0.0)
    _report("Multiscatter GGX, all bounces, Filter Glossy 0, DRT vs Cycles", drt, cycles)
    rel, block = compare(drt, cycles)
    assert (np.abs(rel) <= MEAN_TOLERANCE).all(), rel
    assert block <= BLOCK_TOLERANCE, block


def test_metal_spheres_match_cycles_at_the_defaults(bpy_drt):
    """Every light path at Blender's defaults, Filter Glossy 1 in both engines."""
    cycles = _render(bpy_drt, "CYCLES", DEFAULT_BOUNCES)
    drt = _render(bpy_drt, "DRT", DEFAULT_BOUNCES)
    _report("Multiscatter GGX, Blender's defaults, DRT vs Cycles", drt, cycles)
    rel, block = compare(drt, cycles)
    assert (np.abs(rel) <= MEAN_TOLERANCE).all(), rel
    assert block <= BLOCK_TOLERANCE, block


def build_plastic_sphere(bpy, roughness, distribution):
    """A smooth-shaded Principled sphere (base colour 0.8, default specular) filling a
    32 x 32 view in a uniform white world: nothing else to hit, so Filter Glossy never
    acts."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = 32
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("White")
    if bpy.app.version < (5, 0, 0):
        scene.world.use_nodes = True
    bg = scene.world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, -4.0, 0.0)
    cam.rotation_euler = (math.radians(90.0), 0.0, 0.0)
    cam.data.lens = 50.0
    scene.collection.objects.link(cam)
    scene.camera = cam
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0)
    bpy.ops.object.shade_smooth()
    mat = bpy.data.materials.new("Plastic")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    p = mat.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    p.inputs["Roughness"].default_value = roughness
    p.distribution = distribution
    bpy.context.active_object.data.materials.append(mat)
    return scene


def _plastic(bpy, engine, roughness, distribution):
    key = ("plastic", engine, roughness, distribution)
    if key not in _renders:
        scene = build_plastic_sphere(bpy, roughness, distribution)
        scene.render.engine = engine
        scene.cycles.samples, scene.drt.samples = 1024, 512
        scene.cycles.use_denoising = False
        scene.cycles.use_adaptive_sampling = False
        scene.cycles.device = "CPU"
        _renders[key] = render_current(bpy, scene)
    return _renders[key]


@pytest.mark.parametrize("distribution", ["GGX", "MULTI_GGX"])
def test_plastic_layering_matches_cycles(bpy_drt, distribution):
    for roughness in (0.3, 0.7, 1.0):
        cycles = _plastic(bpy_drt, "CYCLES", roughness, distribution)
        drt = _plastic(bpy_drt, "DRT", roughness, distribution)
        sphere = np.abs(cycles - 1.0).max(axis=2) > 1e-3        # not the white world
        assert sphere.sum() > 300
        md, mc = drt[sphere].mean(), cycles[sphere].mean()
        print(f"{distribution} plastic, roughness {roughness}: DRT {md:.4f}, Cycles {mc:.4f} "
              f"({100 * (md / mc - 1):+.2f} %)")
        assert abs(md / mc - 1.0) <= PLASTIC_TOLERANCE, (roughness, md, mc)
