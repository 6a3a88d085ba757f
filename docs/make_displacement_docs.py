"""Renders the displacement scene (sample_blends/displacement.blend) and the plane of
tests/test_displacement_vs_cycles.py with DRT and with Cycles, and writes
docs/displacement.md: the comparisons the tests make, their controls, what moving the
vertices costs the export, and larger images side by side at equal samples.

    .venv/bin/python docs/make_displacement_docs.py

Takes about 10 minutes on 2 cores.
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
BLEND = os.path.join(ROOT, "sample_blends", "displacement.blend")

from make_comparisons import pct, render, side_by_side  # noqa: E402
from test_artist_scenes_vs_cycles import _block_mad  # noqa: E402
from test_multiscatter_vs_cycles import compare  # noqa: E402
from test_displacement_vs_cycles import (PLANE_CASES, SAMPLES, SCENE_CYCLES_SAMPLES,  # noqa
                                         SCENE_DRT_SAMPLES, _adaptive_plane, _export,
                                         _normal_map, _plane_scene, _tilted_faces_scene)

METHODS = {"DISPLACEMENT": "Displacement Only", "BOTH": "Displacement and Bump"}
BIG = 300                 # percent: 192 x 144 pixels
BIG_SAMPLES = 256


def _bump_only(scene):
    import bpy
    for m in bpy.data.materials:
        m.displacement_method = "BUMP"


def _plane_rows(bpy):
    import node_probe
    from node_probe import image_errors
    rows = []
    for method, coordinates, vector, flat, _, _ in PLANE_CASES:
        scene, mat = _plane_scene(bpy, method, coordinates, vector, flat)
        cycles = node_probe.render(bpy, scene, "CYCLES", SAMPLES)
        mean, block = image_errors(node_probe.render(bpy, scene, "DRT", SAMPLES), cycles)
        mat.displacement_method = "BUMP"
        c_mean, c_block = image_errors(node_probe.render(bpy, scene, "DRT", SAMPLES), cycles)
        node = "Vector Displacement (Tangent)" if vector else "Displacement (Object)"
        node += ", flat shaded" if flat else ""
        rows.append(f"| {METHODS[method]} | {node} | "
                    f"{coordinates or 'Generated'} | {mean:.2%} | {block:.2%} | "
                    f"{c_mean:.2%} | {c_block:.2%} |")
    return rows


def _normal_map_rows(bpy):
    """The Normal Map cases, DRT against Cycles: the tests' two (the tilted flat cube,
    the plane as Bump Only), the gap (the plane with true displacement), and the tube's
    four (tests/test_normal_map_vs_cycles.py)."""
    import node_probe
    from node_probe import image_errors
    cases = [("a flat cube displaced by a constant (edge quads tilted), Displacement and "
              "Bump", _tilted_faces_scene, 4 * SAMPLES)]
    for method in ("BUMP", "BOTH", "DISPLACEMENT"):
        def build(bpy, method=method):
            scene, mat = _plane_scene(bpy, method)
            _normal_map(mat.node_tree)
            return scene
        label = METHODS.get(method, "Bump Only")
        cases.append((f"the plane, {label}", build, SAMPLES))
    from test_normal_map_vs_cycles import CASES, SAMPLES as TUBE_SAMPLES, _tube_scene
    tube = ("a 32-sided tube, an n-gon cap at one end, smooth, scaled 4 x along its "
            "axis")
    labels = {"uv_map": f"{tube}, Bump Only",
              "no_uv_map": f"{tube}, no UV map, Bump Only",
              "true_displacement": f"{tube}, Displacement and Bump at the mid-level",
              "true_displacement_without_map": f"{tube}, Displacement and Bump at the "
                                               "mid-level, no Normal Map"}
    for case in ("uv_map", "no_uv_map", "true_displacement",
                 "true_displacement_without_map"):
        cases.append((labels[case], lambda bpy, c=case: _tube_scene(bpy, **CASES[c]),
                      TUBE_SAMPLES))
    rows = []
    for label, build, spp in cases:
        scene = build(bpy)
        cycles = node_probe.render(bpy, scene, "CYCLES", spp)
        mean, block = image_errors(node_probe.render(bpy, scene, "DRT", spp), cycles)
        rows.append(f"| {label} | {spp} | {mean:.2%} | {block:.2%} |")
    return rows


def _adaptive(bpy, tmp):
    """The adaptive plane of the tests: its comparison, its control at the render levels,
    the export's triangles and seconds both ways, and a larger image of each."""
    import node_probe
    from node_probe import image_errors
    out = {}
    scene, mat, mod = _adaptive_plane(bpy, "BOTH")
    cycles = node_probe.render(bpy, scene, "CYCLES", SAMPLES)
    for adaptive in (True, False):
        mod.use_adaptive_subdivision = adaptive
        mean, block = image_errors(node_probe.render(bpy, scene, "DRT", SAMPLES), cycles)
        best = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            _, stats, _ = _export(bpy)
            best = min(best, time.perf_counter() - t0)
        out[adaptive] = (mean, block, stats["triangles"], best)
    mod.use_adaptive_subdivision = True
    scene.render.resolution_x = scene.render.resolution_y = 288
    path = os.path.join(tmp, "adaptive.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    pngs, captions = [], []
    for engine, adaptive, label in (("DRT", True, "DRT, adaptive"),
                                    ("CYCLES", True, "Cycles, adaptive"),
                                    ("DRT", False, "DRT at the render levels")):
        def setup(scene, adaptive=adaptive):
            bpy.data.objects["Plane"].modifiers["Subdivision"].use_adaptive_subdivision = \
                adaptive
        png = os.path.join(tmp, f"adaptive_{engine}_{adaptive}.png")
        _, seconds = render(bpy, path, engine, BIG_SAMPLES, setup=setup, png=png)
        pngs.append(png)
        captions.append(f"{label}, {BIG_SAMPLES} spp, {seconds:.0f} s")
    side_by_side(pngs, captions, os.path.join(IMAGES, "displacement_adaptive.png"))
    return out


def _export_seconds(bpy, method, repeats=3):
    """The export's seconds for the scene with every material's method set to `method`
    (None: the file's; best of `repeats`), the meshes moved and the triangles, with the
    Subdivision modifiers at their render levels (as a render evaluates them)."""
    from drt_addon.export import export_scene
    bpy.ops.wm.open_mainfile(filepath=BLEND, load_ui=False)
    for m in bpy.data.materials:
        m.displacement_method = m.displacement_method if method is None else method
    for obj in bpy.data.objects:
        for mod in obj.modifiers:
            if mod.type == "SUBSURF":
                mod.levels = mod.render_levels
    best, stats = float("inf"), {}
    for _ in range(repeats):
        stats = {}
        t0 = time.perf_counter()
        scene = export_scene(bpy.context.evaluated_depsgraph_get(), stats=stats)
        best = min(best, time.perf_counter() - t0)
    return best, stats["displaced_meshes"], scene.triangle_count()


def main() -> int:
    import bpy

    import drt_addon
    drt_addon.register()
    render(bpy, BLEND, "DRT", 1)                 # kernels loaded (or compiled) before timing
    cycles, t_cycles = render(bpy, BLEND, "CYCLES", SCENE_CYCLES_SAMPLES)
    drt, t_drt = render(bpy, BLEND, "DRT", SCENE_DRT_SAMPLES)
    control, _ = render(bpy, BLEND, "DRT", 128, setup=_bump_only)
    rows = []
    for label, img in (("DRT", drt), ("control: both materials as Bump Only, DRT 128",
                                       control)):
        means, block = compare(img, cycles)
        rows.append(f"| {label} | {pct(means)} | {block:.2%} | {_block_mad(img, cycles):.2%} |")
    moved, n_moved, tris = _export_seconds(bpy, None)
    flat, n_flat, _ = _export_seconds(bpy, "BUMP")
    plane_rows = _plane_rows(bpy)
    normal_map_rows = _normal_map_rows(bpy)
    with tempfile.TemporaryDirectory() as tmp:
        adaptive = _adaptive(bpy, tmp)
        pngs, times = {}, {}
        for engine in ("DRT", "CYCLES"):
            png = os.path.join(tmp, f"{engine}.png")
            _, times[engine] = render(bpy, BLEND, engine, BIG_SAMPLES, percentage=BIG,
                                      png=png)
            pngs[engine] = png
        out = os.path.join(IMAGES, "displacement.png")
        side_by_side([pngs["DRT"], pngs["CYCLES"]],
                     [f"DRT {BIG_SAMPLES} spp, {times['DRT']:.0f} s",
                      f"Cycles {BIG_SAMPLES} spp, {times['CYCLES']:.0f} s"], out)
    text = f"""# Displacement

DRT renders Material > Settings > Displacement as Cycles does:

- **Bump Only** (Blender's default) bends the shading normal as a Bump of the
  displacement's height would, and sets it as the surface's own normal (Cycles' Set
  Normal): the surface does not move.
- **Displacement Only** moves the mesh's vertices by the material's displacement before
  the acceleration structure is built (`engine/displacement.py`, as Cycles'
  `GeometryManager::displace`). Each vertex moves once, read at the first triangle that
  uses it, with the vertex's smooth normal. The moved triangles get new normals by
  Cycles' rule. The surface still reads its Generated coordinates where it was before
  it moved, as Cycles reads its generated attribute.
- **Displacement and Bump** moves the vertices and keeps their undisplaced normals. The
  bump is then worked out on the undisplaced surface and in the object's space, as in
  Cycles. On flat-shaded faces it starts from the undisplaced vertex normals, as
  Cycles' does.

The Displacement node (Object and World space) and the Vector Displacement node
(Tangent, Object and World space) are evaluated. Any other vector linked to the socket
is a world-space offset. The vertices come from the file's Subdivision modifier at its
render levels. With motion blur, a deforming mesh carries the same offsets at every time
step, as in Cycles.

![DRT and Cycles](images/displacement.png)

`sample_blends/displacement.blend`: a cobbled path at sunset. A Voronoi Texture through a
Color Ramp displaces a plane with a Simple Subdivision modifier (7 levels at render),
Displacement Only. A rock (a UV sphere, Subdivision level 2, scaled 1.3 x 1 x 0.8) is
displaced by a Noise Texture, Displacement and Bump. A low warm sun, a cool area fill
lamp and a dim sky light them. The scene uses Blender's defaults. The images are {BIG}%
of the file's 64 x 48 pixels, at {BIG_SAMPLES} samples in both engines, rendered on this
machine's 2 cores.

## Against Cycles

The test's comparison is DRT {SCENE_DRT_SAMPLES} samples against Cycles
{SCENE_CYCLES_SAMPLES}, at 64 x 48 pixels. It allows 1 % on each channel mean and 3 % on
any 8 x 8 block. The control renders both materials as Bump Only, which is what DRT did
before, and it must fail.

| render | mean per channel | worst 8 x 8 block | block MAD |
|---|---|---|---|
{chr(10).join(rows)}

Render times at 64 x 48: DRT {t_drt:.1f} s ({SCENE_DRT_SAMPLES} samples), Cycles
{t_cycles:.1f} s ({SCENE_CYCLES_SAMPLES} samples).

The plane of `tests/test_displacement_vs_cycles.py`: a 6 m plane (Simple Subdivision, 7
levels), scaled 1 x 0.8 x 1.2 and turned, displaced by a Noise Texture (Scale 0.5) and
coloured by the same noise, under a low sun. DRT and Cycles at {SAMPLES} samples, 96 x 96.
The errors are of the image mean; the test allows 1 % on the mean and 3 % on a block.
The last two columns are the same material rendered as Bump Only (the control, which
must be off by more than 10 % on some block).

| method | node | texture coordinates | mean | worst block | Bump Only: mean | Bump Only: worst block |
|---|---|---|---|---|---|---|
{chr(10).join(plane_rows)}

## Normal Maps with displacement

A tangent-space Normal Map is worked out in the object's space, as Cycles does (the
normal by the object's matrix transposed, the tangent by its inverse, the result back by
the inverse transpose; an unevenly scaled object's frame differs in the world), on the
tangent and smooth normal interpolated there and not normalised. The tangents are
MikkTSpace's as Cycles computes them (`drt_addon/export/mikktspace.py`): on the render
triangles, so n-gons have them, from the UV map, or on a mesh without one from
map_to_sphere of the object-space positions (u differences taken around its wrap). A mesh
that true displacement moves stays in its object space in Cycles, so its smooth normals
are interpolated there before they reach the world, with or without a map. On a face
shaded flat it builds on the face's own normal, not on the undisplaced vertex normals
Displacement and Bump leaves such a face. Its Strength scales the colour's x and y and
mixes its z from 1. A shader with a Normal of its own keeps it for its lobes while the
Displacement socket's bump still sets the surface's own normal (Cycles' Set Normal),
against which those lobes are shadowed. The Normal Map below: on the cube and the plane a
constant colour whose 2c - 1 is not of unit length, Strength 0.6; on the tube (from
OddBitWizard's tunnel.blend) one that tilts the normal far, Strength 1; into the
Principled BSDF's Normal.

| scene | samples | mean | worst block |
|---|---|---|---|
{chr(10).join(normal_map_rows)}

**Not matched yet:** a Normal Map on a smooth surface that true displacement moves (the
plane's last two rows). Cycles' map output there follows the bumps, and with Displacement and
Bump the surface's own normal (Geometry > Normal, read by an AOV) equals the map's output
exactly; DRT builds the map on the undisplaced normal (Displacement and Bump) or the
moved one (Displacement Only), and the two engines' images differ along the bumps, with
opposite signs in the two modes. Read by Attribute nodes, Cycles' own undisplaced_N and
undisplaced_tangent (what its Normal Map reads) are constant on the plane, and DRT's
map output is the one they give, the same at every point; Cycles' varies with the bumps,
nearly alike in both modes. The cause is not found yet.

## Adaptive subdivision

A mesh whose last modifier is a Subdivision modifier with Adaptive Subdivision on is
diced as Cycles dices it, before it is displaced (`engine/dicing.py`,
`drt_addon/export/dicing.py`): each edge is cut into segments of the modifier's Pixel
Size times Render > Subdivision > Dicing Rate on screen (Viewport in the Rendered
viewport), as seen from the Dicing Camera or the scene's camera, coarser off screen by
the Offscreen Scale, or into segments of its Edge Length in Object space, at most
2 ^ Max Subdivisions per edge of the cage (Cycles' rule, sampled at three points along
the edge). Each triangle is then tessellated by its three edges' own factors: a regular
grid where they agree, otherwise a regular interior grid stitched to each edge's points,
so neighbours share their edge's points and the mesh stays watertight
(`tests/test_dicing.py` checks every factor triple up to 10 and random ones up to 70). A
mesh that nothing displaces is not diced: its surface would not change.

The plane above at render levels 2 (4 x 4 quads) with Adaptive Subdivision at Blender's
defaults (1 pixel), DRT and Cycles at {SAMPLES} samples, 96 x 96:

| DRT | mean | worst block | triangles | export |
|---|---|---|---|---|
| adaptive subdivision | {adaptive[True][0]:.2%} | {adaptive[True][1]:.2%} | {adaptive[True][2]:,} | {adaptive[True][3]:.2f} s |
| control: the render levels (what DRT rendered before) | {adaptive[False][0]:.2%} | {adaptive[False][1]:.2%} | {adaptive[False][2]:,} | {adaptive[False][3]:.2f} s |

![Adaptive subdivision](images/displacement_adaptive.png)

The same plane at 288 x 288 pixels (so diced three times finer), {BIG_SAMPLES} samples.

## What it costs

Moving the vertices runs once per mesh at export: the displacement's own node program
over the mesh's vertices, then the new normals, in NumPy. On the sample scene
({tris:,} triangles, {n_moved} meshes moved), the export takes {moved:.2f} s, against
{flat:.2f} s with both materials set to Bump Only ({n_flat} meshes moved). A mesh whose
materials do not move it reads no vertex normals and stores no undisplaced corners, and
a surface hit never runs the displacement's program
(`tests/test_displacement_vs_cycles.py::test_only_scenes_with_true_displacement_pay_for_it`).

## Not modelled

- Adaptive subdivision never dices coarser than the Subdivision modifier's render
  levels (Cycles starts from the cage, so a distant mesh may come out coarser there),
  and it refines the render levels' flat triangles: a Catmull-Clark surface between
  them is not evaluated (Cycles dices its limit surface).
- A Vector Displacement node's bump (Bump Only, or the bump of Displacement and Bump):
  the node is evaluated for moving vertices only.

Written by `docs/make_displacement_docs.py`.
"""
    with open(os.path.join(DOCS, "displacement.md"), "w") as f:
        f.write(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
