"""Sections 4 and 5 of docs/benchmarks.md (called by docs/make_benchmarks.py): a
1M-triangle mesh rendered by each engine in a fresh process, and 1000 rigidly moving
objects with motion blur on and off."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


_BIG_MESH = r"""
import bpy, json, resource, sys, time
blend, engine = sys.argv[1], sys.argv[2]
t0 = time.perf_counter()
import drt_addon; drt_addon.register()
bpy.ops.wm.open_mainfile(filepath=blend, load_ui=False)
scene = bpy.context.scene
scene.render.engine = engine
scene.cycles.samples = 1
scene.drt.samples = 1
scene.cycles.use_denoising = False
t_load = time.perf_counter()
bpy.ops.render.render()
t_end = time.perf_counter()
from drt_addon import render_engine
last = render_engine.last_render if engine == "DRT" else {}
desc = last.get("scene")
arrays = sum(getattr(a, "nbytes", 0) for m in (desc.meshes if desc else [])
             for a in vars(m).values()) / 2**20
print(json.dumps(dict(load=t_load - t0, render=t_end - t_load, whole=t_end - t0,
                      first_sample=last.get("first_sample_seconds"),
                      export=last.get("export_seconds"), build=last.get("build_seconds"),
                      scene_mb=arrays,
                      maxrss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)))
"""


def big_mesh(triangles_wanted=1_000_000):
    """A subdivided Suzanne with about 1M triangles, rendered at 1 sample by each engine in
    a fresh process: whole-process seconds and peak resident memory."""
    import bpy
    tmp = tempfile.mkdtemp(prefix="drt-bench-")
    blend = os.path.join(tmp, "big_mesh.blend")
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
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    out = {"triangles": tris}
    for engine in ("CYCLES", "DRT"):
        proc = subprocess.run([sys.executable, "-c", _BIG_MESH, blend, engine], cwd=ROOT,
                              capture_output=True, text=True, check=True)
        out[engine] = json.loads(proc.stdout.strip().splitlines()[-1])
    return out


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
