"""Hair strands (engine.curves): Embree's round Catmull-Rom curves, shaded like any surface.

Closed forms: a straight strand of radius r, a convex tube, under a uniform white world
reflects exactly its albedo rho (every bounce leaves it for the world), so an
orthographic view of height H across which the strand runs sees a mean of
1 - (1 - rho) 2r / H, at every scene scale. Hit points rebuilt in float64 must be where
Embree found them, on a curved strand of varying radius."""
from __future__ import annotations

import numpy as np
import pytest

from engine import Camera, Material, RenderSettings, Scene, World, render
from engine.accel import Accelerator
from engine.curves import HairCurves
from engine.scene import Instances
from engine.surface import SurfaceBuilder
from engine_scenes import look_at, quad

RHO, R, H = 0.5, 0.1, 2.0


def strand(scale=1.0, radius=R, material=0, y=0.0):
    """A straight strand along x through (0, y, 0), longer than the view."""
    keys = np.array([[-3, y, 0], [-1, y, 0], [1, y, 0], [3, y, 0.0]]) * scale
    return HairCurves("strand", keys, np.full(4, radius * scale), [0, 4], materials=material)


def furnace(curves, materials, scale=1.0, size=32, meshes=()):
    cam = Camera(look_at((0, -5 * scale, 0), (0, 0, 0)), kind="ORTHO", ortho_scale=H * scale,
                 clip_start=1e-3 * scale, clip_end=100 * scale)
    return Scene(cam, size, size, list(meshes), materials, [], World((1, 1, 1)),
                 curves=curves)


def grey(rho=RHO, alpha=1.0):
    return Material("hair", (rho, rho, rho), specular_ior_level=0.0, alpha=alpha)


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e4])
def test_a_strand_in_a_furnace_reflects_its_albedo(scale):
    film, _ = render(furnace([strand(scale)], [grey()], scale),
                     RenderSettings(samples=64, seed=1, max_bounces=8))
    img = film.mean()
    assert np.all(np.isfinite(img))
    expected = 1 - (1 - RHO) * 2 * R / H
    got = img.mean()
    print(f"scale {scale:g}: mean {got:.5f}, closed form {expected:.5f}")
    assert abs(got - expected) < 0.002
    # the pixels the strand covers whole (its middle rows) are its albedo
    middle = img[15:17].mean(axis=(0, 2))
    assert np.allclose(middle, RHO, atol=0.03), middle


def test_a_half_transparent_strand_lets_half_the_light_through():
    """Alpha a = 0.5: rays go on through the strand's front wall with probability 1 - a
    (the transparent layers' rays, rebuilt from their own origins), and then leave it:
    the inside of its back wall is culled (engine.embree.curve_culling). The camera sees
    a rho + (1 - a)."""
    a = 0.5
    v = a * RHO + (1 - a)
    film, _ = render(furnace([strand()], [grey(alpha=a)]),
                     RenderSettings(samples=128, seed=2, max_bounces=16))
    expected = 1 - (1 - v) * 2 * R / H
    assert abs(film.mean().mean() - expected) < 0.002, (film.mean().mean(), expected)


def test_rays_meet_a_strand_only_where_they_enter_it():
    """Back-face culling of curves, as Cycles' Embree is built: a ray from outside hits
    the near wall; one starting inside the tube, or running down its axis into its open
    end, passes, for closest hits and for shadow rays alike."""
    accel = Accelerator([], curves=[strand()])
    o = np.array([[0, -5, 0], [0, 0, 0], [-10, 0, 0.0], [0, 0.05, 0], [0, 5, 0]])
    d = np.array([[0, 1, 0], [0, 1, 0], [1, 0, 0.0], [0, -1, 0], [0, -1, 0]])
    hits = accel.intersect(o, d, np.full(5, np.inf))
    assert hits.prim.tolist()[1:4] == [-1, -1, -1]
    assert hits.prim[0] >= 0 and hits.prim[4] >= 0
    np.testing.assert_allclose(hits.t[[0, 4]], 5 - R, rtol=1e-6)
    assert accel.occluded(o, d, np.full(5, 100.0)).tolist() == [True, False, False, False,
                                                               True]


def _curly():
    """Two strands: a helix of 9 keys with a radius tapering from 0.05 to 0.01, and a
    kinked 3-key strand."""
    a = np.linspace(0, 3 * np.pi, 9)
    helix = np.stack([0.5 * np.cos(a), 0.5 * np.sin(a), np.linspace(-1, 1, 9)], axis=1)
    kink = np.array([[-1.0, 0.3, -0.5], [0.2, 0.0, 0.1], [1.0, -0.2, 0.9]])
    keys = np.concatenate([helix, kink])
    radii = np.concatenate([np.linspace(0.05, 0.01, 9), [0.04, 0.03, 0.02]])
    return HairCurves("curly", keys, radii, [0, 9, 12])


def _spline(points, u):
    """Uniform Catmull-Rom through 4 control points (x, y, z, r) at u, in NumPy."""
    w = 0.5 * np.array([-u ** 3 + 2 * u ** 2 - u, 3 * u ** 3 - 5 * u ** 2 + 2,
                        -3 * u ** 3 + 4 * u ** 2 + u, u ** 3 - u ** 2])
    return w @ points


def test_hit_points_are_where_embree_found_them_on_the_tube():
    curves = _curly()
    accel = Accelerator([], curves=[curves])
    rng = np.random.default_rng(3)
    n = 20000
    target = rng.uniform([-1, -1, -1], [1, 1, 1], (n, 3))
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = target - 3 * d
    hits = accel.intersect(o, d, np.full(n, np.inf))
    hit = np.nonzero(hits.hit)[0]
    assert len(hit) > 300
    si = SurfaceBuilder(accel).build(hits, hit, d, origins=o)
    # the point Embree's float32 distance gives, and the float64 one rebuilt on the tube
    along = o[hit] + hits.t[hit, None] * d[hit]
    gap = np.linalg.norm(si.position - along, axis=1)
    assert np.max(gap) < 1e-4, np.max(gap)
    # on the sphere of the spline at u, its normal radial and facing the ray
    points, first = curves.control_points()
    seg = hits.prim[hit] - accel.curve_start
    rows = first[seg][:, None] + np.arange(4)
    u = hits.u[hit]
    cr = np.array([_spline(points[rows[k]], u[k]) for k in range(len(hit))])
    radial = np.linalg.norm(si.position - cr[:, :3], axis=1)
    assert np.allclose(radial, cr[:, 3], rtol=1e-9, atol=1e-12)
    assert np.allclose(np.linalg.norm(si.geometric_normal, axis=1), 1.0)
    assert np.all((si.geometric_normal * d[hit]).sum(1) <= 0.0)
    assert np.all(si.front_facing)
    assert np.array_equal(si.material, np.zeros(len(hit)))


def test_hair_beside_instanced_and_plain_meshes_names_each_hit():
    """Global ids: static triangles, then the strands' segments, then instanced meshes;
    a hit on each finds its own material (the dominant colour of what the camera sees)."""
    mats = [Material(n, c, specular_ior_level=0.0) for n, c in
            [("red", (0.9, 0.05, 0.05)), ("green", (0.05, 0.9, 0.05)),
             ("blue", (0.05, 0.05, 0.9))]]
    plain = quad((-0.65, 0, 0), (0.3, 0, 0), (0, 0, 0.9), "plain", material=0)
    placed = quad((0, 0, 0), (0.3, 0, 0), (0, 0, 0.9), "placed", material=2)
    m = np.eye(4)
    m[:3, 3] = (0.65, 0, 0)
    placed.instances = Instances(np.array([m]))
    hair = HairCurves("hair", [[0, 0.5, -2], [0, 0.5, -0.5], [0, 0.5, 0.5], [0, 0.5, 2]],
                      np.full(4, 0.2), [0, 4], materials=1)
    scene = furnace([hair], mats, meshes=[plain, placed])
    accel = Accelerator(scene.meshes, curves=scene.curves)
    assert accel.curve_start == 2 and accel.prototypes[0].prim_offset == 2 + 3
    film, _ = render(scene, RenderSettings(samples=16, seed=4, max_bounces=2))
    img = film.mean()
    row = img[16]
    assert np.argmax(row[5]) == 0 and np.argmax(row[16]) == 1 and np.argmax(row[26]) == 2, \
        row[[5, 16, 26]]


def test_a_scene_without_hair_builds_no_curve_geometry():
    """Principle 3: hair's cost is paid by the scenes that have it."""
    plain = quad((0, 0, 0), (1, 0, 0), (0, 0, 1))
    without = Accelerator([plain])
    assert "curves" not in without._scene.kinds
    assert without.packed_curves.first.shape == (0,)
    with_hair = Accelerator([plain], curves=[strand()])
    assert with_hair._scene.kinds.count("curves") == 1


def test_degenerate_strands_render_without_nan():
    """A strand whose keys coincide, one of radius 0, one far thinner than a pixel, and
    one of two keys: finite images, and the thin ones cover (almost) nothing."""
    same = HairCurves("point", np.zeros((3, 3)), np.full(3, 0.1), [0, 3])
    bare = strand(radius=0.0)
    thin = strand(radius=1e-7, y=0.3)
    short = HairCurves("short", [[-0.5, 0, 0.5], [0.5, 0, 0.5]], [0.05, 0.0], [0, 2])
    film, _ = render(furnace([same, bare, thin, short], [grey()]),
                     RenderSettings(samples=16, seed=5, max_bounces=4))
    img = film.mean()
    assert np.all(np.isfinite(img)) and img.max() <= 1.0 + 1e-9
    # the short tapering strand and the dot are seen; the rest is the world
    assert 0.95 < img.mean() < 1.0


def test_bad_strands_are_refused_with_a_clear_error():
    with pytest.raises(ValueError, match="non-finite"):
        HairCurves("nan", [[0, 0, 0], [np.nan, 0, 0]], [0.1, 0.1], [0, 2])
    with pytest.raises(ValueError, match="at least 2 keys"):
        HairCurves("one", [[0, 0, 0], [1, 0, 0], [2, 0, 0]], [0.1] * 3, [0, 1, 3])
    with pytest.raises(ValueError, match="negative"):
        HairCurves("neg", [[0, 0, 0], [1, 0, 0]], [0.1, -0.1], [0, 2])
    with pytest.raises(ValueError, match="material index"):
        Scene(Camera(np.eye(4)), 4, 4, [], [grey()], curves=[strand(material=3)])


def test_curves_info_reads_each_strand_where_it_is_hit():
    """The Curves (Hair) Info node's fields at a hit, emitted as a colour: Intercept (red)
    runs from 0 at the root to 1 at the tip, linear between keys; Thickness (green) is
    twice the radius, linear between keys; Random (blue) is Cycles' hash of the strand's
    index in its object (first_index 7 here). A strand of 5 evenly spaced keys from x = -2
    to 2 tapering from radius 0.2 to 0, seen from the front: at the middle row, in the
    interior segments the camera sees (x in [-1, 1]), every field is its closed form at
    the pixel's x."""
    from engine.nodes import context as C
    from engine.nodes import converter_nodes as V
    from engine.nodes import input_nodes as I
    from engine.nodes.hash import hash_uint2, uint_to_float
    from engine.nodes.program import ProgramBuilder
    b = ProgramBuilder()
    fields = [b.emit(I.IN_HIT1, "float", [f], varying=True) for f in
              (C.H_HAIR_INTERCEPT, C.H_HAIR_THICKNESS, C.H_HAIR_RANDOM)]
    b.output("emission", b.emit(V.CV_COMBINE, "color", fields))
    glow = Material("glow", (0.0, 0.0, 0.0), specular_ior_level=0.0, shader=b.build())
    keys = np.stack([np.linspace(-2, 2, 5), np.zeros(5), np.zeros(5)], axis=1)
    hair = HairCurves("taper", keys, np.linspace(0.2, 0.0, 5), [0, 5], first_index=7)
    cam = Camera(look_at((0, -5, 0), (0, 0, 0)), kind="ORTHO", ortho_scale=2.0)
    scene = Scene(cam, 32, 32, [], [glow], [], World((0, 0, 0)), curves=[hair])
    img = render(scene, RenderSettings(samples=16, seed=6, max_bounces=0))[0].mean()
    x = -1 + (np.arange(32) + 0.5) * 2 / 32
    row = img[15:17].mean(axis=0)
    seen = x <= 0.0                      # where the strand covers the middle rows whole
    np.testing.assert_allclose(row[seen, 0], (x[seen] + 2) / 4, atol=2e-3)
    np.testing.assert_allclose(row[seen, 1], 2 * (0.2 - 0.05 * (x[seen] + 2)), atol=2e-3)
    np.testing.assert_allclose(row[seen, 2], uint_to_float(hash_uint2(7, 0)), rtol=1e-6)
    # off hair (the world behind) nothing is emitted
    assert np.all(img[:8] == 0.0)


CULLED_IN_PYTHON = """
import numpy as np
from engine.accel import Accelerator
from engine.curves import HairCurves
h = HairCurves("s", [[-3, 0, 0], [-1, 0, 0], [1, 0, 0], [3, 0, 0]], np.full(4, 0.1), [0, 4])
a = Accelerator([], curves=[h])
o = np.array([[0, -5, 0], [0, 0, 0], [-10, 0, 0.0], [0, 0.05, 0], [0, 5, 0]])
d = np.array([[0, 1, 0], [0, 1, 0], [1, 0, 0.0], [0, -1, 0], [0, -1, 0]])
hits = a.intersect(o, d, np.full(5, np.inf))
print(hits.prim.tolist(), a.occluded(o, d, np.full(5, 100.0)).tolist())
"""


def test_the_culling_filter_runs_as_plain_python_too():
    """With NUMBA_DISABLE_JIT=1 (every kernel as the Python it is written in) the curve
    filter is a ctypes callback of the same Python: the same hits as compiled."""
    import os
    import subprocess
    import sys
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=root)
    proc = subprocess.run([sys.executable, "-c", CULLED_IN_PYTHON], cwd=root, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    accel = Accelerator([], curves=[strand()])
    o = np.array([[0, -5, 0], [0, 0, 0], [-10, 0, 0.0], [0, 0.05, 0], [0, 5, 0]])
    d = np.array([[0, 1, 0], [0, 1, 0], [1, 0, 0.0], [0, -1, 0], [0, -1, 0]])
    compiled = (accel.intersect(o, d, np.full(5, np.inf)).prim.tolist(),
                accel.occluded(o, d, np.full(5, 100.0)).tolist())
    assert proc.stdout.strip() == f"{compiled[0]} {compiled[1]}", (proc.stdout, compiled)
    assert compiled[0][1:4] == [-1, -1, -1]           # culled: what the filter decides


def test_random_counts_the_curves_the_export_leaves_out():
    """Cycles' Random of a strand is the hash of its index among its object's curves,
    one-point curves (which draw nothing) included: a strand after a left-out curve keeps
    its own index, here 2 (and 7 after first_index 5)."""
    from engine.curves import pack_curves
    from engine.nodes.hash import hash_uint2, uint_to_float
    keys = [[0, 0, 0], [0, 0, 1], [1, 0, 0], [1, 0, 1], [1, 0, 2]]
    hair = HairCurves("gap", keys, np.full(5, 0.1), [0, 2, 5], first_index=5,
                      strand_index=[0, 2])
    info = pack_curves([hair], 0).info
    want = [uint_to_float(hash_uint2(i, 0)) for i in (5, 7, 7)]   # one segment, then two
    np.testing.assert_allclose(info[:, 3], want, rtol=0, atol=0)
    with pytest.raises(ValueError):
        HairCurves("bad", keys, np.full(5, 0.1), [0, 2, 5], strand_index=[0, 1, 2])


def test_a_curves_object_keeps_the_index_of_each_curve(bpy_drt):
    """Exported from a Curves object of curves of 3, 1 and 3 points: two strands, the
    second with index 2 (the one-point curve's place kept, as Cycles numbers them)."""
    from drt_addon.export.hair import curves_object
    bpy = bpy_drt
    bpy.ops.wm.read_factory_settings(use_empty=True)
    data = bpy.data.hair_curves.new("Gappy")
    data.add_curves([3, 1, 3])
    data.attributes["position"].data.foreach_set(
        "vector", np.arange(21, dtype=np.float32) * 0.1)
    obj = bpy.data.objects.new("Gappy", data)
    bpy.context.scene.collection.objects.link(obj)
    hair = curves_object(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()),
                         np.eye(4), [0])
    assert hair.curve_count == 2
    np.testing.assert_array_equal(hair.strand_index, [0, 2])
    assert hair.triangles is hair.triangles            # computed once
