"""Rays that start on a surface and name it, as Cycles casts them
(engine.embree.self_hits, engine.kernels.ray_origin).

Oracles: exact float32 geometry (every coordinate below is a float32 with room to spare),
so a ray starting on a plane meets that plane at t = 0 exactly; whatever is hit or passed
is decided by the names alone."""
from __future__ import annotations

import numpy as np
import pytest

from engine.accel import Accelerator
from engine.embree.self_hits import INSIDE
from engine.scene import Instances, TriangleMesh


def quad(z=0.0, size=1.0, name="quad"):
    """Two triangles covering [-size, size]^2 at height z, facing +z."""
    p = np.array([[-size, -size, z], [size, -size, z], [size, size, z], [-size, size, z]])
    return TriangleMesh(name, p, np.array([[0, 1, 2], [0, 2, 3]], np.int32),
                        np.zeros(2, np.int32))


@pytest.fixture(scope="module")
def coincident():
    """A floor (triangles 0, 1), its coincident copy (2, 3) and a ceiling (4, 5) at z=1."""
    acc = Accelerator([quad(), quad(name="copy"), quad(1.0, name="ceiling")], threads=1)
    yield acc
    acc.close()


def test_a_ray_names_its_triangle_and_meets_a_coincident_face_at_distance_zero(coincident):
    """Cycles' self test: the named triangle is passed, nothing else is: the coincident
    copy is hit at t = 0 (why a cube resting on a floor or a mirrored mesh's doubled faces
    render as they do in Cycles); without a name the ray meets its own triangle."""
    o = np.array([[0.25, -0.5, 0.0]] * 2)          # inside triangle 0
    up = np.array([[0.0, 0.0, 1.0]] * 2)
    named = coincident.intersect(o, up, np.full(2, np.inf), skip=np.array([[0, -1], [-1, -1]]))
    assert named.prim[0] in (2, 3) and named.t[0] == 0.0
    assert named.prim[1] in (0, 2, 3) and named.t[1] == 0.0
    # leaving the copy as well: the ceiling, at its distance to two float32 ulps (how
    # Embree divides depends on the CPU: 1.0 on some, 0.99999994 on a 2-core EPYC)
    acc = Accelerator([quad(), quad(1.0, name="ceiling")], threads=1)
    h = acc.intersect(o[:1], up[:1], np.full(1, np.inf), skip=np.array([[0, -1]]))
    assert h.prim[0] in (2, 3) and abs(h.t[0] - 1.0) <= 2 * np.finfo(np.float32).eps
    acc.close()


def test_a_shadow_ray_passes_the_triangle_it_leaves_and_the_one_it_goes_to(coincident):
    """occluded: blocked by the coincident copy whatever it names; between the ceiling and
    a floor-less scene, naming both ends lets the ray reach its light point exactly."""
    acc = Accelerator([quad(), quad(1.0, name="ceiling")], threads=1)
    o = np.array([[0.25, -0.5, 0.0]] * 3)
    up = np.array([[0.0, 0.0, 1.0]] * 3)
    far = np.ones(3)                                    # to the ceiling's point exactly
    skip = np.array([[0, -1, 2, -1], [0, -1, -1, -1], [-1, -1, 2, -1]])
    assert acc.occluded(o, up, far, skip=skip).tolist() == [False, True, True]
    assert coincident.occluded(o[:1], up[:1], np.full(1, 0.5),
                               skip=np.array([[0, -1, -1, -1]]))[0]
    acc.close()


def test_a_named_instance_triangle_is_passed_in_that_place_only():
    """Names are (global triangle, place): the same triangle of another place of the
    instanced mesh still blocks. Two places of one quad, both at z = 0."""
    mesh = quad()
    mesh.instances = Instances(np.stack([np.eye(4), np.eye(4)]))
    acc = Accelerator([mesh, quad(2.0, name="roof")], threads=1)
    base = acc.prototypes[0].prim_offset
    o = np.array([[0.25, -0.5, 0.0]] * 2)
    up = np.array([[0.0, 0.0, 1.0]] * 2)
    first = acc.intersect(o, up, np.full(2, np.inf), skip=np.array([[base, 0], [base, 1]]))
    assert first.t.tolist() == [0.0, 0.0]
    assert first.inst.tolist() == [1, 0]          # the other place's copy, at t = 0
    acc.close()


def test_hits_on_an_edge_are_reported_inside_their_triangle_and_leave_cleanly():
    """A hit exactly on the diagonal two triangles share is reported INSIDE one of them
    (Cycles' self test then passes, engine.embree.rays.inside), so a ray leaving the
    point rebuilt from it and naming that triangle meets neither: not its neighbour at
    distance 0. Hits away from edges keep Embree's barycentrics."""
    acc = Accelerator([quad()], threads=1)
    o = np.array([[0.5, 0.5, 1.0], [0.25, -0.5, 1.0]])
    down = np.array([[0.0, 0.0, -1.0]] * 2)
    h = acc.intersect(o, down, np.full(2, np.inf))
    w = 1.0 - h.u - h.v
    assert min(h.u[0], h.v[0], w[0]) >= INSIDE * (1 - 1e-12)
    assert max(h.u[0], h.v[0], w[0]) > 0.25          # on the diagonal: two weights ~1/2
    tri = acc.triangles[h.prim[0]]
    p = (w[0] * acc.positions[tri[0]] + h.u[0] * acc.positions[tri[1]]
         + h.v[0] * acc.positions[tri[2]])
    assert p[2] == 0.0 and abs(p[0] - 0.5) < 1e-6 and abs(p[1] - 0.5) < 1e-6
    ways = np.array([[0.3, -0.2, 1.0], [-0.3, 0.2, 1.0], [0.0, 0.0, 1.0]])
    ways /= np.linalg.norm(ways, axis=1)[:, None]
    up = acc.intersect(np.tile(p, (3, 1)), ways, np.full(3, np.inf),
                       skip=np.tile([h.prim[0], -1], (3, 1)))
    assert (up.prim == -1).all()
    # inside a triangle: Embree's own barycentrics (float32), untouched
    assert (h.u[1], h.v[1]) == (np.float64(np.float32(h.u[1])), np.float64(np.float32(h.v[1])))
    assert min(h.u[1], h.v[1], w[1]) > 0.1
    acc.close()
