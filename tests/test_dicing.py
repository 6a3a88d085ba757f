"""engine.dicing, without Blender: Cycles' edge factors (closed forms of its rule), the
tessellation of one triangle for any three edge factors (every triangle wound as its
parent, none without area, the parent's area exactly covered, each edge cut into its
own factor) and of a mesh (watertight: neighbours share their edge's points, so every
inner edge has two triangles, one each way; attributes interpolated exactly).
Against Cycles: test_displacement_vs_cycles.py."""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from engine import dicing as D
from engine.camera import CameraModel
from engine.scene import Camera


def _check_template(ms):
    tp = D.template(*ms)
    xy = tp.weights[:, 1:3]                     # corner 0 at (0, 0), 1 at (1, 0), 2 at (0, 1)
    a, b, c = (xy[tp.triangles[:, k]] for k in range(3))
    cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    assert cross.min() > 1e-12, (ms, cross.min())          # wound as the parent, with area
    assert abs(cross.sum() / 2 - 0.5) < 1e-9, ms            # covers it exactly once
    np.testing.assert_allclose(tp.weights.sum(axis=1), 1.0, atol=1e-12)
    edges = np.sort(np.stack([tp.triangles, np.roll(tp.triangles, -1, axis=1)],
                             axis=2).reshape(-1, 2), axis=1)
    _, uses = np.unique(edges, axis=0, return_counts=True)
    assert uses.max() <= 2, ms
    assert (uses == 1).sum() == sum(ms), ms     # the boundary: each edge in its own factor
    return tp


def test_every_factor_triple_up_to_ten_tessellates_one_triangle_exactly():
    for ms in itertools.product(range(1, 11), repeat=3):
        tp = _check_template(ms)
        if ms[0] == ms[1] == ms[2]:
            assert len(tp.triangles) == ms[0] ** 2        # a regular grid


@settings(max_examples=40, deadline=None)
@given(st.tuples(st.integers(1, 70), st.integers(1, 70), st.integers(1, 70)))
def test_any_factor_triple_tessellates_one_triangle_exactly(ms):
    _check_template(ms)


def _grid(n=12, jitter=0.0, seed=0):
    xs = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(xs, xs)
    P = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], axis=1)
    P[:, :2] += np.random.default_rng(seed).uniform(-jitter, jitter, (len(P), 2)) / n
    a = (np.arange(n)[None, :] + np.arange(n)[:, None] * (n + 1)).ravel()
    T = np.concatenate([np.stack([a, a + 1, a + n + 2], 1), np.stack([a, a + n + 2, a + n + 1], 1)])
    return P, T


def test_a_mesh_diced_with_random_factors_is_watertight_and_keeps_its_area():
    P, T = _grid(jitter=0.3)
    edges, tri_edges = D.unique_edges(T)
    factors = np.random.default_rng(1).integers(1, 9, len(edges))
    d = D.dice(P, T, factors)
    p, t = d.positions, d.triangles
    normal_z = np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])[:, 2]
    assert normal_z.min() > 0.0                               # wound as the parents
    parent_area = np.cross(P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]])[:, 2]
    np.testing.assert_allclose(np.bincount(d.parent, normal_z), parent_area, rtol=1e-9)
    directed = np.stack([t, np.roll(t, -1, axis=1)], axis=2).reshape(-1, 2)
    assert len(np.unique(directed, axis=0)) == len(directed)  # no edge twice one way
    _, uses = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    boundary = np.bincount(tri_edges.ravel(), minlength=len(edges)) == 1
    assert uses.max() == 2 and (uses == 1).sum() == factors[boundary].sum()
    # every new corner and vertex interpolates its parent exactly
    np.testing.assert_allclose(D.interpolate_corners(P[T], d), p[t], atol=1e-12)
    np.testing.assert_allclose(D.interpolate_vertices(P, d), p, atol=1e-12)
    assert len(np.unique(np.round(p, 12), axis=0)) == len(p)  # no vertex twice


def test_factors_of_one_leave_the_mesh_and_a_uniform_factor_makes_n_squared():
    P, T = _grid(4)
    edges, _ = D.unique_edges(T)
    same = D.dice(P, T, np.ones(len(edges), int))
    np.testing.assert_array_equal(same.triangles, T)
    np.testing.assert_array_equal(same.positions, P)
    four = D.dice(P, T, np.full(len(edges), 4))
    assert len(four.triangles) == 16 * len(T)
    assert len(four.positions) == (4 * 4 + 1) ** 2               # a 16 x 16 grid
    assert D.tessellation_size(T, np.full(len(edges), 4)) >= len(four.triangles)


def test_object_space_factors_cut_edges_to_the_rate_up_to_the_limit():
    a = np.zeros((4, 3))
    b = np.array([[1.0, 0, 0], [0.25, 0, 0], [0.0, 0, 0], [100.0, 0, 0]])
    np.testing.assert_array_equal(D.edge_factors(a, b, 0.1, 64), [10, 3, 1, 64])
    bad = np.array([[np.nan, 0, 0], [np.inf, 0, 0], [1e100, 0, 0], [1e-300, 0, 0]])
    np.testing.assert_array_equal(D.edge_factors(a, bad, 0.1, 64), [1, 1, 64, 1])


def _camera(kind="PERSP", width=200, height=100):
    m = np.eye(4)
    m[:3, 3] = (0.0, 0.0, 10.0)                    # at z = 10, looking down -z
    return D.DicingCamera.from_model(CameraModel(Camera(m, kind=kind, ortho_scale=4.0),
                                                 width, height))


def test_pixel_space_factors_follow_the_distance_and_grow_off_screen():
    """An edge across the view, straight ahead at distance d: a pixel there is d times
    the pixel's angle (36 mm sensor on a 50 mm lens over 200 pixels), so a 1 m edge at
    rate r gets ceil(1 / (r d angle)) segments; twice as far, half as many. Beside the
    view, Cycles' offscreen scale (4) makes pixels larger by 3 angle x the distance
    outside the frustum."""
    cam = _camera()
    angle = 36.0 / 50.0 / 200
    for d in (2.0, 5.0, 20.0):
        a = np.array([[-0.5, 0.0, 10.0 - d]])
        b = np.array([[0.5, 0.0, 10.0 - d]])
        size = cam.raster_size(np.array([[0.0, 0.0, 10.0 - d]]))[0]
        assert size == pytest.approx(d * angle, rel=1e-3)
        assert D.edge_factors(a, b, 1.0, 4096, cam)[0] == pytest.approx(1.0 / (d * angle), abs=1.5)
    inside = cam.raster_size(np.array([[0.0, 0.0, 0.0]]))[0]
    beside = cam.raster_size(np.array([[30.0, 0.0, 0.0]]))[0]       # right of the frustum
    x_edge = 10.0 * 0.36                                               # frustum at x = 3.6
    outside = (30.0 - x_edge) / np.sqrt(1.0 + 0.36 ** 2)
    assert beside == pytest.approx(angle * (np.hypot(30.0, 10.0) + 3.0 * outside), rel=1e-3)
    assert beside > 5 * inside
    behind = cam.raster_size(np.array([[0.0, 0.0, 15.0]]))[0]        # behind the camera
    assert behind == pytest.approx(angle * 5.0 * 4.0, rel=1e-3)


def test_an_orthographic_camera_dices_by_its_pixel_size():
    cam = _camera("ORTHO")
    pixel = 4.0 / 200
    assert cam.raster_size(np.array([[1.0, 0.5, -30.0]]))[0] == pytest.approx(pixel)
    assert D.edge_factors(np.zeros((1, 3)), np.array([[1.0, 0, 0]]), 2.0, 4096,
                          cam)[0] == int(np.ceil(1.0 / (2.0 * pixel)))
    assert cam.raster_size(np.array([[5.0, 0.0, 0.0]]))[0] > pixel     # off screen
