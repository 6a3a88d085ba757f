"""Renders every shader-node case of tests/node_cases.py with DRT and with Cycles and
writes docs/nodes.md: the nodes DRT evaluates per hit, a DRT / Cycles image pair per
node family, and the measured difference of every case.

    .venv/bin/python docs/make_nodes_docs.py

Each case is one tile of an emission-only render (tests/node_probe.py): a node graph
shown as an emission colour, so the tile is the node's value, seen by both engines
through the same pixel filter. About 2 minutes on 2 cores.
"""
from __future__ import annotations

import os
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests"), os.path.join(ROOT, "docs")]
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")

from make_comparisons import save_png, side_by_side  # noqa: E402

INTRO = """# Shader nodes

Written by `docs/make_nodes_docs.py`; rerun it to reproduce.

DRT compiles the node graph behind a material's inputs into a small program that the
tracer runs at every hit (`engine/nodes/`, one module per node family; the exporter's
translators are in `drt_addon/export/nodes/`). A graph that does not depend on the hit
is folded into a constant at export. A node DRT does not evaluate is named in one
warning for its material and the socket it feeds keeps its own value.

Below, every case of `tests/node_cases.py` is one tile of an emission-only render: the
node's output shown as an emission colour on its own plane (or sphere), seen from above
by an orthographic camera, so the tile is the node's value. DRT left, Cycles right, the
same samples per pixel. The columns are the difference of the tile means and the
per-pixel mean absolute difference, both over Cycles' tile mean, and the largest
difference of the 8 x 8 block means. `tests/test_nodes_vs_cycles.py` asserts 1%, 3% and
3% for every case, and that every case fails those checks when its node is left out.
"""

KNOWN = """## Known differences

- **Normal Map in a lit scene.** The node's value matches Cycles per pixel (the
  `normal_map` tiles). Cycles' Principled BSDF lights its diffuse lobe by the map's
  normal and its specular lobes by that normal made a valid reflector for the view;
  DRT does the same, with Cycles 5.0's bump shadowing: light from under the surface's
  own smooth normal is refused to every lobe, and the diffuse lobe's light fades
  towards the smooth surface's terminator by a GGX shadowing whose roughness grows with
  the bend (Conty Estevez et al.). A plane tilted by its map agrees with Cycles to
  0.00% under an overhead sun and suns off the vertical
  (`tests/test_nodes_vs_cycles.py`); a normal-mapped diffuse sphere under a low sun to
  0.02% in the mean and 0.7% of the image mean in its largest 8 x 8 block
  (`tests/test_bump_vs_cycles.py`; 52% with the shadowing term of Cycles 3 and 4).
  Material > Settings > Bump Map Correction turned off is honoured as in Cycles: the
  specular lobes take the bent normal as it is and the diffuse light is not faded (only
  refused under the smooth normal); the normal-mapped sphere then agrees to 0.03% and
  0.7% (43% in the largest block when corrected anyway).
- **Smooth shading on coarse meshes.** By the terminator of a smooth-shaded mesh light
  reaches points from under their own triangle's plane. As Cycles, DRT lights them by
  the shading normals alone and starts their shadow rays from the curved surface the
  corner normals describe, with the object's Shadow Terminator > Geometry Offset
  (Cycles' shadow_ray_smooth_surface_offset). A close-up of a 32 x 16 sphere's
  terminator agrees to 0.05% in the mean and 0.16% in its largest block under a low
  sun, 0.03% and 0.45% under an area lamp; with shadow rays from the flat triangles (as
  DRT had them) 6.3% and 9.3% (`tests/test_terminator_vs_cycles.py`). By the
  silhouette the camera may see a triangle whose interpolated normal faces away from
  it; the diffuse lobe still reflects there, as Cycles' does: a tilted 16 x 8 sphere
  agrees to 0.05% and 0.47% (0.89% and 3.9% before). Triangles of objects with motion
  blur start shadow rays from the flat triangle; Shadow Terminator > Shading Offset is
  not read.
- **Bump.** Evaluated as Cycles 5.0 does: the Height's nodes run again at the hit moved
  by Filter Width pixel steps along two tangents, the steps from each ray's footprint
  (Cycles' compact ray differentials: a cone from the camera's pixel that keeps growing
  with the path's length after bounces). The normals match Cycles per pixel (the
  `bump` tiles; on a perspective view of a bumped floor to 0.2%) and are lit as Normal
  Map's above: a bumped lit floor agrees with Cycles to 0.08% in the mean and 0.17%
  in its largest block, a bumped glossy sphere under a low sun to 0.09% and 0.6%
  (`tests/test_bump_vs_cycles.py`).
  Texture Coordinate's Normal is not moved at the offset hits (Cycles moves it with
  the interpolated normal).
- **Inputs that vary per hit but feed a parameter DRT keeps per material** (IOR,
  Transmission, Specular IOR Level, Emission Strength, a Mix Shader's Fac) take the
  graph's average over the unit square of UV and generated coordinates (reported).
- **Mix Shader with a per-hit Fac.** Cycles sums the two shaders weighted by the Fac;
  DRT shades each hit by one of them, picked with the Fac's probability (unbiased, a
  little noisier; `test_mix_shader_with_per_hit_factor_matches_cycles`: a checker mask
  and a Layer Weight Facing, both within 0.1% of Cycles' mean). A per-hit Mix Shader
  inside a Mix Shader whose Fac is constant, or inside an Add Shader, is lifted above
  it: a constant combination distributes over a per-hit mix, so each hit picks a side
  by the inner Fac and shades the constant combination of that side
  (`test_a_per_hit_mix_inside_a_constant_mix_or_add_matches_cycles`: 0.34% and 0.04%
  of Cycles' mean). A Fresnel or Layer Weight Fresnel factor between a diffuse and a
  glossy shader stays Principled's specular layer of that IOR, as before.
- **Object Info's Random** of an object that is not an instance is Cycles' hash of the
  object's name (Blender gives such objects random id 0); of an instance, Blender's
  random id (the `oi_random` tile).
- **A Translucent BSDF's Color** may vary per hit (a texture, or a ramp of Object Info's
  Random: `test_a_translucent_colour_that_varies_per_hit_matches_cycles`).
- **Procedural textures** follow Blender 5's hashes (its 2D to 4D Voronoi places cells
  with an integer hash that Blender 4.x did not use, so on 4.x those differ); White
  Noise hashes the exact float bits of its input, so it matches where both engines
  compute the same float32 coordinate; deep, strongly distorted Magic drifts from
  float32 rounding (5e-2 at depth 10, distortion 3); Wave's Detail is capped at 64
  octaves. Against Blender's own evaluation at random points
  (`tests/test_procedural_textures.py`): White Noise exact, Voronoi 1.3e-6, Wave
  4.3e-6, Magic 9.4e-6, Brick 2.5e-5, Noise 1.5e-4 of the value's scale.
- **Light Path depths** count the path's diffuse, glossy, transmission and transparent
  bounces as Cycles does; a program run for a surface's alpha (transparent layers,
  shadow rays) sees no bounces.
- Not evaluated yet (warned): Gabor, Sky and IES textures, Parametric, Pointiness and Random Per Island, Light Path's Is Singular Ray and Is
  Volume Scatter Ray, Map Range on vectors, Normal Map in object or world space, attributes other than colour
  attributes, a texture node's legacy Mapping panel.
"""


def supported_nodes(bpy):
    from drt_addon.export.nodes import color, converter, input, procedural, texture, vector
    rows = []
    for family, module in (("Input", input), ("Texture", texture),
                           ("Procedural texture", procedural), ("Colour", color),
                           ("Converter", converter), ("Vector", vector)):
        names = []
        for idname in module.TRANSLATORS:
            kind = getattr(bpy.types, idname, None)
            if kind is not None:                 # legacy nodes this Blender lacks
                names.append(kind.bl_rna.name)
        rows.append(f"| {family} | {', '.join(sorted(set(names)))} |")
    return ["| family | nodes |", "|---|---|"] + rows + [
        "| Groups | node groups (nested), Group Input / Output, Reroute, muted nodes |",
        SHADERS_ROW]


# the closures (drt_addon/export/nodes/shader.py, export/volumes.py, export/world.py);
# each is compared with Cycles in tests/test_closures_vs_cycles.py and the *_vs_cycles
# tests of its feature
SHADERS_ROW = ("| Shader | Principled BSDF (its Diffuse Roughness: Oren-Nayar; Anisotropic "
               "along its Tangent, tests/test_anisotropic_vs_cycles.py; Thin Film, "
               "tests/test_thin_film_vs_cycles.py), Diffuse "
               "BSDF (Roughness: Oren-Nayar), Glossy BSDF (Anisotropy), Glass BSDF, "
               "Refraction BSDF (GGX, Multiscatter GGX, Beckmann), Metallic BSDF (F82 Tint, "
               "Anisotropy; a "
               "Physical Conductor as its F82-tint fit), Sheen BSDF, "
               "Translucent BSDF, Emission, Transparent BSDF, Holdout (as the whole "
               "Surface, or mixed: a hole of its weight in the camera's alpha), "
               "Mix Shader, Add Shader; "
               "Principled Volume, Volume Scatter, Volume Absorption, Volume "
               "Coefficients; in a world, Background, Emission, Mix Shader and Add "
               "Shader, or a colour or value linked straight into its Surface |")


def program_cost(size=64, spp=16, repeats=3):
    """(seconds without, with a program): the Cornell box rendered by the engine with its
    white material plain, then driven by a 5-operation program (checker colour and
    roughness), best of `repeats` after a warm-up."""
    import time

    from engine import RenderSettings, render
    from test_shader_programs import _box
    settings = RenderSettings(samples=spp, max_bounces=4)
    out = []
    for with_program in (False, True):
        scene = _box(with_program)
        scene.width = scene.height = size
        render(scene, RenderSettings(samples=1))
        best = float("inf")
        for _ in range(repeats):
            t0 = time.perf_counter()
            render(scene, settings)
            best = min(best, time.perf_counter() - t0)
        out.append(best)
    return out


def main():
    import bpy

    import drt_addon
    import node_probe
    from test_nodes_vs_cycles import FAMILIES, SAMPLES, SPHERE_SAMPLES, TILES
    drt_addon.register()
    lines = [INTRO, "## Supported nodes", ""] + supported_nodes(bpy) + [""]
    with tempfile.TemporaryDirectory() as tmp:
        for family, (cases, shape) in FAMILIES.items():
            tile = TILES.get(family, node_probe.TILE)
            scene, columns, rows = node_probe.build_scene(bpy, cases, shape=shape, tile=tile)
            spp = SPHERE_SAMPLES if shape == "sphere" else SAMPLES
            imgs, pngs = {}, []
            for engine in ("DRT", "CYCLES"):
                imgs[engine] = node_probe.render(bpy, scene, engine, spp)
                pngs.append(os.path.join(tmp, f"{family}_{engine}.png"))
                save_png(bpy, scene, pngs[-1])
            out = os.path.join(IMAGES, f"nodes_{family}.png")
            side_by_side(pngs, [f"DRT {spp} spp", f"Cycles {spp} spp"], out)
            drt = node_probe.tiles(imgs["DRT"], columns, rows, tile)
            cyc = node_probe.tiles(imgs["CYCLES"], columns, rows, tile)
            lines += [f"## {family.replace('_', ' ')}", "",
                      f"![{family}: DRT left, Cycles right](images/nodes_{family}.png)", "",
                      "| tile (row, column) | case | mean | pixels | largest block |",
                      "|---|---|---|---|---|"]
            for k, (name, _) in enumerate(cases):
                mean, mad, block = node_probe.tile_errors(drt[k], cyc[k])
                lines.append(f"| {k // columns + 1}, {k % columns + 1} | {name} | "
                             f"{100 * mean:.2f}% | {100 * mad:.2f}% | {100 * block:.2f}% |")
            lines.append("")
            print(family, "done", flush=True)
    plain, programmed = program_cost()
    lines += ["## Cost", "",
              f"The Cornell box at 64 x 64 pixels, 16 samples, 4 bounces: {plain:.2f} s with "
              f"plain materials, {programmed:.2f} s when the white material (the floor, "
              f"ceiling, back wall and blocks) runs a 5-operation program at every hit "
              f"(checker colour and roughness): {100 * (programmed / plain - 1):+.0f}%. A "
              f"scene without programs runs none of this: no per-hit context, no object "
              f"table, no tangents or colour attributes "
              f"(`tests/test_shader_programs.py`).", ""]
    lines.append(KNOWN)
    with open(os.path.join(DOCS, "nodes.md"), "w") as f:
        f.write("\n".join(lines))


if __name__ == "__main__":
    main()
