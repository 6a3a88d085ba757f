"""Property-based fuzzing of whole renders over the parameter ranges Blender allows.

A small Blender scene (a floor, a sphere, one lamp, a camera, a world) is built with bpy;
each case sets the sphere's and floor's Principled BSDF inputs, the lamp (its type too),
the camera and the world to values drawn by `hypothesis` from the ranges Blender's RNA
gives (`bl_rna.properties[...].hard_min / hard_max` of the lamp, camera and depth of
field properties, and of the node sockets' `default_value`), read at run time, so the
fuzzer follows Blender when Blender changes. The scene is exported by DRT's exporter
and rendered by the engine at 8 x 8 pixels, 2 samples. A case fails when the export or
render raises, when a sample is NaN or infinite (the renderer zeroes and counts those)
or when a pixel is negative.

Where the RNA range includes negative values (a lamp's Power, the world's Strength, the
Principled BSDF's unbounded float inputs such as IOR and Emission Strength), the fuzzer
draws from [0, hard_max]: a negative power is negative light in Cycles as in DRT, not a
robustness failure.

    .venv/bin/python tests/fuzz_renders.py --cases 500 [--seed 0]

prints the count of cases with NaN/Inf samples, negative pixels and crashes (and the
parameters of each failing case) and exits 1 if there was any. tests/test_fuzz_renders.py
runs a few derandomised examples in CI.
"""
from __future__ import annotations

import argparse
import os
import sys
from collections import Counter
from dataclasses import dataclass

TESTS = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(TESTS)
for _p in (ROOT, TESTS):
    if _p not in sys.path:
        sys.path.insert(0, _p)

from hypothesis import strategies as st  # noqa: E402

from extreme_checks import sane  # noqa: E402

SIZE, SAMPLES = 8, 2
LIGHT_TYPES = ("POINT", "SPOT", "SUN", "AREA")


@dataclass(frozen=True)
class Param:
    """One fuzzed property: where it lives ('material', 'light', 'camera', 'dof',
    'world'), its name, its kind ('float', 'color', 'enum', 'bool', 'int') and range."""
    owner: str
    name: str
    kind: str
    lo: float = 0.0
    hi: float = 1.0
    choices: tuple = ()
    only_for: str = ""        # a lamp type the property belongs to ('' = all)


def _rna(bpy_type, name):
    return bpy_type.bl_rna.properties[name]


def _float_param(owner, bpy_type, name, non_negative=False, only_for=""):
    p = _rna(bpy_type, name)
    lo = max(p.hard_min, 0.0) if non_negative else p.hard_min
    kind = "color" if getattr(p, "array_length", 0) >= 3 else "float"
    return Param(owner, name, kind, lo, p.hard_max, only_for=only_for)


def _enum_param(owner, bpy_type, name, only_for=""):
    items = tuple(i.identifier for i in _rna(bpy_type, name).enum_items)
    return Param(owner, name, "enum", choices=items, only_for=only_for)


def _socket_param(owner, socket):
    p = socket.bl_rna.properties["default_value"]
    kind = "color" if socket.type == "RGBA" else "float"
    return Param(owner, socket.name, kind, max(p.hard_min, 0.0), p.hard_max)


def blender_ranges(bpy) -> list:
    """Every fuzzed property with its range, read from Blender's RNA now."""
    T = bpy.types
    params = []
    mat = bpy.data.materials.new("fuzz ranges")
    tree = mat.node_tree if mat.node_tree is not None else None
    if tree is None:
        mat.use_nodes = True
        tree = mat.node_tree
    bsdf = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    for s in bsdf.inputs:
        if s.type in ("VALUE", "RGBA") and s.name != "Weight":
            params.append(_socket_param("material", s))
    bpy.data.materials.remove(mat)
    world = bpy.data.worlds.new("fuzz ranges")
    if world.node_tree is None:
        world.use_nodes = True
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    params += [_socket_param("world", bg.inputs["Color"]),
               _socket_param("world", bg.inputs["Strength"])]
    bpy.data.worlds.remove(world)
    params.append(Param("light", "type", "enum", choices=LIGHT_TYPES))
    params += [_float_param("light", T.PointLight, "energy", non_negative=True),
               _float_param("light", T.PointLight, "color"),
               _float_param("light", T.PointLight, "exposure"),
               Param("light", "normalize", "bool"),
               _float_param("light", T.PointLight, "shadow_soft_size", only_for="POINT"),
               Param("light", "use_soft_falloff", "bool", only_for="POINT"),
               _float_param("light", T.SpotLight, "shadow_soft_size", only_for="SPOT"),
               _float_param("light", T.SpotLight, "spot_size", only_for="SPOT"),
               _float_param("light", T.SpotLight, "spot_blend", only_for="SPOT"),
               _float_param("light", T.SunLight, "angle", only_for="SUN"),
               _float_param("light", T.AreaLight, "size", only_for="AREA"),
               _float_param("light", T.AreaLight, "size_y", only_for="AREA"),
               _float_param("light", T.AreaLight, "spread", only_for="AREA"),
               _enum_param("light", T.AreaLight, "shape", only_for="AREA")]
    params.append(Param("camera", "type", "enum", choices=("PERSP", "ORTHO")))
    params += [_float_param("camera", T.Camera, n) for n in
               ("lens", "ortho_scale", "clip_start", "clip_end", "shift_x", "shift_y",
                "sensor_width", "sensor_height")]
    params.append(_enum_param("camera", T.Camera, "sensor_fit"))
    params.append(Param("dof", "use_dof", "bool"))
    params += [_float_param("dof", T.CameraDOFSettings, n) for n in
               ("aperture_fstop", "focus_distance", "aperture_rotation", "aperture_ratio")]
    blades = _rna(T.CameraDOFSettings, "aperture_blades")
    params.append(Param("dof", "aperture_blades", "int", blades.hard_min, blades.hard_max))
    return params


def _value(p: Param):
    if p.kind == "enum":
        return st.sampled_from(p.choices)
    if p.kind == "bool":
        return st.booleans()
    if p.kind == "int":
        return st.integers(int(p.lo), int(p.hi))
    f = st.floats(p.lo, p.hi, allow_nan=False, allow_infinity=False, width=32)
    return st.tuples(f, f, f) if p.kind == "color" else f


def case_strategy(params):
    """A hypothesis strategy of cases: {(owner, name): value} for every parameter."""
    return st.fixed_dictionaries({(p.owner, p.name, p.only_for): _value(p) for p in params})


def build_scene(bpy):
    """The fuzzed scene (in a fresh empty file); returns the scene."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=6.0)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=12, ring_count=6, radius=0.7,
                                         location=(0.0, 0.0, 0.7))
    mat = bpy.data.materials.new("Fuzzed")
    if mat.node_tree is None:
        mat.use_nodes = True
    for obj in scene.objects:
        obj.data.materials.append(mat)
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    lamp.location = (1.5, -1.0, 2.5)
    lamp.rotation_euler = (0.5, 0.3, 0.0)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, -4.0, 2.0)
    cam.rotation_euler = (1.2, 0.0, 0.0)
    for o in (lamp, cam):
        scene.collection.objects.link(o)
    scene.camera = cam
    world = bpy.data.worlds.new("World")
    if world.node_tree is None:
        world.use_nodes = True
    scene.world = world
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    return scene


def apply_case(bpy, scene, case: dict):
    """Set every parameter of `case` on the scene (lamp type first)."""
    lamp = scene.objects["Lamp"]
    lamp.data.type = case[("light", "type", "")]
    light = lamp.data                    # re-read: its RNA type follows the lamp type
    cam = scene.camera.data
    bsdf = next(n for n in bpy.data.materials["Fuzzed"].node_tree.nodes
                if n.type == "BSDF_PRINCIPLED")
    bg = next(n for n in scene.world.node_tree.nodes if n.type == "BACKGROUND")
    for (owner, name, only_for), value in case.items():
        if owner == "light" and name == "type":
            continue
        if owner == "light" and only_for and only_for != light.type:
            continue
        if owner in ("material", "world"):
            sock = (bsdf if owner == "material" else bg).inputs.get(name)
            if sock is None:             # a socket this node does not show now
                continue
            sock.default_value = (*value, 1.0) if isinstance(value, tuple) else value
        else:
            target = {"light": light, "camera": cam, "dof": cam.dof}[owner]
            setattr(target, name, value)


def render_case(bpy, scene, case: dict, seed: int = 0) -> list:
    """Problems of one case's render: [] when finite and non-negative; 'crash: ...' when
    the export or the render raised."""
    from drt_addon.engine_link import engine
    from drt_addon.export import Reporter, export_scene
    try:
        apply_case(bpy, scene, case)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        depsgraph.update()
        description = export_scene(depsgraph, Reporter(), size=(SIZE, SIZE))
        film, stats = engine.render(description, engine.RenderSettings(
            samples=SAMPLES, seed=seed, threads=1))
    except Exception as e:               # noqa: BLE001 - every exception is a finding
        return [f"crash: {type(e).__name__}: {e}"]
    return sane(film, stats)


def describe(case: dict) -> str:
    """A case as 'owner.name=value' items, sorted."""
    def fmt(v):
        if isinstance(v, tuple):
            return "(" + ", ".join(f"{x:.4g}" for x in v) + ")"
        return f"{v:.4g}" if isinstance(v, float) else repr(v)
    return ", ".join(f"{o}.{n}={fmt(v)}" for (o, n, _), v in sorted(case.items()))


def summarize(outcomes) -> Counter:
    """Counts of cases by kind of problem: nonfinite, negative, crash, ok."""
    counts = Counter()
    for problems in outcomes:
        if not problems:
            counts["ok"] += 1
        for text in problems:
            kind = ("crash" if text.startswith("crash") else
                    "negative" if text.startswith("negative") else "nonfinite")
            counts[kind] += 1
    return counts


def run(bpy, cases: int, seed: int = 0, verbose=True):
    """Fuzz `cases` cases (hypothesis, generation only, seeded); returns (counts, the
    failing cases with their problems)."""
    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis import seed as hypothesis_seed
    scene = build_scene(bpy)
    params = blender_ranges(bpy)
    outcomes, failures = [], []

    @hypothesis_seed(seed)
    @settings(max_examples=cases, phases=[Phase.generate], database=None, deadline=None,
              suppress_health_check=list(HealthCheck))
    @given(case_strategy(params), st.integers(0, 2 ** 31 - 1))
    def one(case, render_seed):
        problems = render_case(bpy, scene, case, render_seed)
        outcomes.append(problems)
        if problems:
            failures.append((case, problems))
            if verbose:
                print(f"case {len(outcomes)}: {problems}: {describe(case)}", flush=True)

    one()
    return summarize(outcomes), failures


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=500)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    import bpy

    import drt_addon
    drt_addon.register()
    counts, failures = run(bpy, args.cases, args.seed)
    total = counts["ok"] + len(failures)
    print(f"{total} cases: {counts['nonfinite']} with NaN/Inf samples, {counts['negative']} "
          f"with negative pixels, {counts['crash']} crashes, {counts['ok']} clean")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
