"""One image per effect of distribution ray tracing, rendered by DRT's tracer directly
(no Blender needed), with the settings and the measured cost written beside each.

    .venv/bin/python docs/effects.py [NAME ...]

Images go to docs/images/effect_*.png (display: sRGB transfer of the linear radiance,
clipped at 1), their captions and timings to docs/effects.md.
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests")]

from PIL import Image  # noqa: E402

from engine import (AreaLight, Camera, Material, PointLight, RenderSettings, Scene,  # noqa: E402
                    SunLight, World, render)
from engine.motion import RigidMotion, Shutter  # noqa: E402
from engine_scenes import box, cornell_box, look_at, quad, uv_sphere  # noqa: E402

IMAGES = os.path.join(ROOT, "docs", "images")


def to_srgb(img):
    x = np.clip(img, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def run(scene, **settings):
    t0 = time.perf_counter()
    film, stats = render(scene, RenderSettings(**settings))
    return film.mean(), time.perf_counter() - t0, stats


def save(name, panels):
    row = np.concatenate([to_srgb(p) for p in panels], axis=1)
    Image.fromarray((row * 255 + 0.5).astype(np.uint8)).save(os.path.join(IMAGES, name))


def stage(materials, extra_meshes, lights, camera, size=(160, 120)):
    """A grey floor and back wall with whatever is added."""
    meshes = [quad((0, 0, 0), (3, 0, 0), (0, 3, 0), "floor", 0),
              quad((0, 2.0, 1.5), (0, 0, 1.5), (3, 0, 0), "back", 0)] + extra_meshes
    mats = [Material("grey", (0.6, 0.6, 0.6), specular_ior_level=0.0)] + materials
    return Scene(camera, size[0], size[1], meshes, mats, lights, World((0.02, 0.02, 0.03)))


def default_camera(**kw):
    return Camera(look_at((0, -4.0, 1.6), (0, 0.3, 0.5)), lens=40.0, **kw)


def effect_antialiasing(lines):
    """Thin slanted bars: one centred sample per pixel (aliasing) against 64 jittered
    samples through the Blackman-Harris filter."""
    mats = [Material("black", (0, 0, 0), specular_ior_level=0.0),
            Material("glow", (0, 0, 0), specular_ior_level=0.0, emission=(1, 1, 1))]
    meshes = []
    for i in range(12):
        x = -1.5 + i * 0.27
        meshes.append(quad((x, 0, 0), (0.05, 0.02 * (i + 1), 0), (0.0, 1.0, 0.2 * (i % 3)), "bar", 1))
    meshes.append(quad((0, 0, -0.5), (4, 0, 0), (0, 4, 0), "ground", 0))
    cam = Camera(look_at((0, -0.2, 4.0), (0, 0, 0), up=(0, 1, 0)), lens=35.0)
    scene = Scene(cam, 160, 120, meshes, mats, [], World((0, 0, 0)))
    one, t1, _ = run(scene, samples=1, filter_type="BOX", filter_width=1e-6)
    many, t64, _ = run(scene, samples=64, sampler="jittered")
    save("effect_antialiasing.png", [one, many])
    lines.append(f"| Pixel anti-aliasing | effect_antialiasing.png | left: 1 sample at the pixel "
                 f"centre ({t1:.2f} s); right: 64 jittered samples, Blackman-Harris 1.5 px "
                 f"({t64:.2f} s) |")


def effect_soft_shadows(lines):
    """One blocker, five light sources of the same size class."""
    panels, notes = [], []
    blocker = [box((-0.3, -0.3, 0.0), (0.3, 0.3, 0.8), "block", 0)]
    pos = (-1.4, -0.6, 2.0)
    m = np.eye(4)
    m[:3, 3] = pos
    glow = Material("glow", (0, 0, 0), specular_ior_level=0.0, emission=(12, 12, 12))
    variants = [
        ("area rectangle", [AreaLight(m, (40,) * 3, "RECTANGLE", 0.8, 0.4)], [], []),
        ("area disk", [AreaLight(m, (40,) * 3, "DISK", 0.8)], [], []),
        ("sphere (point, radius 0.3)", [PointLight(pos, (120,) * 3, radius=0.3)], [], []),
        ("sun, 10 degrees", [SunLight((0.6, 0.3, -0.7), (1.5,) * 3, angle=np.radians(10))], [], []),
        ("emissive mesh", [], [quad(pos, (0.4, 0, 0), (0, -0.2, 0), "panel", 1)], [glow]),
    ]
    for name, lights, extra, mats in variants:
        scene = stage(mats, blocker + extra, lights, default_camera(), size=(128, 96))
        img, t, _ = run(scene, samples=64, integrator="distribution")
        panels.append(img)
        notes.append(f"{name} {t:.1f} s")
    save("effect_soft_shadows.png", panels)
    lines.append("| Soft shadows | effect_soft_shadows.png | distribution integrator, 64 samples; "
                 + "; ".join(notes) + " |")


def effect_depth_of_field(lines):
    """Small bright spheres at several depths, focus on the middle row; round aperture
    against six blades."""
    glow = Material("glow", (0, 0, 0), specular_ior_level=0.0, emission=(150, 110, 70))
    spheres = [uv_sphere((x, y, 0.4 + 0.3 * (i % 2)), 0.025, 8, 16, "s", 1)
               for i, (x, y) in enumerate([(x, y) for x in (-0.9, -0.3, 0.3, 0.9)
                                           for y in (-2.0, 0.3, 1.8)])]
    panels, notes = [], []
    for blades in (0, 6):
        cam = default_camera(aperture_radius=0.12, focus_distance=4.3, blades=blades,
                             blade_rotation=0.3)
        img, t, _ = run(stage([glow], spheres, [], cam, size=(160, 120)), samples=128)
        panels.append(img)
        notes.append(f"{'round' if blades == 0 else f'{blades} blades'} {t:.1f} s")
    save("effect_depth_of_field.png", panels)
    lines.append("| Depth of field, bokeh | effect_depth_of_field.png | aperture radius 0.12 m "
                 "(about f/0.17 at 40 mm: exaggerated to show the shape), focus 4.3 m, "
                 "128 samples; " + "; ".join(notes) + " |")


def effect_integrators(lines):
    panels, notes = [], []
    for integ in ("whitted", "distribution", "path"):
        img, t, _ = run(cornell_box(128, 128), samples=64, integrator=integ)
        panels.append(img)
        notes.append(f"{integ} {t:.1f} s")
    save("effect_integrators.png", panels)
    lines.append("| Integrators | effect_integrators.png | Whitted (hard shadows), distribution "
                 "(soft shadows, no interreflection), path (global illumination), 64 samples; "
                 + "; ".join(notes) + " |")


def effect_motion_blur(lines):
    red = Material("red", (0.8, 0.1, 0.1), specular_ior_level=0.0)
    cube = box((-0.25, -0.25, 0.0), (0.25, 0.25, 0.5), "cube", 1)
    shift = np.eye(4)
    shift[:3, 3] = (1.0, 0, 0)
    cube.motion = RigidMotion([0.0, 1.0], [np.eye(4), shift])
    cube.positions = cube.positions + [-0.8, 0, 0]
    spin = box((-0.5, -0.05, 0.0), (0.5, 0.05, 0.1), "bar", 1)
    spin.positions = spin.positions + [0, 0, 1.2]
    rot = []
    for a in np.linspace(0, np.pi * 0.75, 5):
        m = np.eye(4)
        m[:2, :2] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
        m[:3, 3] = (0.9, 0.6, 0)
        rot.append(m)
    spin.motion = RigidMotion(np.linspace(0, 1, 5), rot)
    spin.positions = spin.positions - [0, 0, 0]
    light = AreaLight(np.array([[1, 0, 0, -1.0], [0, 1, 0, -1.0], [0, 0, 1, 3.0],
                                [0, 0, 0, 1.0]]), (60,) * 3, "SQUARE", 1.5, 1.5)
    cam = Camera(look_at((0.2, -3.0, 1.4), (0.2, 0.3, 0.6)), lens=35.0)
    scene = stage([red], [cube, spin], [light], cam, size=(200, 150))
    static = stage([red], [box((-0.25, -0.25, 0.0), (0.25, 0.25, 0.5), "cube", 1)], [light],
                   cam, size=(200, 150))
    scene.shutter = Shutter()
    img, t, _ = run(scene, samples=64, integrator="distribution")
    img0, t0, _ = run(static, samples=64, integrator="distribution")
    save("effect_motion_blur.png", [img0, img])
    lines.append(f"| Motion blur | effect_motion_blur.png | left: still; right: a cube translating 1 m and a bar "
                 f"turning 135 degrees over the shutter (5 motion steps), 64 samples, "
                 f"{t:.1f} s (the same stage with a still cube: {t0:.1f} s) |")


def _spheres_row(materials, y=0.0):
    xs = np.linspace(-1.2, 1.2, len(materials))
    return [uv_sphere((x, y, 0.4), 0.38, 24, 48, "ball", 1 + i) for i, x in enumerate(xs)]


def _lit_stage(materials, meshes, size=(240, 120)):
    m = np.eye(4)
    m[:3, 3] = (0.0, -1.0, 2.5)
    light = AreaLight(m, (120,) * 3, "RECTANGLE", 2.0, 0.6)
    stripes = [quad((x, 1.9, 1.0), (0.12, 0, 0), (0, 0, 1.0), "stripe", len(materials) + 1)
               for x in np.linspace(-2.4, 2.4, 9)]
    glow = Material("stripe", (0, 0, 0), specular_ior_level=0.0, emission=(3.0, 2.6, 2.0))
    cam = Camera(look_at((0, -3.6, 1.2), (0, 0.2, 0.45)), lens=45.0)
    mats = [Material("checker", (0.5, 0.5, 0.5), specular_ior_level=0.0)] + materials + [glow]
    floor = [quad((0, 0, 0), (3, 0, 0), (0, 3, 0), "floor", 0)]
    scene = Scene(cam, size[0], size[1], floor + meshes + stripes, mats, [light],
                  World((0.05, 0.05, 0.06)))
    return scene


def effect_glossy(lines):
    """GGX metals at three roughnesses (alpha = roughness^2, as Blender), and a plastic."""
    mats = [Material("gold r0.05", (1.0, 0.78, 0.34), metallic=1.0, roughness=0.05),
            Material("gold r0.25", (1.0, 0.78, 0.34), metallic=1.0, roughness=0.25),
            Material("gold r0.5", (1.0, 0.78, 0.34), metallic=1.0, roughness=0.5),
            Material("plastic", (0.1, 0.25, 0.7), roughness=0.2, specular_ior_level=0.5)]
    scene = _lit_stage(mats, _spheres_row(mats))
    img, t, _ = run(scene, samples=128, integrator="distribution")
    for m in mats:
        m.glossy_model = "BLINN_PHONG"
    img_bp, t_bp, _ = run(_lit_stage(mats, _spheres_row(mats)), samples=128,
                          integrator="distribution")
    save("effect_glossy.png", [img, img_bp])
    lines.append(f"| Glossy reflection | effect_glossy.png | left: GGX metal at roughness 0.05, "
                 f"0.25, 0.5 and a blue plastic (dielectric coat over diffuse), {t:.1f} s; "
                 f"right: the same with the lecture's Blinn-Phong lobe (exponent 2/alpha^2 - 2), "
                 f"{t_bp:.1f} s; distribution integrator, 128 samples |")


def effect_translucency(lines):
    """Smooth and rough glass (Fresnel, refraction, total internal reflection)."""
    mats = [Material("glass", (1, 1, 1), transmission=1.0, roughness=0.0, ior=1.45),
            Material("frosted", (1, 1, 1), transmission=1.0, roughness=0.3, ior=1.45),
            Material("tinted", (0.6, 0.9, 0.7), transmission=1.0, roughness=0.1, ior=1.5)]
    scene = _lit_stage(mats, _spheres_row(mats))
    img, t, _ = run(scene, samples=128, integrator="path", max_bounces=12)
    save("effect_translucency.png", [img])
    lines.append(f"| Translucency | effect_translucency.png | smooth glass (IOR 1.45), rough "
                 f"glass (roughness 0.3), tinted glass; path tracing, 128 samples, {t:.1f} s |")


def effect_cameras(lines):
    """Perspective, perspective with lens shift (verticals stay vertical), orthographic."""
    mats = [Material("white", (0.8, 0.8, 0.8), specular_ior_level=0.0)]
    towers = [box((x - 0.2, y - 0.2, 0), (x + 0.2, y + 0.2, 1.8), "tower", 1)
              for x in (-1.0, 0.0, 1.0) for y in (0.0, 1.2)]
    sun = [SunLight((-0.4, 0.6, -0.7), (3.0,) * 3, angle=np.radians(2))]
    panels, notes = [], []
    flat = look_at((0, -4.5, 0.9), (0, 0.5, 0.9))
    for name, cam in (("perspective, tilted up", Camera(look_at((0, -4.5, 0.5), (0, 0.5, 1.4)),
                                                        lens=30)),
                      ("perspective, shift_y 0.15", Camera(flat, lens=30, shift_y=0.15)),
                      ("orthographic, scale 5", Camera(flat, kind="ORTHO", ortho_scale=5.0))):
        scene = stage(mats, towers, sun, cam, size=(128, 96))
        img, t, _ = run(scene, samples=16, integrator="distribution")
        panels.append(img)
        notes.append(f"{name} {t:.1f} s")
    save("effect_cameras.png", panels)
    lines.append("| Cameras | effect_cameras.png | " + "; ".join(notes) + " |")


EFFECTS = {"antialiasing": effect_antialiasing, "soft_shadows": effect_soft_shadows,
           "depth_of_field": effect_depth_of_field, "integrators": effect_integrators,
           "motion_blur": effect_motion_blur, "glossy": effect_glossy,
           "translucency": effect_translucency, "cameras": effect_cameras}


def main(names):
    os.makedirs(IMAGES, exist_ok=True)
    lines = ["# Effects", "", "Written by `docs/effects.py` (rerun it to reproduce images and "
             "timings; 2-core machine).", "", "| effect | image | settings and measured time |",
             "|---|---|---|"]
    for name in names or EFFECTS:
        EFFECTS[name](lines)
        print(lines[-1])
    body = "\n".join(lines) + "\n\n" + "\n".join(
        f"![{l.split('|')[1].strip()}](images/{l.split('|')[2].strip()})"
        for l in lines[6:]) + "\n"
    with open(os.path.join(ROOT, "docs", "effects.md"), "w") as f:
        f.write(body)


if __name__ == "__main__":
    main(sys.argv[1:])
