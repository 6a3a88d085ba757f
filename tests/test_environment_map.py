"""The environment map (engine.environment_map) and its sampling distribution
(engine.piecewise_2d): the equirectangular convention, the distribution against its
function, the map's direction sampler against its own pdf (chi-square, tests/chi2.py),
the pdf's integral over the sphere, and the compiled twin (engine.kernels.lights
.environment_map through the packed light set) against the NumPy code.

Chi-square in the map's own coordinates: a sampled world direction d is taken to the
map's frame (M d / |M d|, computed here, not by the model) and to its equirectangular
(u, v), which is drawn on the harness's sphere as the chart point cos(theta) = 2 v - 1,
phi = pi (2 u - 1) (constant Jacobian 4 pi); the harness's uniform grid of H x W cells
is then exactly the texel grid, so every cell integral is of a smooth function (the
pdf is piecewise constant per texel in (u, v)). The chart density is
    pdf(d) x d(omega_world)/d(omega_map) x 2 pi^2 sin(theta) / (4 pi),
with d(omega_world)/d(omega_map) = |M d|^3 / |det M| written out here again, so the
test checks the model's pdf, Jacobian included, against its sampler.
"""
from __future__ import annotations

import zlib

import numpy as np
import pytest
from numba import typeof

from chi2 import chi2_test, directions, spherical
from engine.environment_map import EnvironmentMap, direction_to_uv, uv_to_direction
from engine.kernels.lights import (environment_pdf, lamp_pdf, pack_lights, sample,
                                   world_escaped)
from engine.kernels.lights.batch import sample_batch
from engine.lights import LightSet
from engine.piecewise_2d import PiecewiseConstant2D
from engine.scene import PointLight, World
from engine.textures import Texture
from engine.world_light import world_model

N_CHI2 = 1_000_000
N_TESTS = 4            # chi-square tests in this module (Sidak correction)
RTOL = 1e-9


def rotation_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rotation_x(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


MAPPINGS = {
    "identity": None,
    "rotation": rotation_z(1.1) @ rotation_x(0.4),
    "scale": rotation_z(-0.7) @ np.diag([1.0, 2.5, 0.6]) @ rotation_x(0.3),
}


def random_map(width=32, height=16, seed=0, srgb=False):
    """Random texels with two black rows and a black column, a bright 2-texel blob."""
    rng = np.random.default_rng(seed)
    px = rng.random((height, width, 3)).astype(np.float32)
    px[3:5] = 0.0
    px[:, 7] = 0.0
    px[11, 20:22] = (400.0, 300.0, 200.0) if not srgb else (1.0, 1.0, 1.0)
    return px


def environment(interp="Linear", mapping="identity", srgb=False, **kw):
    tex = Texture(random_map(srgb=srgb, **kw), interp, "REPEAT", srgb=srgb)
    return EnvironmentMap(tex, (0.5, 1.0, 2.0), MAPPINGS[mapping])


def unit_rows(rng, n):
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


# ------------------------------------------------------------------ convention

def test_equirectangular_convention_and_inverse():
    """Cycles' direction_to_equirectangular (confirmed on Cycles 5.0 renders of a
    texel-coded image): +X is the image's centre, +Y a quarter from its left edge, -X
    its left and right edges, +Z its top row."""
    d = np.array([[1, 0, 0], [0, 1, 0], [0, -1, 0], [-1, 0, 0], [0, 0, 1], [0, 0, -1],
                  [1, 0, 1]], float)
    uv = direction_to_uv(d)
    np.testing.assert_allclose(uv[:4], [[0.5, 0.5], [0.25, 0.5], [0.75, 0.5], [0.0, 0.5]],
                               atol=1e-15)
    assert uv[4, 1] == 1.0 and uv[5, 1] == 0.0 and uv[6, 1] == pytest.approx(0.75)
    rng = np.random.default_rng(1)
    w = unit_rows(rng, 1000)
    back, sin_t = uv_to_direction(direction_to_uv(w))
    np.testing.assert_allclose(back, w, atol=1e-14)
    np.testing.assert_allclose(sin_t, np.hypot(w[:, 0], w[:, 1]), atol=1e-14)


# ------------------------------------------------------------------ distribution

def test_piecewise_constant_2d_samples_its_function():
    rng = np.random.default_rng(2)
    f = rng.random((6, 10)) ** 3
    f[2] = 0.0
    f[:, 4] = 0.0
    dist = PiecewiseConstant2D(f)
    uv, pdf = dist.sample(rng.random((400_000, 2)))
    r, c = dist.cell_of(uv)
    counts = np.bincount(r * 10 + c, minlength=60).reshape(6, 10)
    expected = f / f.sum() * len(uv)
    assert counts[f == 0].sum() == 0                     # black cells never sampled
    nz = f > 0
    chi2 = ((counts[nz] - expected[nz]) ** 2 / expected[nz]).sum()
    assert chi2 < nz.sum() + 6 * np.sqrt(2 * nz.sum())   # ~ mean + 6 sigma of chi2(k)
    np.testing.assert_allclose(pdf, f[r, c] / f.mean(), rtol=1e-12)
    np.testing.assert_allclose(dist.pdf(uv), pdf, rtol=0)
    # the pdf integrates to one over [0, 1]^2, and a black function is sampled uniformly
    assert dist.cell_pdf(*np.divmod(np.arange(60), 10)).mean() == pytest.approx(1.0)
    black = PiecewiseConstant2D(np.zeros((3, 4)))
    uv0, pdf0 = black.sample(rng.random((10, 2)))
    assert np.isfinite(uv0).all() and np.all(pdf0 == 1.0)


@pytest.mark.parametrize("interp,mapping", [("Linear", "identity"), ("Closest", "identity"),
                                            ("Linear", "rotation"), ("Linear", "scale")])
def test_map_directions_follow_the_pdf(interp, mapping):
    env = environment(interp, mapping)
    m = env.matrix
    inv = np.linalg.inv(m)
    det = abs(np.linalg.det(m))
    h, w = env.distribution.height, env.distribution.width

    def to_chart(d):
        dm = d @ m.T
        uv = direction_to_uv(dm)
        return directions(2.0 * uv[:, 1] - 1.0, np.pi * (2.0 * np.mod(uv[:, 0], 1.0) - 1.0))

    def sample(u):
        d, pdf = env.sample(u[:, 1:3])
        return to_chart(d), pdf > 0

    def pdf(wc):
        c, phi = spherical(wc)
        u, v = (phi / np.pi + 1.0) / 2.0, (c + 1.0) / 2.0
        dm, sin_t = uv_to_direction(np.stack([u, v], axis=1))
        d = dm @ inv.T
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        jac = np.linalg.norm(d @ m.T, axis=1) ** 3 / det
        return env.pdf(d) * jac * 2.0 * np.pi ** 2 * sin_t / (4.0 * np.pi)

    res = chi2_test(sample, pdf, N_CHI2, seed=zlib.crc32(f"{interp}{mapping}".encode()) % 1000,
                    n_tests=N_TESTS, rows=h, cols=w, adaptive=False)
    print(interp, mapping, res)
    assert res.passed, str(res)


def _sphere_grid(n, rng):
    """One random point in each cell of an n x 2n grid in (cos theta, phi): cells of equal
    solid angle 4 pi / 2n^2, so 4 pi x the mean of f over the points is an unbiased
    estimate of the integral of f, whose error comes only from the cells a jump of f
    crosses."""
    c = (np.arange(n)[:, None] + rng.random((n, 2 * n))) / n * 2.0 - 1.0
    p = (np.arange(2 * n)[None, :] + rng.random((n, 2 * n))) / (2 * n) * 2.0 * np.pi
    return directions(c.ravel(), p.ravel())


@pytest.mark.parametrize("mapping", ["identity", "rotation", "scale"])
def test_pdf_integrates_to_one_over_the_sphere(mapping):
    """Jittered grid of 8M cells (not aligned with the texels, so this checks the solid
    angle measure independently of the sampler); a pdf without the mapping's Jacobian
    misses by far more."""
    env = environment("Linear", mapping)
    d = _sphere_grid(2000, np.random.default_rng(4))
    pdf = env.pdf(d)
    integral = pdf.mean() * 4.0 * np.pi
    print(mapping, "integral", integral)
    assert abs(integral - 1.0) < 1e-3
    if mapping == "scale":
        jac = env.abs_det / np.linalg.norm(d @ env.matrix.T, axis=1) ** 3
        assert abs((pdf / jac).mean() * 4.0 * np.pi - 1.0) > 0.05


# ------------------------------------------------------------------ compiled twin

@pytest.mark.parametrize("interp,mapping,srgb", [("Linear", "identity", False),
                                                 ("Closest", "rotation", False),
                                                 ("Linear", "scale", True)])
def test_compiled_twin_matches_numpy(interp, mapping, srgb):
    env = environment(interp, mapping, srgb)
    world = World(texture=env.texture, strength=tuple(env.strength), mapping=env.matrix)
    ls = LightSet([PointLight((0, 0, 2), (50.0, 50.0, 50.0))], 3.0, world=world_model(world))
    L = pack_lights(ls)
    k_env = ls.env_index
    rng = np.random.default_rng(3)
    n = 4000
    p = rng.normal(size=(n, 3))
    up, u = rng.random(n), rng.random((n, 2))
    k, wi, dist, rad, pdf, delta, _ = sample_batch(L, p, up, u)
    s, idx, dl = ls.sample(p, up, u)
    assert np.array_equal(k, idx) and (k == k_env).sum() > n // 4
    env_rows = k == k_env
    np.testing.assert_allclose(wi[env_rows], s.wi[env_rows], rtol=0, atol=1e-12)
    np.testing.assert_allclose(pdf, s.pdf, rtol=RTOL)
    np.testing.assert_allclose(rad, s.radiance, rtol=RTOL, atol=1e-300)
    assert np.all(np.isinf(dist[env_rows])) and not delta[env_rows].any()
    # escaped rays: radiance and MIS pdf along any direction, and the lamp pdf
    d = np.concatenate([unit_rows(rng, 2000), s.wi[env_rows][:500]])
    got = np.array([world_escaped(L, np.zeros(3), 2, *x) for x in d])
    np.testing.assert_allclose(got[:, :3], env.radiance(d), rtol=RTOL, atol=1e-300)
    np.testing.assert_allclose(got[:, 3], ls.environment_pdf(d), rtol=RTOL)
    assert np.all([environment_pdf(L, *x) for x in d[:50]] == got[:50, 3])
    assert np.all([lamp_pdf(L, k_env, 0.0, 0.0, 0.0, *x, np.inf, 0.0) for x in d[:50]]
                  == got[:50, 3])
    one = sample(L, *p[0], up[0], *u[0], 0.0)
    assert one[0] == k[0] and one[8] == pdf[0]


def test_world_hidden_from_camera_rays_is_black_for_them():
    env = environment()
    world = World(texture=env.texture, visibility=31 & ~1)      # camera off
    L = pack_lights(LightSet([], 1.0, world=world_model(world)))
    assert world_escaped(L, np.zeros(3), 1, 0.0, 0.0, 1.0) == (0.0, 0.0, 0.0, 0.0)
    assert world_escaped(L, np.zeros(3), 2, 0.0, 0.0, 1.0)[0] > 0.0     # diffuse rays


def test_one_compilation_serves_maps_and_uniform_worlds():
    env = environment()
    with_map = LightSet([], 1.0, world=world_model(World(texture=env.texture)))
    uniform = LightSet([], 1.0, world=(0.2, 0.3, 0.4))
    assert typeof(pack_lights(with_map)) == typeof(pack_lights(uniform)) \
        == typeof(pack_lights(LightSet([], 1.0)))


def test_bad_mapping_is_refused_clearly():
    tex = Texture(np.ones((4, 8, 3), np.float32))
    with pytest.raises(ValueError, match="invertible"):
        EnvironmentMap(tex, mapping=np.diag([1.0, 0.0, 1.0]))
    with pytest.raises(ValueError, match="invertible"):
        EnvironmentMap(tex, mapping=np.full((3, 3), np.nan))
