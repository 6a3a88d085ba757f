"""Arvo's sampling of spherical triangles (engine/kernels/lights/spherical_triangle.py),
against closed forms: the solid angle of an octant and of a small far triangle, and
directions that all land inside the triangle with the density 1 / omega (the share that
lands in each of four sub-triangles is its solid angle's share). The full emissive-
triangle sampler, both of its branches, is checked by chi-square against its pdf in
tests/test_light_sampling.py."""
from __future__ import annotations

import math

import numpy as np
import pytest

from engine.kernels.lights.spherical_triangle import sample_direction, solid_angle


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def test_octant_and_a_far_triangle():
    assert solid_angle(1, 0, 0, 0, 1, 0, 0, 0, 1) == pytest.approx(math.pi / 2, rel=1e-12)
    # a triangle of area 0.5 at distance 1000, facing the origin: omega ~ A / d^2
    a, b, c = (_unit(p) for p in ([0, 0, 1000], [1, 0, 1000], [0, 1, 1000]))
    assert solid_angle(*a, *b, *c) == pytest.approx(0.5e-6, rel=1e-3)


def _inside(d, corners):
    """Whether each direction d passes inside the planar triangle of `corners`."""
    v0, v1, v2 = corners
    n = np.cross(v1 - v0, v2 - v0)
    t = (v0 @ n) / (d @ n)
    q = d * t[:, None]
    w = [np.cross(corners[(k + 1) % 3] - q, corners[(k + 2) % 3] - q) @ n for k in range(3)]
    return (t > 0) & (w[0] >= -1e-9) & (w[1] >= -1e-9) & (w[2] >= -1e-9)


@pytest.mark.parametrize("corners", [
    [[1.0, -0.5, 0.2], [0.3, 1.2, 0.1], [0.2, 0.1, 1.5]],           # a large near one
    [[0.2, 0.1, 1.0], [0.25, 0.1, 1.0], [0.2, 0.18, 1.02]],         # a small one
    [[-3.0, -1.0, 0.05], [3.0, -1.0, 0.05], [0.0, 4.0, 0.05]],      # grazing, wide
])
def test_directions_fill_the_triangle_with_density_one_over_omega(corners):
    v = np.asarray(corners, float)
    a, b, c = (_unit(p) for p in v)
    omega = solid_angle(*a, *b, *c)
    rng = np.random.default_rng(7)
    u = rng.random((40000, 2))
    d = np.array([sample_direction(*a, *b, *c, omega, u0, u1) for u0, u1 in u])
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)
    assert _inside(d, v).all()
    # four sub-triangles (corners and edge midpoints): shares by solid angle
    m = [(v[0] + v[1]) / 2, (v[1] + v[2]) / 2, (v[2] + v[0]) / 2]
    parts = [[v[0], m[0], m[2]], [m[0], v[1], m[1]], [m[2], m[1], v[2]], [m[0], m[1], m[2]]]
    for part in parts:
        p = np.asarray(part)
        share = solid_angle(*_unit(p[0]), *_unit(p[1]), *_unit(p[2])) / omega
        got = _inside(d, p).mean()
        assert abs(got - share) < 4 * math.sqrt(share * (1 - share) / len(d)) + 1e-3, \
            (got, share)
