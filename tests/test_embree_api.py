"""Embree through its own C API (engine.embree): shared buffers, the geometry kinds DRT
builds on (triangles, curves, points, instances, motion steps) and rays cast from
compiled kernels. Oracles share no code with Embree: closed-form distances of rays to a
plane, a sphere and a cylinder, and a float64 ray-triangle test."""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from engine.embree import library as L
from engine.embree.rays import intersect_batch, occluded_batch, target
from engine.embree.scene import Scene

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
F32 = np.finfo(np.float32).eps


def scene_target(scene, center=np.zeros(3)):
    """The Target of a bare Scene (geometry ids as global ids, no instance rows)."""
    k = len(scene.kinds)
    return target(scene.handle, center, np.zeros(k, np.int64), np.full(k, -1, np.int64),
                  scene.kinds.index("curves") if "curves" in scene.kinds else -1)


def trace(scene, o, d, tmax=None, time=None, center=np.zeros(3)):
    n = len(o)
    out = [np.empty(n, np.int64) for _ in range(4)] + [np.empty(n) for _ in range(3)]
    intersect_batch(scene_target(scene, center), np.ascontiguousarray(o, np.float64),
                    np.ascontiguousarray(d, np.float64),
                    np.full(n, np.inf) if tmax is None else np.asarray(tmax, np.float64),
                    np.zeros(0) if time is None else np.asarray(time, np.float64),
                    np.zeros((0, 2), np.int64), *out)
    return dict(zip(("geom", "prim", "inst", "element", "t", "u", "v"), out))


def blocked(scene, o, d, tmax, time=None):
    b = np.zeros(len(o), bool)
    occluded_batch(scene_target(scene), np.ascontiguousarray(o, np.float64),
                   np.ascontiguousarray(d, np.float64), np.asarray(tmax, np.float64),
                   np.zeros(0) if time is None else np.asarray(time, np.float64),
                   np.zeros((0, 4), np.int64), b)
    return b


def down_dirs(rng, n, spread=0.3):
    """Unit directions around -z."""
    d = np.c_[rng.normal(size=(n, 2)) * spread, -np.ones(n)]
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def moller_trumbore(o, d, p0, p1, p2):
    """float64 ray-triangle distances and barycentrics (inf where missed)."""
    e1, e2 = p1 - p0, p2 - p0
    pv = np.cross(d, e2)
    det = pv @ e1                        # (n,)
    tv = o - p0
    u = np.einsum("ij,ij->i", tv, pv) / det
    qv = np.cross(tv, e1)
    v = np.einsum("ij,ij->i", qv, d) / det
    t = (qv @ e2) / det
    hit = (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    return np.where(hit, t, np.inf), u, v


def test_library_is_the_wheels_and_loaded_once():
    path = L.library_path()
    assert "embree4" in os.path.basename(path)
    assert L.load() is L.load() and L.load().drt_path == path
    with open(f"/proc/{os.getpid()}/maps") as f:
        maps = {line.split()[-1] for line in f if "embree4" in line}
    # one copy of the wheel's Embree in this process (the bpy module links its own for
    # Cycles, which a process that imported bpy maps too)
    ours = {m for m in maps if os.path.samefile(m, path)}
    assert len(ours) == 1 and all("bpy" in m for m in maps - ours), maps


def test_triangle_hits_match_a_float64_oracle():
    rng = np.random.default_rng(1)
    p = np.array([[-1.0, -1.0, 0.2], [2.0, -0.5, -0.1], [-0.3, 1.7, 0.0]])
    s = Scene()
    s.add_triangles(p, np.array([[0, 1, 2]]))
    s.commit()
    o = np.c_[rng.uniform(-1.5, 2.5, (4000, 2)), rng.uniform(1, 3, 4000)]
    d = down_dirs(rng, 4000)
    h = trace(s, o, d)
    t, u, v = moller_trumbore(o, d, *p)
    inside = np.isfinite(t) & (u > 1e-4) & (v > 1e-4) & (u + v < 1 - 1e-4)
    outside = ~np.isfinite(t) & ((u < -1e-4) | (v < -1e-4) | (u + v > 1 + 1e-4))
    assert inside.sum() > 500 and outside.sum() > 1000
    assert (h["prim"][inside] == 0).all() and (h["geom"][inside] == 0).all()
    assert (h["prim"][outside] == -1).all() and np.isinf(h["t"][outside]).all()
    assert (h["inst"] == -1).all()
    np.testing.assert_allclose(h["t"][inside], t[inside], rtol=64 * F32, atol=64 * F32)
    np.testing.assert_allclose(h["u"][inside], u[inside], atol=1e-5)
    np.testing.assert_allclose(h["v"][inside], v[inside], atol=1e-5)
    # tmax: a segment that ends before the triangle sees nothing; occlusion agrees
    short = h["t"][inside] * 0.99
    assert (trace(s, o[inside], d[inside], short)["prim"] == -1).all()
    assert not blocked(s, o[inside], d[inside], short).any()
    assert blocked(s, o[inside], d[inside], h["t"][inside] * 1.01).all()
    assert not blocked(s, o[outside], d[outside], np.full(outside.sum(), 1e9)).any()


def test_buffers_are_shared_not_copied():
    rng = np.random.default_rng(2)
    verts = rng.uniform(-1, 1, (300, 3))
    tris = rng.integers(0, 300, (500, 3)).astype(np.int32)
    s = Scene()
    g = s.add_triangles(verts, tris)
    s.commit()
    assert s.buffer_address(g, L.BUFFER_INDEX) == tris.ctypes.data
    vbuf = [a for a in s._keep if a.dtype == np.float32]
    assert s.buffer_address(g, L.BUFFER_VERTEX) == vbuf[0].ctypes.data
    np.testing.assert_array_equal(vbuf[0], verts.astype(np.float32))


def test_bad_geometry_is_refused_with_a_clear_error():
    s = Scene()
    with pytest.raises(ValueError, match="vertex that does not exist"):
        s.add_triangles(np.zeros((3, 3)), np.array([[0, 1, 3]]))
    child = Scene()
    child.add_triangles(np.eye(3), np.array([[0, 1, 2]]))
    with pytest.raises(ValueError, match="commit"):
        s.add_instance(child, np.eye(4))
    child.commit()
    with pytest.raises(ValueError, match="not finite"):
        s.add_instance(child, np.full((4, 4), np.nan))


def test_sphere_points_hit_at_the_closed_form_distance():
    rng = np.random.default_rng(3)
    c, r = np.array([0.3, -0.2, 0.1]), 0.7
    s = Scene()
    s.add_points(np.array([[*c, r]]))
    s.commit()
    o = c + rng.normal(size=(2000, 3)) * 0.3 + np.array([0, 0, 4.0])
    d = down_dirs(rng, 2000) * 0.6 + (c - o) / np.linalg.norm(c - o, axis=1, keepdims=True)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    oc = o - c
    b = np.einsum("ij,ij->i", oc, d)
    disc = b * b - (np.einsum("ij,ij->i", oc, oc) - r * r)
    hit = disc > 1e-3
    want = -b - np.sqrt(np.maximum(disc, 0))
    h = trace(s, o, d)
    assert hit.sum() > 500 and (~hit).sum() > 100
    assert (h["prim"][hit] == 0).all() and (h["prim"][disc < -1e-3] == -1).all()
    np.testing.assert_allclose(h["t"][hit], want[hit], rtol=1e-5, atol=1e-5)


def test_round_linear_curve_is_a_tube_of_its_radius():
    r = 0.05
    pts = np.array([[-1.0, 0, 0, r], [1.0, 0, 0, r]])
    s = Scene()
    s.add_curves(pts, np.array([0]), kind=L.GEOMETRY_ROUND_LINEAR_CURVE)
    s.commit()
    x = np.linspace(-0.8, 0.8, 33)
    y = np.linspace(-0.9 * r, 0.9 * r, 7)
    X, Y = np.meshgrid(x, y)
    o = np.c_[X.ravel(), Y.ravel(), np.full(X.size, 2.0)]
    d = np.tile([0.0, 0.0, -1.0], (len(o), 1))
    h = trace(s, o, d)
    assert (h["prim"] == 0).all()
    want = 2.0 - np.sqrt(r * r - o[:, 1] ** 2)          # the tube's top, z = sqrt(r²-y²)
    np.testing.assert_allclose(h["t"], want, atol=2e-5)
    # beside the tube: a miss
    assert (trace(s, o + [0, 2 * r, 0], d)["prim"] == -1).all()


def test_instances_share_one_mesh_and_report_which_was_hit():
    mesh = Scene()
    mesh.add_triangles(np.array([[-0.4, -0.4, 0.0], [0.4, -0.4, 0.0], [0.0, 0.4, 0.0]]),
                       np.array([[0, 1, 2]]))
    mesh.commit()
    top = Scene()
    n = 200
    for i in range(n):
        m = np.eye(4)
        m[:3, 3] = (i % 20, i // 20, 0.1 * i)
        m[:3, :3] *= 1.0 + 0.001 * i                    # scaled too
        top.add_instance(mesh, m)
    top.commit()
    # the instances hold the mesh scene, not copies of its buffers
    assert sum(a.nbytes for a in top._keep if isinstance(a, np.ndarray)) == 0
    i = np.arange(n)
    o = np.c_[i % 20, i // 20, np.full(n, 50.0)]
    d = np.tile([0.0, 0.0, -1.0], (n, 1))
    h = trace(top, o, d)
    np.testing.assert_array_equal(h["inst"], i)
    assert (h["geom"] == 0).all() and (h["prim"] == 0).all() and (h["element"] == 0).all()
    np.testing.assert_allclose(h["t"], 50.0 - 0.1 * i, rtol=4 * F32)


def test_an_instance_array_is_one_geometry_with_one_shared_transform_buffer():
    """10,000 places of a triangle as one Embree instance array: one geometry in the top
    scene, one float32 buffer of 12 floats a place shared with Embree, and each hit names
    its place (the element) beside the array's geometry id."""
    mesh = Scene()
    mesh.add_triangles(np.array([[-0.4, -0.4, 0.0], [0.4, -0.4, 0.0], [0.0, 0.4, 0.0]]),
                       np.array([[0, 1, 2]]))
    mesh.commit()
    top = Scene()
    top.add_triangles(np.array([[-1.0, -1.0, -5.0], [300.0, -1.0, -5.0], [-1.0, 300.0, -5.0]]),
                      np.array([[0, 1, 2]]))
    n = 10000
    i = np.arange(n)
    places = np.tile(np.eye(4), (n, 1, 1))
    places[:, :3, 3] = np.c_[i % 100, i // 100, 0.01 * i]
    places[:, :3, :3] *= (1.0 + 1e-5 * i)[:, None, None]
    gid = top.add_instance_array(mesh, places)
    top.commit()
    assert gid == 1 and top.kinds == ["triangles", "instance array"] and top.counts[1] == n
    shared = [a for a in top._keep if isinstance(a, np.ndarray) and a.dtype == np.float32
              and a.size == 12 * n]
    assert len(shared) == 1 and shared[0].nbytes == 48 * n
    o = np.c_[i % 100, i // 100, np.full(n, 500.0)]
    d = np.tile([0.0, 0.0, -1.0], (n, 1))
    h = trace(top, o, d)
    np.testing.assert_array_equal(h["element"], i)
    assert (h["inst"] == gid).all() and (h["geom"] == 0).all() and (h["prim"] == 0).all()
    np.testing.assert_allclose(h["t"], 500.0 - 0.01 * i, rtol=4 * F32)
    # beside every place: the ground, a hit of the top scene itself (no instance)
    h = trace(top, o + [0.5, 0.5, 0.0], d)
    assert (h["geom"] == 0).all() and (h["inst"] == -1).all() and (h["element"] == -1).all()
    with pytest.raises(ValueError, match="not finite"):
        top.add_instance_array(mesh, np.full((2, 4, 4), np.nan))


def test_motion_steps_interpolate_vertices_and_instances_over_time():
    p = np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]])
    tri = np.array([[0, 1, 2]])
    s = Scene()
    s.add_triangles([p, p + [0, 0, 1.0]], tri)         # rises by 1 over the shutter
    s.commit()
    times = np.linspace(0, 1, 11)
    n = len(times)
    o, d = np.tile([0.0, -0.2, 5.0], (n, 1)), np.tile([0.0, 0.0, -1.0], (n, 1))
    np.testing.assert_allclose(trace(s, o, d, time=times)["t"], 5.0 - times, rtol=4 * F32)
    mesh = Scene()
    mesh.add_triangles(p, tri)
    mesh.commit()
    top = Scene()
    a, b = np.eye(4), np.eye(4)
    b[:3, 3] = (0.0, 0.0, -2.0)
    top.add_instance(mesh, [a, b])
    top.commit()
    np.testing.assert_allclose(trace(top, o, d, time=times)["t"], 5.0 + 2 * times,
                               rtol=4 * F32)
    assert (blocked(top, o, d, 5.0 + 2 * times - 0.01, time=times) == False).all()  # noqa: E712


def test_origin_shift_keeps_precision_far_from_the_world_origin():
    far = np.array([1e6, -1e6, 1e6])
    p = np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]]) * 1e-3 + far
    s = Scene()
    s.add_triangles(p, np.array([[0, 1, 2]]), offset=far)
    s.commit()
    o = far + np.array([[0.0, -2e-4, 1e-2]])
    h = trace(s, o, np.array([[0.0, 0.0, -1.0]]), center=far)
    assert h["prim"][0] == 0 and abs(h["t"][0] - 1e-2) < 1e-8


def test_ray_kernels_load_from_the_cache_in_a_new_process(tmp_path):
    """The kernels that call Embree are cached like every other: a second process
    compiles nothing (Numba refuses to cache kernels holding ctypes pointers)."""
    code = ("import numpy as np\n"
            "from numba.core import event\n"
            "n = []\n"
            "class C(event.Listener):\n"
            "    def on_start(self, ev): n.append(ev.data['dispatcher'].py_func.__name__)\n"
            "    def on_end(self, ev): pass\n"
            "event.register('numba:compile', C())\n"
            "from test_embree_api import Scene, trace\n"
            "s = Scene(); s.add_points(np.array([[0, 0, 0, 1.0]])); s.commit()\n"
            "h = trace(s, np.array([[0, 0, 3.0]]), np.array([[0, 0, -1.0]]))\n"
            "assert abs(h['t'][0] - 2.0) < 1e-6\n"
            "print(len(n))\n")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path),
               PYTHONPATH=os.pathsep.join([ROOT, os.path.join(ROOT, "tests")]))
    runs = [subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                           text=True, timeout=600) for _ in range(2)]
    for r in runs:
        assert r.returncode == 0, r.stderr
    assert int(runs[0].stdout.split()[-1]) > 0          # the first process compiled
    assert int(runs[1].stdout.split()[-1]) == 0         # the second loaded them
