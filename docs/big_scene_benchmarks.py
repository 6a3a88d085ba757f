"""Sections 4 and 5 of docs/benchmarks.md (called by docs/make_benchmarks.py): a
1M-triangle mesh and a scatter of 100,000 instances rendered by each engine in a fresh
process, and 1000 rigidly moving objects with motion blur on and off."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


_BIG_MESH = r"""
import json, sys, time
t_start = time.perf_counter()
sys.path.insert(0, "docs")
from render_phases import PhaseRecorder, array_mb, peak_mb, rss_mb
import bpy
blend, engine = sys.argv[1], sys.argv[2]
t0 = time.perf_counter()          # the process's times below are from here
marks = [("import bpy", t0, rss_mb(), peak_mb())]
import drt_addon; drt_addon.register()
marks.append(("import and register DRT's add-on (its tracer loads with its first render)",
              time.perf_counter(),
              rss_mb(), peak_mb()))
bpy.ops.wm.open_mainfile(filepath=blend, load_ui=False)
scene = bpy.context.scene
scene.render.engine = engine
scene.cycles.samples = 1
scene.drt.samples = 1
scene.cycles.use_denoising = False
t_load = time.perf_counter()
marks.append(("file load", t_load, rss_mb(), peak_mb()))
recorder = PhaseRecorder()
if engine == "DRT":
    recorder.install()
bpy.ops.render.render()
t_end = time.perf_counter()
from drt_addon import render_engine
last = render_engine.last_render if engine == "DRT" else {}
desc = last.get("scene")
phases = recorder.phases(t_load, marks[-1][2]) if engine == "DRT" else []
before = [(name, t - t_prev, rss, rss - rss_prev, peak, 0.0, 0.0, 0, None) for
          (name, t, rss, peak), (_, t_prev, rss_prev, _) in
          zip(marks, [("", t_start, 0, 0)] + marks)]
print(json.dumps(dict(load=t_load - t0, render=t_end - t_load, whole=t_end - t0,
                      first_sample=last.get("first_sample_seconds"),
                      export=last.get("export_seconds"), build=last.get("build_seconds"),
                      scene_mb=array_mb(*(desc.meshes if desc else [])),
                      kernel_seconds=recorder.kernel_seconds, kernel_mb=recorder.kernel_mb,
                      kernel_loads=recorder.loads,
                      rss_after_mb=rss_mb(), phases=before + phases,
                      maxrss_mb=peak_mb())))
"""


def user_env() -> dict:
    """The environment of a timed process: this one's with Python's bytecode cache on
    (PYTHONDONTWRITEBYTECODE removed), as on a user's machine, where the add-on's modules
    are compiled once and then loaded from __pycache__ (bpy's own come compiled). With
    the variable set, every DRT process compiled its ~200 source files again: 0.2 s that
    no user pays."""
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def save_big_mesh(blend: str) -> int:
    """Saves the big-mesh scene to `blend`: Suzanne subdivided to about 1M triangles, a
    camera, a sun, the default world, 320 x 240, Denoise off. Returns its triangle
    count."""
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_monkey_add()
    obj = bpy.context.object
    mod = obj.modifiers.new("subd", "SUBSURF")
    mod.levels = mod.render_levels = 5          # 968 x 4^5 / ... about 1M triangles
    bpy.ops.object.modifier_apply(modifier="subd")
    tris = sum(len(p.vertices) - 2 for p in obj.data.polygons)
    bpy.ops.object.camera_add(location=(0, -4, 0), rotation=(np.pi / 2, 0, 0))
    bpy.context.scene.camera = bpy.context.object
    bpy.ops.object.light_add(type="SUN")
    bpy.context.scene.render.resolution_x, bpy.context.scene.render.resolution_y = 320, 240
    # Render > Denoise, on in a new file, off: section 3 fits each engine's noise to a
    # power law in samples, which a denoised image does not follow (DRT reads the switch
    # since it renders with the file's Cycles settings: at 16, 64 and 256 samples its
    # error against its own denoised 1024 fell only as samples^-0.46)
    bpy.context.scene.cycles.use_denoising = False
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    return tris


def big_mesh(engines=("CYCLES", "DRT"), repeats=3):
    """A subdivided Suzanne with about 1M triangles, rendered at 1 sample by each engine in
    a fresh process: whole-process seconds and peak resident memory, and for DRT per
    phase of its render call (docs/render_phases.py)."""
    tmp = tempfile.mkdtemp(prefix="drt-bench-")
    blend = os.path.join(tmp, "big_mesh.blend")
    tris = save_big_mesh(blend)
    # a DRT process first, untimed: the kernels this scene uses, compiled into the on-disk
    # cache if an engine change left it stale (the timed processes load them from there);
    # then `repeats` processes per engine, taking turns, and per engine the run of median
    # whole-process time (on a shared machine, one run can meet a burst of other work)
    runs = {engine: [] for engine in engines}
    for engine in ("DRT",) + engines * repeats:
        proc = subprocess.run([sys.executable, "-c", _BIG_MESH, blend, engine], cwd=ROOT,
                              capture_output=True, text=True, env=user_env())
        if proc.returncode:
            raise RuntimeError(f"the {engine} process failed:\n{proc.stderr[-3000:]}")
        runs[engine].append(json.loads(proc.stdout.strip().splitlines()[-1]))
    shutil.rmtree(tmp, ignore_errors=True)
    out = {"triangles": tris, "repeats": repeats}
    for engine, results in runs.items():
        results = sorted(results[-repeats:], key=lambda run: run["whole"])
        out[engine] = results[len(results) // 2]
    return out


def save_many_instances(blend: str, side: int) -> tuple[int, int]:
    """Saves a scatter to `blend`: Geometry Nodes' Instance on Points puts a
    5,000-triangle UV sphere on each vertex of a side x side grid (one Embree instance
    array in DRT, engine.instancing), a camera over it, a sun, 320 x 240. Returns
    (places, triangles of the sphere)."""
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    src = bpy.data.collections.new("Source")
    scene.collection.children.link(src)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.4, segments=50, ring_count=51)
    ball = bpy.context.object
    for c in ball.users_collection:
        c.objects.unlink(ball)
    src.objects.link(ball)
    bpy.context.view_layer.layer_collection.children["Source"].exclude = True
    tris = sum(len(p.vertices) - 2 for p in ball.data.polygons)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=side - 1, y_subdivisions=side - 1,
                                    size=side)
    grid = bpy.context.object
    group = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    group.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    gin, gout = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
    place = group.nodes.new("GeometryNodeInstanceOnPoints")
    info = group.nodes.new("GeometryNodeObjectInfo")
    info.inputs["Object"].default_value = ball
    group.links.new(gin.outputs[0], place.inputs["Points"])
    group.links.new(info.outputs["Geometry"], place.inputs["Instance"])
    group.links.new(place.outputs["Instances"], gout.inputs[0])
    grid.modifiers.new("Scatter", "NODES").node_group = group
    bpy.ops.object.camera_add(location=(0, -0.7 * side, 0.5 * side), rotation=(0.9, 0, 0))
    scene.camera = bpy.context.object
    bpy.ops.object.light_add(type="SUN")
    scene.render.resolution_x, scene.render.resolution_y = 320, 240
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    return len(grid.data.vertices), tris


def many_instances(sides=(100, 317), engines=("CYCLES", "DRT")):
    """The scatter of `save_many_instances` with about 10,000 and 100,000 places, each
    engine in a fresh process (after one untimed DRT process per scene, which compiles
    what an engine change left stale): whole-process seconds and peak memory."""
    tmp = tempfile.mkdtemp(prefix="drt-bench-")
    out = {}
    for side in sides:
        blend = os.path.join(tmp, f"scatter_{side}.blend")
        places, tris = save_many_instances(blend, side)
        runs = {}
        for engine in ("DRT",) + engines:
            proc = subprocess.run([sys.executable, "-c", _BIG_MESH, blend, engine], cwd=ROOT,
                                  capture_output=True, text=True, env=user_env())
            if proc.returncode:
                raise RuntimeError(f"the {engine} process failed:\n{proc.stderr[-3000:]}")
            runs[engine] = json.loads(proc.stdout.strip().splitlines()[-1])
        out[places] = dict(triangles=tris, **runs)
    shutil.rmtree(tmp, ignore_errors=True)
    return out


def memory_target(label: str, drt: dict, cycles: dict, note: str) -> tuple:
    """A target row: DRT's peak memory at most 1.2x Cycles'."""
    memory = drt["maxrss_mb"] / cycles["maxrss_mb"]
    return (label, "<= 1.2x",
            f"{memory:.2f}x ({drt['maxrss_mb'] - cycles['maxrss_mb']:.0f} MB more{note})",
            bool(memory <= 1.2))


def many_instances_section(r: dict, load: float, big: dict) -> tuple[list, list]:
    """docs/benchmarks.md section 4b from many_instances()'s result: (lines, targets).
    big: big_mesh()'s result, whose render call's memory per triangle prices copies."""
    (few, f), (many, m) = sorted(r.items())
    c, d = m["CYCLES"], m["DRT"]
    per_place = (d["maxrss_mb"] - f["DRT"]["maxrss_mb"]) * 2 ** 20 / (many - few)
    b = big["DRT"]
    loaded = {p[0]: p for p in b["phases"]}["file load"][2]
    per_triangle = (b["maxrss_mb"] - loaded) * 2 ** 20 / big["triangles"]
    flat = m["triangles"] * per_triangle
    targets = [memory_target("4. 100,000 instances of a 5,000-triangle mesh: peak memory, "
                             "DRT over Cycles", d, c,
                             f"; {per_place:.0f} bytes a place, not a copy of the mesh")]
    lines = ["## 4b. A scatter of instances", "",
             f"Geometry Nodes' Instance on Points puts a {m['triangles']:,}-triangle UV sphere "
             f"on each vertex of a grid: {few:,} and {many:,} places ({many * m['triangles']:,} "
             "triangles as copies), 320x240, 1 sample, each engine in a fresh process "
             f"(`docs/big_scene_benchmarks.py`; load average {load:.2f}). DRT keeps the "
             "sphere once and traces the places as one Embree instance array "
             "(engine.instancing).", "",
             "| places | Cycles: whole process (s) | DRT | Cycles: peak memory (MB) | DRT | "
             "DRT: export (s) | DRT: acceleration structure (s) |",
             "|---|---|---|---|---|---|---|"]
    for places, run in sorted(r.items()):
        cy, dr = run["CYCLES"], run["DRT"]
        lines.append(f"| {places:,} | {cy['whole']:.2f} | {dr['whole']:.2f} | "
                     f"{cy['maxrss_mb']:.0f} | {dr['maxrss_mb']:.0f} | "
                     f"{dr['export'] or 0:.2f} | {dr['build'] or 0:.2f} |")
    lines += ["", f"DRT's peak memory grows by {per_place:.0f} bytes a place from {few:,} to "
              f"{many:,} places (its object table, 47 float64 per place, and Embree's "
              "12 float32 transform), where a copy of the sphere would take "
              f"{flat / 1e6:.2f} MB a place (section 4's render call takes "
              f"{per_triangle:.0f} bytes a triangle). What DRT's process holds beyond Cycles' at "
              f"{many:,} places, {d['maxrss_mb'] - c['maxrss_mb']:.0f} MB, is mostly its tracer "
              "(Numba and the compiled kernels, section 4).", ""]
    return lines, targets


def many_moving(n_objects=1000, spp=1):
    """n rigidly moving cubes: seconds per sample with motion blur on and off (engine
    only, the same export)."""
    from engine import Camera, Material, RenderSettings, Scene, SunLight, TriangleMesh, World
    from engine.motion import RigidMotion, Shutter
    rng = np.random.default_rng(0)
    cube_v = np.array([[x, y, z] for x in (-.1, .1) for y in (-.1, .1) for z in (-.1, .1)])
    cube_f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                       [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    meshes = []
    for i in range(n_objects):
        p = rng.uniform(-3, 3, 3)
        m0, m1 = np.eye(4), np.eye(4)
        m0[:3, 3], m1[:3, 3] = p, p + rng.uniform(-.2, .2, 3)
        meshes.append(TriangleMesh(f"c{i}", cube_v, cube_f, [0],
                                   motion=RigidMotion(np.array([0.0, 1.0]), np.stack([m0, m1]))))
    cam = np.eye(4)
    cam[:3, 3] = (0, 0, 12)
    lights = [SunLight((0.3, 0.2, -1.0), (3.0, 3.0, 3.0))]
    out = {}
    from engine import render
    for blur in (False, True):
        scene = Scene(Camera(cam), 160, 120, meshes, [Material()], lights, World((.1, .1, .1)),
                      shutter=Shutter() if blur else None)
        render(scene, RenderSettings(samples=1))     # the kernels this scene uses, loaded
        t0 = time.perf_counter()
        render(scene, RenderSettings(samples=spp))
        out["blur" if blur else "static"] = (time.perf_counter() - t0) / spp
    return out


def big_mesh_section(r: dict, load: float) -> tuple[list, list]:
    """docs/benchmarks.md section 4 from big_mesh()'s result: (lines, targets). `load`:
    the load average when it ran."""
    c, d = r["CYCLES"], r["DRT"]
    ratio = d["whole"] / c["whole"]
    rows = {p[0]: p for p in d["phases"]}
    embree = [p for p in d["phases"] if ("Embree" in p[0] or "accelerator" in p[0])
              and not p[0].startswith("import")]
    embree_s, embree_mb = sum(p[1] for p in embree), sum(p[3] for p in embree)
    first = d["phases"][-1]
    imported = next((p[1] for p in d["phases"] if p[0].startswith("import DRT's tracer")), 0.0)
    setup = d["render"] - imported - d["export"] - first[1]
    targets = [("4. 1M triangles: whole process, DRT over Cycles", "<= 1.5x",
                f"{ratio:.2f}x (Embree {embree_s:.1f} s, loading DRT's tracer "
                f"{imported:.1f} s and its compiled kernels {d['kernel_seconds']:.1f} s of "
                f"DRT's {d['render']:.1f} s render call)",
                bool(ratio <= 1.5)),
               memory_target("4. ... peak memory, DRT over Cycles", d, c,
                             f"; Numba's compiled kernels take {d['kernel_mb']:.0f} MB")]
    lines = ["## 4. A big mesh", "",
             f"Suzanne subdivided to {r['triangles']:,} triangles, 320x240, 1 sample, each "
             f"engine in a fresh process (`docs/big_scene_benchmarks.py`; load average "
             f"{load:.2f}; {r['repeats']} processes per engine, taking turns; for each "
             "engine, its run of median whole-process time). Seconds from after `import bpy`: the "
             "file load includes registering DRT's add-on; whole process = file load + "
             "render call (for DRT, its first render in the process loads its tracer).", "",
             "| | Cycles | DRT |", "|---|---|---|",
             f"| file load (s) | {c['load']:.2f} | {d['load']:.2f} |",
             f"| render call: sync, build, 1 sample (s) | {c['render']:.2f} | "
             f"{d['render']:.2f} |",
             f"| DRT: depsgraph to first sample (s) | | "
             f"{(d['first_sample'] or 0) + imported:.2f} |",
             f"| ... of which loading DRT's tracer (engine, Numba, Embree) (s) | | "
             f"{imported:.2f} |",
             f"| ... export from the depsgraph (s) | | {d['export'] or 0:.2f} |",
             f"| ... acceleration structure and render set-up (s) | | {setup:.2f} |",
             f"| ... the first sample (s) | | {first[1]:.2f} |",
             f"| peak resident memory (MB) | {c['maxrss_mb']:.0f} | {d['maxrss_mb']:.0f} |",
             f"| DRT: the exported scene's arrays (MB) | | {d['scene_mb']:.0f} |", "",
             "Where DRT's process spends its time and memory, phase by phase "
             "(`docs/render_phases.py` marks the end of each step of the render call: "
             "wall time, resident memory then and the peak so far; \"arrays kept\" are the "
             "NumPy arrays the step's result holds that no earlier step holds):", "",
             "| phase | s | resident MB after | MB added | peak MB so far | arrays kept (MB) "
             "| kernels loaded from Numba's cache |", "|---|---|---|---|---|---|---|"]
    for name, secs, rss, added, peak, k_s, k_mb, n, kept in d["phases"]:
        loaded = f"{n}: {k_s:.2f} s, {k_mb:.0f} MB" if n else ""
        lines.append(f"| {name} | {secs:.2f} | {rss:.0f} | {added:+.0f} | {peak:.0f} | "
                     f"{'' if kept is None else f'{kept:.0f}'} | {loaded} |")
    before, c_before = rows["file load"][2], {p[0]: p for p in c["phases"]}["file load"][2]
    export = rows["export (depsgraph to scene description)"]
    surface = rows["surface arrays (engine/surface.py)"]
    name, first_s, first_mb = d["kernel_loads"][0] if d["kernel_loads"] else ("", 0, 0)
    lines += ["", f"Both processes hold about the same before the render call ({before:.0f} "
              f"MB DRT, {c_before:.0f} MB Cycles: Blender, the file, and DRT's add-on, "
              "registered in both; its tracer loads with the first DRT render). DRT's "
              f"render call adds {d['maxrss_mb'] - before:.0f} MB to it at the peak, "
              f"Cycles' {c['maxrss_mb'] - c_before:.0f} MB. DRT's: the export "
              f"{export[3]:.0f} MB (the scene description's arrays {d['scene_mb']:.0f} MB, "
              f"float64 positions by its contract), Embree {embree_mb:.0f} MB (its float32 "
              "copy of the triangles and its hierarchy; Cycles builds an Embree BVH on the "
              f"CPU too), the surface arrays the kernels read {surface[8] or 0:.0f} MB (a "
              "material index per triangle: corners are read from the accelerator's "
              "vertices, normals and offset scales computed per hit), and Numba's "
              f"compiled kernels {d['kernel_mb']:.0f} "
              f"MB, loaded from the on-disk cache during the first sample in "
              f"{d['kernel_seconds']:.2f} s, of which the first load ({name}) "
              f"{first_s:.2f} s and {first_mb:.0f} MB: it initialises Numba's code "
              "generation in the process. Of the accelerator's time, converting the "
              "vertices once to the float32 buffer Embree shares (no copy by Embree) "
              f"takes {rows[embree[1][0]][1]:.2f} s and Embree's hierarchy build "
              f"{rows[embree[2][0]][1]:.2f} s.", ""]
    return lines, targets
