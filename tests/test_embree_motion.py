"""Moving objects traced by Embree's own motion blur (engine/accel.py): rigid objects as
instances with one quaternion decomposition per motion step, deforming ones as triangles
with one vertex buffer per step. Against an oracle that shares none of that code (every
ray against every triangle in float64, each object placed at the ray's own time by
engine.motion's definitions): random rays through scenes of many moving objects
(translating, turning by up to a full revolution, scaling, shearing, mirrored, deforming)
among static geometry, at scales from 1e-3 to 1e3 and away from the origin, give the same
hits and the same occlusion; the kernels rebuild each hit where the oracle finds it; and
the negative control, objects frozen at mid-shutter, does not."""
from __future__ import annotations

import numpy as np
import pytest

from engine.accel import Accelerator
from engine.kernels.motion import rigid_at
from engine.motion import DeformMotion, RigidMotion
from engine.surface import SurfaceBuilder
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
    """Static floor and boxes, then `count` moving objects: 3 in 10 spheres of 528
    triangles, the rest 12-triangle boxes; 1 in 4 deforming (2 or 3 steps), the rest
    rigid."""
    s = scale

    def at(*p):
        return np.array(p) * s + offset

    meshes = [quad(at(0.0, 0.0, -2.0), (5 * s, 0, 0), (0, 5 * s, 0), "floor"),
              box(at(-1.0, -1.0, -1.0), at(-0.6, 1.0, 0.0)),
              box(at(0.5, -0.3, 0.0), at(0.9, 0.3, 2.0))]
    for i in range(count):
        centre = rng.uniform(-2.0, 2.0, 3) * s + offset
        if rng.random() < 0.3:
            mesh = uv_sphere((0, 0, 0), 0.3 * s, 12, 24, f"big{i}")
        else:
            mesh = box(np.array([-0.2, -0.1, -0.15]) * s, np.array([0.2, 0.1, 0.15]) * s,
                       f"small{i}")
        if rng.random() < 0.25:
            k = int(rng.integers(2, 4))
            start = mesh.positions + centre
            steps = [start + rng.normal(0.0, 0.3 * s, start.shape) * j for j in range(k)]
            mesh.motion = DeformMotion(np.linspace(0.0, 1.0, k), np.stack(steps))
        else:
            mesh.motion = random_rigid_motion(rng, centre, 0.3 * s)
        meshes.append(mesh)
    return meshes


def random_rays(rng, n, scale=1.0, offset=0.0):
    o = rng.uniform(-3.0, 3.0, (n, 3)) * scale + offset
    d = rng.normal(size=(n, 3))
    return o, d / np.linalg.norm(d, axis=1, keepdims=True), rng.random(n)


def _nearest(o, d, p0, p1, p2):
    """Every ray (n, 3) against every triangle (n or 1, T, 3) in float64
    (Moller-Trumbore, written out per component): (t, triangle) of the nearest hit,
    (inf, -1) where none."""
    e1, e2 = p1 - p0, p2 - p0
    e1x, e1y, e1z = e1[..., 0], e1[..., 1], e1[..., 2]
    e2x, e2y, e2z = e2[..., 0], e2[..., 1], e2[..., 2]
    dx, dy, dz = d[:, 0, None], d[:, 1, None], d[:, 2, None]
    qx, qy, qz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
    det = e1x * qx + e1y * qy + e1z * qz
    ok = np.abs(det) > 1e-300
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    sx = o[:, 0, None] - p0[..., 0]
    sy = o[:, 1, None] - p0[..., 1]
    sz = o[:, 2, None] - p0[..., 2]
    u = (sx * qx + sy * qy + sz * qz) * inv
    rx, ry, rz = sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x
    v = (dx * rx + dy * ry + dz * rz) * inv
    t = (e2x * rx + e2y * ry + e2z * rz) * inv
    t = np.where(ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0), t, np.inf)
    best = t.argmin(axis=1)
    tb = t[np.arange(len(o)), best]
    return tb, np.where(np.isfinite(tb), best, -1)


def _deformed(motion, time):
    """(n, V, 3): the deforming mesh at each ray's time, each vertex moving linearly from
    step to step (DeformMotion's definition, written here for many times at once)."""
    times, pos = motion.times, motion.positions
    if len(times) == 1:
        return np.broadcast_to(pos[0], (len(time),) + pos[0].shape)
    i = np.clip(np.searchsorted(times, time, side="right") - 1, 0, len(times) - 2)
    f = np.clip((time - times[i]) / (times[i + 1] - times[i]), 0.0, 1.0)[:, None, None]
    return pos[i] * (1 - f) + pos[i + 1] * f


def oracle(meshes, o, d, time, frozen=False):
    """(t, global triangle id) of each ray's nearest hit in the Accelerator's triangle
    order (static meshes, then moving ones), every object placed at the ray's time by
    RigidMotion.at / DeformMotion.positions_at (frozen: at mid-shutter, the control)."""
    n = len(o)
    best_t, best_prim = np.full(n, np.inf), np.full(n, -1)
    still = [m for m in meshes if m.motion is None]
    moving = [m for m in meshes if m.motion is not None]
    offset = 0
    for m in still + moving:
        tris = m.triangles
        at = np.full(n, 0.5) if frozen else time
        if m.motion is None:
            p = m.positions[tris][None]
            t, k = _nearest(o, d, p[:, :, 0], p[:, :, 1], p[:, :, 2])
        elif isinstance(m.motion, RigidMotion):
            mats = m.motion.at(at)
            inv = np.linalg.inv(mats)
            lo = np.einsum("nij,nj->ni", inv[:, :3, :3], o) + inv[:, :3, 3]
            ld = np.einsum("nij,nj->ni", inv[:, :3, :3], d)   # t is kept by an affine map
            p = m.positions[tris][None]
            t, k = _nearest(lo, ld, p[:, :, 0], p[:, :, 1], p[:, :, 2])
        else:
            world = _deformed(m.motion, at)                              # (n, V, 3)
            p = world[:, tris]                                          # (n, T, 3, 3)
            t, k = _nearest(o, d, p[:, :, 0], p[:, :, 1], p[:, :, 2])
        closer = t < best_t
        best_t[closer], best_prim[closer] = t[closer], k[closer] + offset
        offset += len(tris)
    return best_t, best_prim


@pytest.mark.parametrize("seed,scale,offset", [(0, 1.0, 0.0), (1, 1e-3, 0.0), (2, 1.0, 1e3),
                                               (3, 1e3, -50.0)])
def test_hits_and_occlusion_equal_the_oracle(seed, scale, offset):
    rng = np.random.default_rng(seed)
    meshes = moving_scene(rng, 40, scale, offset)
    accel = Accelerator(meshes, time_enabled=True)
    assert len(accel.moving) == 40 and any(not m.rigid for m in accel.moving)
    o, d, time = random_rays(rng, 3000, scale, offset)
    far = np.full(len(o), np.inf)
    hits = accel.intersect(o, d, far, time)
    t_ref, prim_ref = oracle(meshes, o, d, time)
    moving_hits = prim_ref >= accel.moving_start
    assert moving_hits.mean() > 0.1 and ((prim_ref >= 0) & ~moving_hits).mean() > 0.1
    same = hits.prim == prim_ref
    print(f"scale {scale}, offset {offset}: {100 * (1 - same.mean()):.3f} % of rays differ")
    assert same.mean() >= 0.998
    both = same & (prim_ref >= 0)
    magnitude = abs(offset) + 6.0 * scale
    assert np.abs(hits.t[both] - t_ref[both]).max() <= 1e-5 * magnitude
    # the kernels rebuild each hit at the ray's time where the oracle finds it
    surface = SurfaceBuilder(accel)
    idx = np.flatnonzero(both)
    built = surface.build(hits, idx, d, time)
    expected = o[idx] + t_ref[idx, None] * d[idx]
    assert np.abs(built.position - expected).max() <= 1e-5 * magnitude
    # occlusion over random segments
    seg = rng.uniform(0.0, 4.0, len(o)) * scale
    blocked = accel.occluded(o, d, seg, time)
    assert 0.2 < blocked.mean() < 0.8
    assert (blocked != (t_ref < seg)).mean() <= 2e-3
    # the control: every object frozen at mid-shutter (on a third of the rays)
    k = len(o) // 3
    _, prim_frozen = oracle(meshes, o[:k], d[:k], time[:k], frozen=True)
    assert (prim_frozen != hits.prim[:k]).mean() > 0.05


def test_steps_at_uneven_times_are_resampled_evenly():
    """Embree takes evenly spaced steps: a motion stepped at 0, 0.3 and 1 is traced on 11
    evenly spaced steps, on which it is the same motion (to Embree's linear interpolation
    of nearly equal rotations); steps on no grid of up to 129 are approximated by 129."""
    rng = np.random.default_rng(5)
    cube = box((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5), "cube")
    cube.motion = RigidMotion([0.0, 0.3, 1.0], [translation((0, 0, 0)),
                                                translation((1.0, 0.5, 0)) @ rotation((0, 0, 1), 1.0),
                                                translation((2.0, 0, 0)) @ rotation((1, 1, 0), 2.5)])
    accel = Accelerator([cube], time_enabled=True)
    resampled = accel.moving[0].motion
    assert len(resampled.times) == 11
    np.testing.assert_allclose(resampled.times, np.linspace(0, 1, len(resampled.times)))
    times = rng.random(200)
    err = np.abs(resampled.at(times) - cube.motion.at(times))[:, :3].max()
    print(f"resampled on {len(resampled.times)} steps: largest matrix difference {err:.2e}")
    assert err < 1e-5
    odd = RigidMotion([0.0, 1 / np.pi, 1.0], cube.motion.matrices).evenly_spaced()
    assert len(odd.times) == 129
    o, _, time = random_rays(rng, 3000)
    d = cube.motion.at(time)[:, :3, 3] + rng.uniform(-0.6, 0.6, o.shape) - o
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    hits = accel.intersect(o, d, np.full(len(o), np.inf), time)
    _, prim_ref = oracle([cube], o, d, time)
    assert (prim_ref >= 0).mean() > 0.3
    assert (hits.prim == prim_ref).mean() >= 0.99


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
        got = np.array([rigid_at(M.info, M.step_trans, M.step_quat, M.step_upper, obj, t)
                        for t in times])
        np.testing.assert_allclose(got[:, :9].reshape(-1, 3, 3), ref[:, :3, :3], atol=1e-13)
        np.testing.assert_allclose(got[:, 9:], ref[:, :3, 3], atol=1e-12)


def test_rigid_motion_decomposes_into_rotation_and_upper_scale():
    """The motion steps' decomposition (A = R U, Embree's quaternion decomposition) gives
    the step matrices back, U upper triangular with a positive diagonal but for a mirror,
    R a rotation."""
    rng = np.random.default_rng(3)
    for _ in range(20):
        motion = random_rigid_motion(rng, rng.uniform(-5, 5, 3), 1.0)
        np.testing.assert_allclose(motion.at(motion.times), motion.matrices, atol=1e-12)
        _, quat, upper = motion._decomposed
        np.testing.assert_allclose(np.linalg.norm(quat, axis=1), 1.0, atol=1e-12)
        assert np.all(np.tril(upper, -1) == 0.0)
        assert np.all(upper[:, 0, 0] > 0) and np.all(upper[:, 1, 1] > 0)
        mirrored = np.linalg.det(motion.matrices[:, :3, :3]) < 0
        np.testing.assert_array_equal(upper[:, 2, 2] < 0, mirrored)
