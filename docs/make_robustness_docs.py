"""Measures how DRT behaves at the extremes and writes docs/robustness_extremes.md.

    .venv/bin/python docs/make_robustness_docs.py [--cases 500]

- scale and position: the Cornell box scaled by 1e-3 .. 1e4 and moved 1e3 .. 1e8 from the
  origin, each against the unit scene by the per-pixel z-test of
  tests/extreme_checks.py (the settings of tests/test_extremes_scale.py);
- materials at their limits in the white furnace (tests/test_extremes_materials.py);
- property-based fuzzing over Blender's RNA ranges (tests/fuzz_renders.py), --cases
  cases, with the count of NaN/Inf, negative and crashing renders.
Takes about 2 minutes on 2 cores.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests")]
OUT = os.path.join(ROOT, "docs", "robustness_extremes.md")


def scale_rows():
    import copy

    import numpy as np

    from engine import TriangleMesh
    from engine_scenes import scaled, translated
    from extreme_checks import z_test
    from test_extremes_scale import MEAN_Z, PASS_RATE, SIZE, _render
    from engine_scenes import cornell_box
    scene = cornell_box(SIZE, SIZE, light_size=1.0)
    ref = _render(scene, seed=1)
    rows = []
    for s in (1e-3, 1.0, 1e2, 1e4):
        rows.append((f"scaled by {s:g}", z_test(_render(scaled(scene, s), seed=2), ref)))
    for d in (1e3, 1e4, 1e5, 1e6, 1e7, 1e8):
        rows.append((f"moved by ({d:g}, -{d:g}, {d:g})",
                     z_test(_render(translated(scene, (d, -d, d)), seed=2), ref)))
    n_box = sum(len(m.positions) for m in scene.meshes)
    for d in (1e2, 1e3, 1e4, 1e5, 1e6):
        # what sets the precision is the distance from the scene's median vertex: specks
        # d away (out of view) with twice the box's vertices move it there
        far = copy.deepcopy(scene)
        k = np.arange(2 * n_box // 3 + 1)[:, None, None]
        tri = np.array([[0, 0, 0], [0.01, 0, 0], [0, 0.01, 0]]) + (d, d, 0) + k * (0.1, 0, 0)
        far.meshes.append(TriangleMesh("specks", tri.reshape(-1, 3),
                                       np.arange(tri.size // 3).reshape(-1, 3), 0))
        rows.append((f"with {len(tri)} specks {d:g} away", z_test(_render(far, seed=2), ref)))
    brighter = copy.deepcopy(scene)
    brighter.lights[0].strength = tuple(np.asarray(brighter.lights[0].strength) * 1.1)
    rows.append(("control: the light 10% brighter", z_test(_render(brighter, seed=2), ref)))
    lines = ["| scene | pixels with \\|z\\| < 3 | mean z | image mean vs unit | passes |",
             "|---|---|---|---|---|"]
    for name, z in rows:
        ok = z.pass_rate >= PASS_RATE and abs(z.mean_z) < MEAN_Z
        lines.append(f"| {name} | {100 * z.pass_rate:.1f}% | {z.mean_z:+.3f} | "
                     f"{100 * z.rel_mean:+.2f}% | {'yes' if ok else 'NO'} |")
    return "\n".join(lines)


def furnace_rows():
    from test_extremes_materials import LIMITS, WHITE, _furnace, _mean_and_error
    from engine import Material
    from extreme_checks import sane
    lines = ["| material | furnace mean (<= 1) | finite, non-negative |", "|---|---|---|"]
    for name, kw in LIMITS.items():
        film, stats = _furnace(Material(name, **{"base_color": WHITE, **kw}))
        mean, se = _mean_and_error(film)
        lines.append(f"| {name} | {mean:.4f} +- {se:.4f} | "
                     f"{'yes' if not sane(film, stats) else ', '.join(sane(film, stats))} |")
    return "\n".join(lines)


def fuzz_summary(cases):
    import bpy

    import drt_addon
    import fuzz_renders
    drt_addon.register()
    t0 = time.perf_counter()
    counts, failures = fuzz_renders.run(bpy, cases, seed=0, verbose=False)
    seconds = time.perf_counter() - t0
    params = fuzz_renders.blender_ranges(bpy)
    total = counts["ok"] + len(failures)
    text = (f"{total} cases (seed 0, {fuzz_renders.SIZE} x {fuzz_renders.SIZE} pixels, "
            f"{fuzz_renders.SAMPLES} samples, {seconds:.0f} s): **{counts['nonfinite']} with "
            f"NaN/Inf samples, {counts['negative']} with negative pixels, {counts['crash']} "
            f"crashes**.")
    for case, problems in failures[:10]:
        text += f"\n- {problems}: {fuzz_renders.describe(case)}"
    rows = ["| owner | property | range fuzzed |", "|---|---|---|"]
    for p in params:
        rng = (", ".join(p.choices) if p.kind == "enum" else "on / off" if p.kind == "bool"
               else f"{p.lo:.4g} .. {p.hi:.4g}")
        lamp = f" ({p.only_for} lamps)" if p.only_for else ""
        rows.append(f"| {p.owner} | {p.name}{lamp} | {rng} |")
    return text, "\n".join(rows)


TEMPLATE = """# Robustness: extreme inputs

What DRT does with the scenes at the edges of what Blender allows. Every number below is
printed by `docs/make_robustness_docs.py`; each item is also a test in CI (named beside
it).

## Scale and distance from the origin

The Cornell box (1 m light, direct and indirect light, 24 x 24 pixels, 64 samples of the
*random* sampler) scaled (lengths times s, light power times s^2, so the same radiance)
and moved away from the world origin (camera and lights too), each rendered with other
random numbers than the unit scene and compared pixel by pixel: z = difference of the
two pixel means over its estimated standard deviation. The unit scene against itself
gives the noise floor. A test passes with at least 95% of pixels |z| < 3 and |mean z| <
0.15 (`tests/test_extremes_scale.py`); the last row shows that the test does see a 10%
brighter light.

{scale}

How: Embree traces in float32, whose spacing at 1e5 is 0.008. DRT keeps geometry in
float64, rebuilds hit points in float64, and uploads the static scene to Embree relative
to its median vertex, moving every ray origin by the same amount in float64 before
rounding. A ray leaving a surface starts on it and names the triangle it leaves, which
Embree's filter passes (`engine/embree/self_hits.py`, as Cycles starts its rays): there
is no offset to grow with the coordinates. So a compact scene far from the origin keeps
the precision it has at the origin. The limit that remains is the distance of detail from
the median vertex: the rows "with specks" add, out of view, twice as many vertices as the
box has (1 cm triangles) that far away, which moves the median vertex there; where they
fail, the box's 2 m of detail has become too fine for float32 at that distance (float32
spacing against a 2 m box). A few far vertices do not move the median (a vertex at
3.4e38 in `tests/test_degenerate_input.py`). Moving objects (motion blur) are traced in
their own object spaces.

Acne and leaks at every scale (`tests/test_robustness.py`, scales 1e-3, 1, 1e2, 1e4):
a plane under a sun at 85 degrees has no self-shadowed pixel; a closed box with walls 1%
or 0.01% of its size thick lets no light in; a sheet 1e-4 or 2e-6 of its size above a
table leaves it black (2e-6 leaked before 2026-11-30, when rays started 2^-17 of the
coordinates' magnitude off the surface); an opaque sheet 2e-6 of its size under an
emissive panel leaves the table under them black (shadow rays towards an emitting
triangle name it, as Cycles' do, and stop 2^-21 of the point's magnitude over the cosine
short of it; until 2026-11-30 they stopped 2^-17 short, before the sheet, and lit the
table at every scale).
The plane and a box with walls 1e-3 thick also 1e5 and 1e7 from the origin
(`tests/test_extremes_scale.py`; before the median-vertex origin, the box let light in
at 1e5 and 37.5% of the plane's pixels were self-shadowed at 1e7).

## Materials at their limits

A sphere under a uniform white world (radiance 1) with no lamps: an energy-conserving
BSDF reflects at most 1 (the mean over the pixels inside the sphere's outline, 16 x 16
pixels, 16 samples; `tests/test_extremes_materials.py`). Blinn-Phong exponent 1e6 is
roughness (2 / (1e6 + 2))^(1/4) = 0.0376 with the Blinn-Phong glossy model.

{furnace}

An emission strength of 1e6 is seen as exactly 1e6 (plus at most the 1 it reflects).
Grazing: a camera 1 mm above a 10 km plane, looking 0.01 degrees below the horizon, sees
the plane reflect at most the white world (diffuse, mirror, glossy, multiscatter,
Blinn-Phong 1e6 and rough glass); a sun 0.1 degrees above the horizon lights a diffuse
plane to rho / pi E cos(89.9 deg) in every pixel to 1e-6 (no acne).

## Cameras at their limits

`tests/test_extremes_camera_geometry.py`: f/0.01 (a 1.75 m aperture at 35 mm) focused at
3 m or 1e6 m and f/1e4 keep a uniformly lit plane exact to 1e-9 in every pixel (depth of
field only moves light between pixels); f/1e4 renders as the pinhole within 3%. Focus
distance 1e-4 m renders the world alone, as Cycles does (measured with the default
scene: both give the world colour in every pixel). Lens 1 mm (a 172-degree view) and
5000 mm, orthographic scale 1e-3 and 1e4, resolutions 1 x 1, 1 x 4096 and 4096 x 1 render
finite, non-negative images. A clip end not beyond the clip start, or an orthographic
scale of 0, renders the world alone, as in Cycles (they stopped the render with an error
before the fuzzer found them; `tests/test_fuzz_renders.py`).

## Geometry at its limits

Needle triangles (1 m by 1e-9 m), a vertex used twice in a triangle, a triangle doubled,
a 1e-7 m triangle, a mesh with vertices but no faces and a cube scaled to a point change
nothing measurable; a cube scaled to zero height renders as the square it has become
(within 1%). An emissive triangle of zero area adds no light and no NaN. Lights of zero
size render as their limits (to 1e-3): a point light of radius 0 and the smallest spot
cone give S / (4 pi d^2) rho / pi; an area light of 1e-9 m, square or disk, four times
that straight below it (a one-sided cosine emitter of the same power); a sun of angle 0
rho / pi E. An area lamp of size exactly 0 is skipped with a warning, as Cycles does
(`tests/test_degenerate_input.py`); NaN and infinite vertices are dropped with their
triangles, with one warning per object.

## Property-based fuzzing

`tests/fuzz_renders.py` builds a floor, a sphere, one lamp, a camera and a world in
Blender and draws every parameter below with `hypothesis` from the range Blender's RNA
gives it (`hard_min` .. `hard_max`, read when the fuzzer runs; where that range includes
negative powers or strengths it draws from 0, since negative light is negative in Cycles
too). Each case is exported and rendered at 8 x 8 pixels, 2 samples; a case fails when
the export or render raises, a sample is NaN or infinite, or a pixel is negative. CI runs
20 derandomised examples (`tests/test_fuzz_renders.py`); `python
tests/fuzz_renders.py --cases 500` runs more and lists the failing cases.

{fuzz}

What the fuzzer found and is now fixed, each a named test in `tests/test_fuzz_renders.py`:
a clip end not beyond the clip start and an orthographic scale of 0 stopped the render
with an error (Cycles renders the world); a base colour of 3.8e20 under a world of
radiance 8.7e75 overflowed float64 over the bounces, and the clamp turned the infinite
contributions into NaN (a path whose throughput overflows now ends, and an infinite
contribution clamps to the clamp value).

The ranges fuzzed:

{ranges}
"""


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", type=int, default=500)
    args = ap.parse_args(argv)
    scale = scale_rows()
    print(scale, flush=True)
    furnace = furnace_rows()
    print(furnace, flush=True)
    fuzz, ranges = fuzz_summary(args.cases)
    print(fuzz, flush=True)
    with open(OUT, "w") as f:
        f.write(TEMPLATE.format(scale=scale, furnace=furnace, fuzz=fuzz, ranges=ranges))
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
