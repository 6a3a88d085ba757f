"""Renders the volume scenes (tests/volume_scenes.py), the fog room
(sample_blends/fog_room.blend) and the smoke plume (a Volume object,
sample_blends/smoke_plume.blend) with DRT and with Cycles, side by side, and writes
docs/volumes.md with the measured differences and render times.

    .venv/bin/python docs/make_volume_docs.py [--cases noise ...]

With --cases only the scenes named are rendered again; the other rows of the table
(and their images) are kept from the current docs/volumes.md.

Each volume scene is built with bpy at Blender's defaults and rendered at 64 x 48
pixels, Cycles at 1024 samples, DRT at 512; the images in docs/images/volume_<case>.png
are the PNGs Blender saves through the view transform, DRT left, Cycles right. Takes
about 8 minutes on 2 cores.
"""
from __future__ import annotations

import os
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests"), os.path.join(ROOT, "docs")]
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")

from make_comparisons import render, save_png, side_by_side  # noqa: E402
from test_multiscatter_vs_cycles import compare  # noqa: E402

CYCLES_SAMPLES = 1024
DRT_SAMPLES = 512
CASES = {
    "scatter": "Fog in a box: Principled Volume, density 0.25, a volume-only material "
               "(Surface unlinked).",
    "tinted": "Tinted forward-scattering fog: Color (0.9, 0.6, 0.3), Absorption Color "
              "(0.2, 0.5, 0.9), Anisotropy 0.5, density 0.4.",
    "multiple": "Multiple scattering: Volume Scatter, density 0.6, colour 0.9, Light Paths "
                "> Volume 4 in both engines.",
    "absorption_glass": "Coloured glass: a Glass BSDF with Volume Absorption inside "
                        "(colour (0.2, 0.6, 0.9), density 1.5).",
    "noise": "Fog in blobs (a heterogeneous volume): Principled Volume whose Density is a "
             "Noise Texture (scale 2.5, Generated coordinates) through a Color Ramp "
             "from 0 at 0.42 to 0.6 at 0.58.",
    "noise_lamps": "The fog in blobs lit by two point lamps inside it (150 W warm, 100 W "
                   "cool, radius 5 cm), the area lamp dimmed to 20 W: most light is "
                   "scattered close to the lamps, which equiangular sampling finds. "
                   "Near the lamps both engines are still noisy at these samples (Cycles "
                   "against itself at another seed: 3.4 % in the largest block at 48 x "
                   "32); tests/test_volumes_vs_cycles.py compares DRT at 1024 samples "
                   "with Cycles at 4096.",
    "emission": "An emitting volume: an Emission shader on the Volume socket, strength "
                "1.5.",
    "world": "A world volume: Principled Volume, density 0.05, on the World Output.",
    "camera_inside": "The camera inside the fog (density 0.15): the paths start in it.",
    "beam": "A spot lamp (1500 W, 40 degrees) through fog of density 0.08, the area lamp "
            "dimmed to 20 W: the beam is lit fog. Its direct light takes distances by "
            "transmittance and equiangularly towards the lamp, combined by multiple "
            "importance sampling (the material's Volume Sampling Method, Cycles' default); "
            "{distance} (tests/test_lit_fog.py measures the noise on a thinner fog: "
            "1/190 of the squared error at equal samples). Equiangular distances are "
            "drawn only inside the spot's cone, as Cycles draws them.",
    "clipped_world": "Thin fog filling the world (Volume Scatter, density 0.02) under a "
                     "grey sky, a spot lamp's beam (200 kW, 35 degrees) crossing the view "
                     "far beyond the camera's clip end (9 m): a ray that reaches the clip "
                     "end goes on through the world's volume to infinity, as in Cycles, "
                     "so the sky is not seen through the fog and the beam beyond is. A "
                     "sun (3 W/m2) gives no light at all through such a volume, in "
                     "either engine. "
                     "Before 2026-12-03 DRT ended the volume at the clip end (smoke.blend, "
                     "a public file, was +51 % too bright).",
}


def _render(bpy, build, engine, samples, png):
    from conftest import render_current, use_engine
    scene = build()
    use_engine(scene, engine, samples)
    t0 = time.perf_counter()
    img = render_current(bpy, scene)
    seconds = time.perf_counter() - t0
    save_png(bpy, scene, png)
    return img, seconds


def _distance_alone(bpy, build, cycles, tmp):
    """The scene's largest block difference from Cycles with its fog's Volume Sampling
    Method set to Distance (no equiangular sampling), at DRT's samples and 4 times
    them."""
    parts = []
    for samples in (DRT_SAMPLES, 4 * DRT_SAMPLES):
        def distance_only():
            scene = build()
            bpy.data.materials["Fog"].cycles.volume_sampling = "DISTANCE"
            return scene
        img, _ = _render(bpy, distance_only, "DRT", samples,
                         os.path.join(tmp, f"distance_{samples}.png"))
        parts.append(f"{100 * compare(img, cycles)[1]:.1f} % at {samples} samples")
    return "with distance sampling alone the largest block is " + " and ".join(parts)


def _kept_rows(cases):
    """The current docs/volumes.md's table rows and sections of the scenes not in
    `cases` ({case: (row, section lines)})."""
    path = os.path.join(DOCS, "volumes.md")
    if not os.path.exists(path):
        return {}
    text = open(path).read().split("\n")
    rows = {line.split("|")[1].strip(): line for line in text
            if line.startswith("| ") and not line.startswith("| scene")}
    kept = {}
    for case, row in rows.items():
        if case in cases or f"## {case}" not in text:
            continue
        i = text.index(f"## {case}")
        kept[case] = (row, text[i:i + 6])
    return kept


def main(argv=None):
    import argparse
    import bpy
    import drt_addon
    import volume_scenes
    drt_addon.register()
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", nargs="*", default=None,
                    help="render only these scenes again, keeping the others' rows")
    args = ap.parse_args(argv)
    only = set(args.cases) if args.cases else None
    kept = _kept_rows(only) if only else {}
    lines = ["# Volumes", "",
             "DRT renders homogeneous volumes as Cycles does: Principled Volume, Volume "
             "Scatter, Volume Absorption, Volume Coefficients and Emission on a material's "
             "Volume socket (inside its closed meshes) or the world's (everywhere outside "
             "them); a material with a volume and no surface shader is the volume's "
             "boundary, which rays cross without a bounce. Paths carry a stack of the "
             "volumes they are in (the camera's found by a ray), sample a scattering "
             "distance per colour channel with one-sample MIS, light the scattering points "
             "by next-event estimation with the Henyey-Greenstein phase function (MIS "
             "against phase sampling), and light each segment's direct light once more at "
             "a distance sampled equiangularly towards the picked lamp (Kulla and Fajardo "
             "2012), the two distances combined by MIS as the material's or world's "
             "Settings > Volume > Sampling Method says (Cycles' defaults: Multiple "
             "Importance for materials, Equiangular for the world; Distance turns it off), "
             "and go on within Light Paths > Max Bounces > Volume "
             "(Cycles' default 0: direct light in volumes only). Shadow rays are "
             "attenuated by the volumes they cross.", "",
             "A volume whose coefficients vary in space (a texture, or any node graph, on "
             "Density, Color, Absorption Color, the emission or a Mix Shader's Fac) is "
             "rendered as Cycles 5 renders it by default, by null scattering: the "
             "material's node program runs at points inside the medium, the scattering "
             "distance is sampled by delta tracking (spectral tracking over the colour "
             "channels) against a majorant of the density, and shadow rays are attenuated "
             "by ratio tracking. Both estimators are unbiased whatever the majorant. The "
             "direct light of each segment is also taken at a distance sampled "
             "equiangularly towards a lamp, as in homogeneous fog: its transmittance is "
             "the same tracking's, continued past a scattering as ratio tracking, and "
             "the two strategies are weighed by the densities of their null-scattering "
             "paths (Miller et al. 2019), as Cycles weighs them. DRT "
             "keeps a grid of 16 x 16 x 16 majorants over the object's bounds, each 1.5 "
             "times the largest of 8 samples of the program in its cell and its 26 "
             "neighbours (a peak between one cell's samples is often found by a "
             "neighbour's) and of the "
             "program at the centre of each grid's largest voxel that reaches into it, "
             "and takes free flights cell by cell (engine/kernels/majorant_grid.py, "
             "majorant_bounds.py), so that a smoke in its box is tracked at the rate "
             "its density needs where it is (Cycles keeps an octree of majorants for "
             "the same reason). Scenes without such a volume run none of this.", "",
             "Volume objects (an OpenVDB file: a smoke or fire cache, a cloud) render "
             "too. DRT reads the grids the object's materials use (Attribute nodes, and "
             "the Principled Volume's Density, Color and Temperature Attributes: "
             "density and temperature by default) with the openvdb module that ships "
             "with Blender, as dense blocks over their active voxels, and fills a box "
             "around them with the material's volume. Values sit at the voxel centres "
             "and blend trilinearly between them, as in Cycles 5. The temperature is "
             "read as Cycles 5 reads it, one voxel's value per lookup picked with the "
             "trilinear weights, so that blackbody emission (Stefan-Boltzmann's T^4 "
             "times the blackbody colour of T) is the blend of the voxels' emissions. "
             "In Object space (the Volume's default Render > Space) the coefficients "
             "scale with the object, as in Cycles. A Volume object without a material "
             "renders with Cycles' default volume (a Principled Volume reading its "
             "density grid). A packed or missing file, modifiers on the Volume, and "
             "integer grids are named in Blender's report.", "",
             f"Each scene below at Blender's defaults, 64 x 48 pixels, Cycles "
             f"{CYCLES_SAMPLES} samples, DRT {DRT_SAMPLES}; DRT left, Cycles right. Mean: "
             "signed difference of the image means per channel; block: the largest "
             "difference of 8 x 8 block means over Cycles' image mean "
             "(tests/test_volumes_vs_cycles.py checks the same at 48 x 32).", "",
             "| scene | mean R / G / B | largest block | DRT s | Cycles s |",
             "|---|---|---|---|---|"]
    sections = []
    with tempfile.TemporaryDirectory() as tmp:
        jobs = [(c, (lambda c=c: volume_scenes.build(bpy, c)), CASES[c]) for c in CASES]
        jobs.append(("fog_room", None, "The artist scene sample_blends/fog_room.blend: a "
                     "room of default materials filled with fog, lit through a window."))
        jobs.append(("smoke_plume", None, "A Volume object (sample_blends/smoke_plume."
                     "blend): an OpenVDB file of density, temperature and flame grids "
                     "(48 x 48 x 80 voxels of 4 cm) rising from a fire, with a Principled "
                     "Volume reading the density and temperature grids by Blender's "
                     "default attribute names (Density 10, Blackbody Intensity 1 over "
                     "1500 K) and an Attribute node reading the flame grid into Emission "
                     "Strength; a sun and a dim sky."))
        for case, build, text in jobs:
            if case in kept:
                row, section = kept[case]
                lines.append(row)
                sections += section
                continue
            out = {}
            for engine, samples in (("DRT", DRT_SAMPLES), ("CYCLES", CYCLES_SAMPLES)):
                png = os.path.join(tmp, f"{case}_{engine}.png")
                if build is None:
                    img, sec = render(bpy, os.path.join(ROOT, "sample_blends",
                                                        f"{case}.blend"), engine, samples,
                                      png=png)
                else:
                    img, sec = _render(bpy, build, engine, samples, png)
                out[engine] = (img, sec, png)
                print(case, engine, f"{sec:.1f} s", flush=True)
            (d, ds, dp), (c, cs, cp) = out["DRT"], out["CYCLES"]
            rel, block = compare(d, c)
            if "{distance}" in text:
                text = text.format(distance=_distance_alone(bpy, build, c, tmp))
            name = f"volume_{case}.png"
            side_by_side([dp, cp], ["DRT", "Cycles"], os.path.join(IMAGES, name))
            lines.append(f"| {case} | {' / '.join(f'{100 * v:+.2f} %' for v in rel)} | "
                         f"{100 * block:.1f} % | {ds:.1f} | {cs:.1f} |")
            sections += [f"## {case}", "", text, "", f"![{case}](images/{name})", ""]
    lines += [""] + sections + [
        "## A volume that fills the world", "",
        "A volume on the World Output fills all space, so, as in Cycles, no sun and no "
        "world light reaches anything through it (their shadow rays are endless), and "
        "the sky is not seen through it, also past the camera's clip end (the clipped_world "
        "case); Blender warns that such a volume might need to be converted to an "
        "object. Lamps with a position light it. Before 2026-12-03 DRT let sun and world "
        "light through four scene radii of it, and camera rays saw the sky through what "
        "lay beyond the clip end.", "",
        "## Known differences", "",
        "- Phase functions other than Henyey-Greenstein are not rendered (warned); an "
        "Anisotropy that varies in space takes its average, and so does a world volume "
        "that varies (warned).",
        "- A Volume object's grids are read from its file at the frame: modifiers on the "
        "Volume (Mesh to Volume, Volume Displace) and packed files are not read yet "
        "(warned). Velocity grids do not blur the smoke (Cycles' volume motion blur).",
        "- With motion blur a heterogeneous volume keeps one majorant everywhere "
        "(its grid holds the media where they are at the frame): slower, not less "
        "accurate."]
    with open(os.path.join(DOCS, "volumes.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("wrote docs/volumes.md")


if __name__ == "__main__":
    main()
