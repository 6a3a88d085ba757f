"""The hierarchy over moving objects (engine/kernels/motion_tlas.py, walked by
engine/kernels/motion_trace.py) against brute force: random rays through scenes of many
rigidly moving (translating, turning by more than 90 degrees, scaling, shearing) and
deforming objects, small ones intersected in the kernel and large ones by Embree, among
static geometry, give the same hits and the same occlusion as every ray against every
object; the swept boxes hold each object at every time; bounds that ignore the motion
between steps (the negative control) do miss hits; and a ray visits few objects."""
from __future__ import annotations

import numpy as np
import pytest

from engine.accel import KERNEL_TRIANGLES, Accelerator
from engine.kernels.motion import rigid_at
from engine.motion import DeformMotion, RigidMotion
from engine_scenes import box, quad, uv_sphere


def rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    return m


def translation(v):
    m = np.eye(4)
    m[:3, 3] = v
    return m


def random_rigid_motion(rng, centre, size):
    """2 to 4 motion steps: a translation of about the object's size or more, a turn
    of up to a full revolution over the shutter about a random axis, a non-uniform
    scale and a fixed shear (mirrored one time in five)."""
    steps = int(rng.integers(2, 5))
    times = np.linspace(0.0, 1.0, steps)
    velocity = rng.normal(0.0, 2.0 * size, 3)
    axis, spin = rng.normal(size=3), rng.uniform(0.0, 2.0 * np.pi)
    grow = rng.uniform(-0.5, 1.5, 3)
    shear = np.eye(4)
    shear[0, 1] = rng.uniform(-0.5, 0.5)
    if rng.random() < 0.2:
        shear[2] *= -1.0
    mats = [translation(centre + t * velocity) @ rotation(axis, t * spin)
            @ np.diag([*(1.0 + t * grow), 1.0]) @ shear for t in times]
    return RigidMotion(times, np.stack(mats))


def moving_scene(rng, count, scale=1.0, offset=0.0):
    """Static floor and boxes, then `count` moving objects: 3 in 10 large (a 528-triangle
    sphere, above KERNEL_TRIANGLES: Embree), the rest 12-triangle boxes (kernel); 1 in 4
    deforming (4 time slices), the rest rigid."""
    s = scale

    def at(*p):
        return np.array(p) * s + offset

    meshes = [quad(at(0.0, 0.0, -2.0), (5 * s, 0, 0), (0, 5 * s, 0), "floor"),
              box(at(-1.0, -1.0, -1.0), at(-0.6, 1.0, 0.0)), box(at(0.5, -0.3, 0.0), at(0.9, 0.3, 2.0))]
    for i in range(count):
        centre = rng.uniform(-2.0, 2.0, 3) * s + offset
        if rng.random() < 0.3:
            mesh = uv_sphere((0, 0, 0), 0.3 * s, 12, 24, f"big{i}")
            assert len(mesh.triangles) > KERNEL_TRIANGLES
        else:
            mesh = box(np.array([-0.2, -0.1, -0.15]) * s, np.array([0.2, 0.1, 0.15]) * s,
                       f"small{i}")
        if rng.random() < 0.25:
            start = mesh.positions + centre
            end = start + rng.normal(0.0, 0.3 * s, start.shape)
            mesh.motion = DeformMotion([0.0, 1.0], np.stack([start, end]), slices=4)
        else:
            mesh.motion = random_rigid_motion(rng, centre, 0.3 * s)
        meshes.append(mesh)
    return meshes


def random_rays(rng, n, scale=1.0, offset=0.0):
    o = rng.uniform(-3.0, 3.0, (n, 3)) * scale + offset
    d = rng.normal(size=(n, 3))
    return o, d / np.linalg.norm(d, axis=1, keepdims=True), rng.random(n)


def accelerators(meshes, **kw):
    """(hierarchy, brute force with the same kernel objects, brute force all-Embree)."""
    return (Accelerator(meshes, time_enabled=True, **kw),
            Accelerator(meshes, time_enabled=True, motion_tlas=False, **kw),
            Accelerator(meshes, time_enabled=True, motion_tlas=False, kernel_triangles=0))


@pytest.mark.parametrize("seed,scale,offset", [(0, 1.0, 0.0), (1, 1e-3, 0.0), (2, 1.0, 1e3),
                                               (3, 1e3, -50.0)])
def test_hits_and_occlusion_equal_brute_force(seed, scale, offset):
    rng = np.random.default_rng(seed)
    meshes = moving_scene(rng, 60, scale, offset)
    tlas, brute, embree = accelerators(meshes)
    assert tlas.tlas is not None and (tlas.tlas.unit_root >= 0).any() \
        and (tlas.tlas.unit_root < 0).any()            # both kinds of object present
    o, d, time = random_rays(rng, 20000, scale, offset)
    far = np.full(len(o), np.inf)
    a, b, c = (acc.intersect(o, d, far, time) for acc in (tlas, brute, embree))
    moving_hits = a.prim >= tlas.static_count
    assert moving_hits.mean() > 0.15 and (a.hit & ~moving_hits).mean() > 0.15
    # the same kernel objects: the same answer, bit for bit
    for field in ("t", "prim", "u", "v"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
    # all through Embree (float32): the same triangles, distances to float32 rounding
    assert (a.prim != c.prim).mean() <= 1e-3
    same = (a.prim == c.prim) & a.hit
    magnitude = abs(offset) + 6.0 * scale
    assert np.abs(a.t[same] - c.t[same]).max() <= 1e-5 * magnitude
    # occlusion over random segments
    seg = rng.uniform(0.0, 4.0, len(o)) * scale
    occ = [acc.occluded(o, d, seg, time) for acc in (tlas, brute, embree)]
    assert 0.2 < occ[0].mean() < 0.8
    np.testing.assert_array_equal(occ[0], occ[1])
    assert (occ[0] != occ[2]).mean() <= 1e-3
    # small batches: more (ray, object) pairs than the first guess of the pair buffer
    small = slice(0, 40)
    h = brute.intersect(o[small], d[small], far[small], time[small])
    np.testing.assert_array_equal(h.prim, a.prim[small])
    np.testing.assert_array_equal(brute.occluded(o[small], d[small], seg[small], time[small]),
                                  occ[0][small])


def test_bounds_at_the_steps_only_miss_hits():
    """Negative control: items bounded by the object at the start of each interval (no
    sweep) lose the hits of the objects' later positions."""
    rng = np.random.default_rng(5)
    tlas, brute, _ = accelerators(moving_scene(rng, 60))
    o, d, time = random_rays(rng, 20000)
    far = np.full(len(o), np.inf)
    reference = brute.intersect(o, d, far, time)
    tlas.build_tlas(swept=False)
    unswept = tlas.intersect(o, d, far, time)
    moving = reference.prim >= brute.static_count
    assert (unswept.prim != reference.prim).sum() > 0.05 * moving.sum()
    tlas.build_tlas()
    np.testing.assert_array_equal(tlas.intersect(o, d, far, time).prim, reference.prim)


def _escapes(accel, rng, samples=64):
    """How many (item, time, vertex) placements of the rigid objects' vertices fall
    outside their item's box, over `samples` times in each item's time range."""
    t = accel.tlas
    out = 0
    for it in range(len(t.item_box)):
        obj = accel.moving[t.unit_obj[t.item_unit[it]]]
        if not obj.rigid:
            continue
        t0, t1 = max(t.item_time[it, 0], 0.0), min(t.item_time[it, 1], 1.0)
        times = np.concatenate([[t0, np.nextafter(t1, t0)], rng.uniform(t0, t1, samples)])
        m = obj.mesh.motion.at(times)
        world = np.einsum("kij,vj->kvi", m[:, :3, :3], obj.mesh.positions) + m[:, None, :3, 3]
        lo, hi = t.item_box[it, :3], t.item_box[it, 3:]
        out += int(((world < lo) | (world > hi)).any(axis=2).sum())
    return out


def test_swept_boxes_hold_the_objects_at_every_time():
    """Property test over random motions (turns up to a full revolution, scaling, shear):
    every vertex at many times of each item's time range lies in the item's box; the
    unswept boxes of the negative control do not hold them."""
    rng = np.random.default_rng(11)
    for trial in range(20):
        meshes = [box((-0.3, -0.2, -0.1), (0.4, 0.2, 0.1), f"b{k}") for k in range(5)]
        for mesh in meshes:
            mesh.motion = random_rigid_motion(rng, rng.uniform(-1, 1, 3), 0.3)
        accel = Accelerator(meshes, time_enabled=True)
        assert _escapes(accel, rng) == 0, trial
        deform_free = accel.tlas.item_slices.max() == 0
        assert deform_free
    accel.build_tlas(swept=False)
    assert _escapes(accel, rng) > 0


def test_kernel_transform_equals_rigid_motion():
    """engine.kernels.motion.rigid_at against RigidMotion.at, at random times (before,
    within and after the steps)."""
    rng = np.random.default_rng(2)
    meshes = [box((-1, -1, -1), (1, 1, 1), f"b{k}") for k in range(6)]
    for mesh in meshes:
        mesh.motion = random_rigid_motion(rng, rng.uniform(-5, 5, 3), 1.0)
    accel = Accelerator(meshes, time_enabled=True)
    M = accel.motion
    times = np.concatenate([[-0.5, 0.0, 1.0, 1.5], rng.random(40)])
    for obj, moving in enumerate(accel.moving):
        ref = moving.mesh.motion.at(times)
        got = np.array([rigid_at(M.info, M.step_time, M.step_trans, M.step_quat,
                                 M.step_stretch, M.step_linear, obj, t) for t in times])
        np.testing.assert_allclose(got[:, :9].reshape(-1, 3, 3), ref[:, :3, :3], atol=1e-13)
        np.testing.assert_allclose(got[:, 9:], ref[:, :3, 3], atol=1e-12)


def test_a_ray_visits_few_of_a_thousand_moving_objects():
    """1000 small moving cubes on a grid: with the hierarchy, the (ray, object) pairs
    examined are a small fraction of rays x objects (brute force examines all of them),
    with the same hits."""
    rng = np.random.default_rng(4)
    meshes = [quad((0, 0, -1.0), (30, 0, 0), (0, 30, 0), "floor")]
    for i in range(1000):
        centre = np.array([i % 40 - 20.0, i // 40 - 12.5, 0.0]) + rng.uniform(-0.2, 0.2, 3)
        cube = box((-0.25, -0.25, -0.25), (0.25, 0.25, 0.25), f"cube{i}")
        cube.motion = RigidMotion([0.0, 1.0], [translation(centre), translation(
            centre + rng.normal(0, 0.3, 3)) @ rotation(rng.normal(size=3), rng.uniform(0, 3))])
        meshes.append(cube)
    n = 2000
    o = np.tile([0.0, 0.0, 30.0], (n, 1))
    target = np.column_stack([rng.uniform(-20, 20, n), rng.uniform(-13, 13, n), np.zeros(n)])
    d = target - o
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    time, far = rng.random(n), np.full(n, np.inf)
    tlas = Accelerator(meshes, time_enabled=True)
    brute = Accelerator(meshes, time_enabled=True, motion_tlas=False)
    a = tlas.intersect(o, d, far, time)
    b = brute.intersect(o, d, far, time)
    np.testing.assert_array_equal(a.prim, b.prim)
    assert (a.prim >= tlas.static_count).mean() > 0.2
    assert brute.pairs_visited == n * 1000
    per_ray = tlas.pairs_visited / n
    print(f"pairs visited per ray: {per_ray:.2f} of 1000 objects")
    assert per_ray < 10
