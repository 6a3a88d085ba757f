"""DRT's light passes and light groups against Cycles' on public .blend files made by
others, and writes docs/public_passes.md.

Each file is opened as its author saved it, its longest side scaled to 160 px, 64
samples in both engines (no denoising, no adaptive sampling), every light pass on, and
light groups made for it: one per lamp, "objects" for every object (emissive meshes),
"sky" for the world. Per pass: both engines' image means and their difference relative
to Combined's mean; and DRT's own identities on the file: the passes recompose Combined
((Direct + Indirect) x Color per kind, plus Volume, Emission, Environment) and the
groups sum to it (largest absolute difference per pixel).

    .venv/bin/python docs/public_passes.py --source github:OWNER/REPO@COMMIT FILE.blend ...

The files are not part of this repository (fetch them as docs/public_files.py says).
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests")]
PAGE = os.path.join(ROOT, "docs", "public_passes.md")
SAMPLES = 64
KINDS = ("Diffuse", "Glossy", "Transmission")
LIGHT = [f"{k} {p}" for k in KINDS for p in ("Direct", "Indirect", "Color")] + [
    "Volume Direct", "Volume Indirect", "Emission", "Environment"]


def _open(bpy, path):
    """Open `path` with every light pass on and a light group per lamp, "objects" and
    "sky"; returns (scene, the Combined_<group> pass names)."""
    bpy.ops.wm.open_mainfile(filepath=path, load_ui=False)
    scene = bpy.context.scene
    r = scene.render
    r.resolution_percentage = max(1, round(100 * 160 / max(r.resolution_x, r.resolution_y)))
    scene.cycles.samples = scene.drt.samples = SAMPLES
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    layer = bpy.context.view_layer
    for kind in ("diffuse", "glossy", "transmission"):
        for part in ("direct", "indirect", "color"):
            setattr(layer, f"use_pass_{kind}_{part}", True)
    layer.cycles.use_pass_volume_direct = layer.cycles.use_pass_volume_indirect = True
    layer.use_pass_emit = layer.use_pass_environment = True
    layer.lightgroups.add(name="objects")
    for obj in scene.objects:
        if obj.type == "LIGHT" and not obj.hide_render:
            name = "L_" + "".join(c if c.isalnum() else "_" for c in obj.name)[:20]
            layer.lightgroups.add(name=name)
            obj.lightgroup = name
        elif obj.type in ("MESH", "CURVE", "SURFACE", "META", "FONT", "CURVES", "VOLUME"):
            obj.lightgroup = "objects"
    if scene.world is not None:
        layer.lightgroups.add(name="sky")
        scene.world.lightgroup = "sky"
    return scene, ["Combined_" + g for g in layer.lightgroups.keys()]


def measure(bpy, path) -> dict:
    import light_pass_scene as lps
    scene, groups = _open(bpy, path)
    scene.render.engine, scene.cycles.device = "CYCLES", "CPU"
    t0 = time.perf_counter()
    cycles = lps.cycles_passes(bpy, scene, ["Image"] + LIGHT + groups)
    t_cycles = time.perf_counter() - t0
    _open(bpy, path)
    t0 = time.perf_counter()
    drt = lps.drt_passes(bpy, LIGHT + groups)
    t_drt = time.perf_counter() - t0
    scale = max(cycles["Image"].mean(), 1e-12)
    rows = [(n, drt[n].mean(), cycles[n].mean(), (drt[n].mean() - cycles[n].mean()) / scale)
            for n in ["Image"] + LIGHT + groups]
    rebuilt = sum((drt[f"{k} Direct"] + drt[f"{k} Indirect"]) * drt[f"{k} Color"]
                  for k in KINDS) + drt["Volume Direct"] + drt["Volume Indirect"] \
        + drt["Emission"] + drt["Environment"]
    return {"rows": rows, "size": drt["Image"].shape[:2], "seconds": (t_drt, t_cycles),
            "recompose": float(np.abs(rebuilt - drt["Image"]).max()),
            "groups": float(np.abs(sum(drt[g] for g in groups) - drt["Image"]).max())}


def write(source, results) -> None:
    lines = ["# Light passes on public files", "",
             "<!-- written by docs/public_passes.py; do not edit by hand -->", "",
             f"Files from `{source}`, as their authors saved them, {SAMPLES} samples in both "
             "engines, the longest side 160 px; every light pass on, a light group per lamp, "
             "`objects` (every object) and `sky` (the world). Differences are relative to "
             "Cycles' Combined mean. DRT's identities: the passes recompose Combined and the "
             "groups sum to it (largest difference per pixel). Known difference: Glossy Color "
             "of metals (the lobe's albedo: DRT averages Schlick's Fresnel over the visible "
             "normals by quadrature, Cycles reads a table), which moves Glossy Direct the "
             "other way; their product, the light, agrees ([passes.md](passes.md)).", ""]
    for name, m in results.items():
        t_drt, t_cycles = m["seconds"]
        lines += [f"## {name}", "",
                  f"{m['size'][1]} x {m['size'][0]} px; DRT {t_drt:.1f} s, Cycles "
                  f"{t_cycles:.1f} s; recomposed Combined within {m['recompose']:.1e}, "
                  f"groups within {m['groups']:.1e}.", "",
                  "| pass | DRT | Cycles | difference |", "|---|---|---|---|"]
        lines += [f"| {n} | {a:.4f} | {b:.4f} | {d:+.4f} |" for n, a, b, d in m["rows"]]
        lines.append("")
    with open(PAGE, "w") as f:
        f.write("\n".join(lines))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", required=True, help="where the files come from")
    parser.add_argument("files", nargs="+")
    args = parser.parse_args()
    import bpy
    import drt_addon
    drt_addon.register()
    results = {}
    for path in args.files:
        name = os.path.basename(path)
        results[name] = measure(bpy, path)
        for n, a, b, d in results[name]["rows"]:
            print(f"{name}: {n:28s} DRT {a:.4f} Cycles {b:.4f} difference {d:+.4f}")
        print(f"{name}: recomposed within {results[name]['recompose']:.1e}, groups within "
              f"{results[name]['groups']:.1e}")
    write(args.source, results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
