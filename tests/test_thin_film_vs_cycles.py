"""The Principled BSDF's Thin Film against Cycles, at its defaults (Multiscatter GGX):
iridescent plastics, metals and soap-bubble glass as artists set them up
(engine/kernels/bsdf/thin_film.py).

Each case is the smooth sphere of tests/test_anisotropic_vs_cycles.py (an area lamp, a
world of strength 0.4): the film's colours change with the angle across the sphere and in
the lamp's highlight. The images are compared per colour channel, since a film moves
colour more than brightness: each channel's mean within 1 % and its largest 8 x 8 block
within 5 % of the channel's mean (8 % for the metals, below). Measured at 512 samples
each (worst channel's mean, largest block): soap on black 0.01 % and 3.2 %, tinted plastic
0.05 % and 2.7 %, oxidised copper 0.13 % and 6.2 %, tinted metal 0.18 % and 6.2 %. The
control, DRT without the film (as before, when DRT left the film out with a warning):
37.7 % and 1073 %, 2.5 % and 83 %, 34.4 % and 861 %, 15.6 % and 384 %.

The metals' largest block is their lamp highlight, which is darker in DRT by 3.5 % of the
image mean with or without a film (DRT at 2048 samples against Cycles at 4096, the
copper without its film: -3.5 %, a grey metal -3.5 %, at roughness 0.5 -1.0 %, alike
with DRT's light-only, BSDF-only and MIS estimators, on a 48 x 24 and a 192 x 96 sphere;
Cycles' own noise there at 512 samples: 6.7 %): a gap of the rough metal's highlight
that the film does not change, not yet found, so those two cases are allowed 8 %."""
from __future__ import annotations

import numpy as np
import pytest

from figures import AGAINST_CYCLES, record
from node_probe import new_material, render
from test_anisotropic_vs_cycles import _sphere_scene

SAMPLES = 512
MEAN_TOLERANCE = 0.01
BLOCK_TOLERANCE = 0.05
METAL_BLOCK_TOLERANCE = 0.08          # the rough metal's highlight (module docstring)


def _principled(bpy, name, base, film_nm, film_ior, metallic=0.0, roughness=0.2,
                tint=None):
    mat, nt = new_material(bpy, name)
    p = nt.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*base, 1.0)
    p.inputs["Metallic"].default_value = metallic
    p.inputs["Roughness"].default_value = roughness
    p.inputs["Thin Film Thickness"].default_value = film_nm
    p.inputs["Thin Film IOR"].default_value = film_ior
    if tint is not None:
        p.inputs["Specular Tint"].default_value = (*tint, 1.0)
    return mat


CASES = {
    # a dark plastic under a soap film: the film is all its reflection shows
    "soap_on_black": lambda bpy: _principled(bpy, "Soap", (0.02, 0.02, 0.02), 450.0, 1.33,
                                             roughness=0.15),
    # a pale plastic whose Specular Tint scales the film's F0
    "tinted_plastic": lambda bpy: _principled(bpy, "Tinted", (0.3, 0.3, 0.35), 250.0, 1.6,
                                              tint=(1.0, 0.6, 0.6)),
    # copper under an oxide film
    "oxidised_copper": lambda bpy: _principled(bpy, "Copper", (0.95, 0.64, 0.54), 300.0, 1.5,
                                               metallic=1.0, roughness=0.25),
    # a tinted (F82) metal under a high-index film
    "tinted_metal": lambda bpy: _principled(bpy, "Metal", (0.9, 0.9, 0.9), 150.0, 2.0,
                                            metallic=1.0, roughness=0.3,
                                            tint=(0.8, 0.9, 1.0)),
}


def _glass(bpy, name, roughness, film_nm):
    mat = _principled(bpy, name, (1.0, 1.0, 1.0), film_nm, 1.33, roughness=roughness)
    mat.node_tree.nodes["Principled BSDF"].inputs["Transmission Weight"].default_value = 1.0
    return mat


GLASS_CASES = {
    # a soap bubble's skin: a clear glass under a film (smooth: delta reflection and
    # refraction, from outside and from inside)
    "bubble": lambda bpy: _glass(bpy, "Bubble", 0.0, 380.0),
    # a frosted glass under a film (rough: the reflection and refraction pairs)
    "frosted_bubble": lambda bpy: _glass(bpy, "Frosted", 0.25, 500.0),
}


def channel_errors(drt, cycles, what=AGAINST_CYCLES):
    """(largest |channel mean ratio - 1|, largest 8 x 8 block difference of a channel
    over that channel's mean), recorded for the docs as `what`."""
    h, w, _ = cycles.shape
    means = drt.mean(axis=(0, 1)) / cycles.mean(axis=(0, 1)) - 1.0
    d = (drt - cycles).reshape(h // 8, 8, w // 8, 8, 3).mean(axis=(1, 3))
    block = np.abs(d).max(axis=(0, 1)) / cycles.mean(axis=(0, 1))
    worst = float(np.abs(means).max()), float(block.max())
    record(what + " (worst channel)", mean=worst[0], block=worst[1])
    return worst


@pytest.mark.parametrize("case", sorted(CASES))
def test_thin_film_matches_cycles(bpy_drt, case):
    bpy = bpy_drt
    scene = _sphere_scene(bpy, CASES[case])
    cycles = render(bpy, scene, "CYCLES", SAMPLES)[..., :3]
    mean, block = channel_errors(render(bpy, scene, "DRT", SAMPLES)[..., :3], cycles)
    print(f"{case}: worst channel mean {mean:.2%}, largest block {block:.2%}")
    # the control: the film left out
    for mat in bpy.data.materials:
        mat.node_tree.nodes["Principled BSDF"].inputs["Thin Film Thickness"].default_value = 0.0
    c_mean, c_block = channel_errors(render(bpy, scene, "DRT", 64)[..., :3], cycles,
                                     "control: the film left out")
    print(f"{case} without the film (control): worst channel mean {c_mean:.2%}, "
          f"largest block {c_block:.2%}")
    bound = METAL_BLOCK_TOLERANCE if case in ("oxidised_copper", "tinted_metal") else \
        BLOCK_TOLERANCE
    assert mean < MEAN_TOLERANCE and block < bound, (mean, block)
    assert not (c_mean < MEAN_TOLERANCE and c_block < bound), (c_mean, c_block)


def _film_thickness(bpy, nm):
    for mat in bpy.data.materials:
        mat.node_tree.nodes["Principled BSDF"].inputs["Thin Film Thickness"].default_value = nm


@pytest.mark.parametrize("case", sorted(GLASS_CASES))
def test_thin_film_on_glass_changes_the_image_as_in_cycles(bpy_drt, case):
    """A glass sphere under an area lamp is noisy in both engines (the lamp refracted
    through it; at 512 samples each, Cycles' own largest block against another seed is
    about 20 %), and the rough one's mean is 1.5 % above Cycles' without a film too (at
    512 samples each; not separated into noise and gap here). So the film's effect is
    compared:
    each channel's mean with the film over its mean without, DRT's against Cycles', within
    1 %; and DRT's largest block with the film against Cycles' at most 1.5 times Cycles'
    own against another seed. Measured (the film's effect on the worst channel, DRT
    against Cycles; largest block, Cycles' own): bubble 0.09 % (the film: red -27 %, blue
    -6 %), 22.9 % and 22.3 %; frosted 0.69 % (red +1 %, blue -24 %), 26.1 % and 20.0 %.
    Before, choosing reflection or refraction by the film-free Fresnel, the bubble was 4 %
    bright (fireflies where the film lets through light the bare glass nearly totally
    reflects); the choice now takes the film's reflectance, as Cycles' does
    (thin_film.glass_choice)."""
    bpy = bpy_drt
    scene = _sphere_scene(bpy, GLASS_CASES[case])
    film = bpy.data.materials[0].node_tree.nodes["Principled BSDF"].inputs[
        "Thin Film Thickness"].default_value
    means, images = {}, {}
    for nm in (film, 0.0):
        _film_thickness(bpy, nm)
        for engine in ("CYCLES", "DRT"):
            img = render(bpy, scene, engine, SAMPLES)[..., :3]
            images[engine, nm] = img
            means[engine, nm] = img.mean(axis=(0, 1))
    _film_thickness(bpy, film)
    scene.cycles.seed = 1
    cycles_again = render(bpy, scene, "CYCLES", SAMPLES)[..., :3]
    effect = {e: means[e, film] / means[e, 0.0] for e in ("CYCLES", "DRT")}
    off = float(np.abs(effect["DRT"] / effect["CYCLES"] - 1.0).max())
    _, block = channel_errors(images["DRT", film], images["CYCLES", film])
    _, own = channel_errors(cycles_again, images["CYCLES", film],
                            "Cycles against itself (another seed)")
    record("the film's effect on each channel's mean, DRT's over Cycles'", mean=off)
    print(f"{case}: the film's effect, DRT {np.round(effect['DRT'] - 1, 4)}, Cycles "
          f"{np.round(effect['CYCLES'] - 1, 4)} (off by {off:.2%}); largest block "
          f"{block:.2%}, Cycles' own {own:.2%}")
    assert off < MEAN_TOLERANCE, effect
    assert float(np.abs(effect["CYCLES"] - 1.0).max()) > 0.05     # the film shows
    assert block < 1.5 * own, (block, own)


def _both_spheres(bpy):
    """The copper under its film (left) and the clear bubble (right) in one scene."""
    scene = _sphere_scene(bpy, CASES["oxidised_copper"])
    copper = bpy.context.object
    copper.location.x = -1.1
    copper.scale = (0.9, 0.9, 0.9)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.9, segments=48, ring_count=24,
                                         location=(1.1, 0.0, 0.0))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(GLASS_CASES["bubble"](bpy))
    return scene


def test_the_color_passes_carry_the_film(bpy_drt):
    """Glossy and Transmission Color (the lobes' albedo at the first hit, Cycles' estimate:
    a film's reflectance at the view, no table, times the closure weight's multiscatter
    darkening) of a copper and a clear glass under films, against Cycles' passes at 128
    samples: means within 0.002 and 8 x 8 blocks within 0.02 of Combined's mean. Measured:
    +0.0001 and 0.0084 (Glossy), +0.0001 and 0.0061 (Transmission). With the film-free
    Fresnel in the passes (before): the copper's Glossy Color 4.3 % above Cycles', the
    bubble's 50 %; without the darkening, the copper's 1.2 %."""
    import light_pass_scene
    bpy = bpy_drt
    if bpy.app.version < (5, 0, 0):
        pytest.skip("the File Output node's API read here is Blender 5's")
    names = ["Glossy Color", "Transmission Color"]

    def build():
        scene = _both_spheres(bpy)
        scene.cycles.samples = scene.drt.samples = 128
        scene.cycles.use_denoising = scene.cycles.use_adaptive_sampling = False
        vl = scene.view_layers[0]
        vl.use_pass_glossy_color = vl.use_pass_transmission_color = True
        return scene
    scene = build()
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    cycles = light_pass_scene.cycles_passes(bpy, scene, ["Image"] + names)
    build()
    drt = light_pass_scene.drt_passes(bpy, names)
    scale = cycles["Image"].mean()
    h, w, _ = cycles["Image"].shape
    for name in names:
        mean = (drt[name].mean() - cycles[name].mean()) / scale
        d = (drt[name] - cycles[name])[:h // 8 * 8, :w // 8 * 8]
        block = np.abs(d.reshape(h // 8, 8, w // 8, 8, 3).mean(axis=(1, 3))).max() / scale
        print(f"{name}: mean {mean:+.4f}, worst block {block:.4f}")
        assert abs(mean) < 0.002 and block < 0.02, (name, mean, block)
