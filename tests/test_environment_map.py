"""The environment map (engine.environment_map, its distribution engine.piecewise_2d,
sampled by the kernels of engine.kernels.lights.environment_map through the packed light
set): the equirectangular convention, the map's direction sampler against its own pdf
(chi-square, tests/chi2.py; black texels are never sampled), the pdf's integral over the
sphere, the radiance of a texel against the image, and what an escaped ray sees against
what a light sample carries.

Chi-square in the map's own coordinates: a sampled world direction d is taken to the
map's frame (M d / |M d|, computed here, not by the model) and to its equirectangular
(u, v), which is drawn on the harness's sphere as the chart point cos(theta) = 2 v - 1,
phi = pi (2 u - 1) (constant Jacobian 4 pi); the harness's uniform grid of H x W cells
is then exactly the texel grid, so every cell integral is of a smooth function (the
pdf is piecewise constant per texel in (u, v)). The chart density is
    pdf(d) x d(omega_world)/d(omega_map) x 2 pi^2 sin(theta) / (4 pi),
with d(omega_world)/d(omega_map) = |M d|^3 / |det M| written out here again, so the
test checks the kernel's pdf, Jacobian included, against its sampler.
"""
from __future__ import annotations

import zlib

import numpy as np
import pytest
from numba import typeof

from chi2 import chi2_test, directions, spherical
from engine.environment_map import EnvironmentMap, direction_to_uv, uv_to_direction
from engine.kernels.lights import (OMNI, environment_pdf, lamp_pdf, pack_lights,
                                   world_escaped)
from engine.kernels.lights.batch import sample_batch, world_escaped_batch
from engine.lights import LightSet
from engine.scene import PointLight, World
from engine.textures import Texture
from engine.world_light import world_model

N_CHI2 = 1_000_000
N_TESTS = 4            # chi-square tests in this module (Sidak correction)


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


def world_of(env):
    return World(texture=env.texture, strength=tuple(env.strength), mapping=env.matrix)


def packed_world(env, lamps=()):
    """The kernels' light set of this map as the world (and lamps): (L, LightSet)."""
    ls = LightSet(list(lamps), 3.0, world=world_model(world_of(env)))
    return pack_lights(ls), ls


def map_sample(L, u, up=None):
    """Directions (n, 3) sampled from the world light with u (n, 2), and their pdfs."""
    n = len(u)
    up = np.full(n, 0.5) if up is None else up
    k, wi, dist, rad, pdf, delta, _, _ = sample_batch(L, np.zeros((n, 3)), up,
                                                   np.ascontiguousarray(u, np.float64))
    return wi, pdf, rad, k


def map_pdf(L, d):
    """The world light's solid-angle pdf along unit directions d (n, 3)."""
    return world_escaped_batch(L, np.zeros(3), np.ascontiguousarray(d, np.float64))[1]


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


# ------------------------------------------------------------------ sampling

@pytest.mark.parametrize("interp,mapping", [("Linear", "identity"), ("Closest", "identity"),
                                            ("Linear", "rotation"), ("Linear", "scale")])
def test_map_directions_follow_the_pdf(interp, mapping):
    env = environment(interp, mapping)
    L, _ = packed_world(env)
    m = env.matrix
    inv = np.linalg.inv(m)
    det = abs(np.linalg.det(m))
    h, w = env.distribution.height, env.distribution.width

    def to_chart(d):
        dm = d @ m.T
        uv = direction_to_uv(dm)
        return directions(2.0 * uv[:, 1] - 1.0, np.pi * (2.0 * np.mod(uv[:, 0], 1.0) - 1.0))

    def sample(u):
        d, pdf, _, _ = map_sample(L, u[:, 1:3])
        return to_chart(d), pdf > 0

    def pdf(wc):
        c, phi = spherical(wc)
        u, v = (phi / np.pi + 1.0) / 2.0, (c + 1.0) / 2.0
        dm, sin_t = uv_to_direction(np.stack([u, v], axis=1))
        d = dm @ inv.T
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        jac = np.linalg.norm(d @ m.T, axis=1) ** 3 / det
        return map_pdf(L, d) * jac * 2.0 * np.pi ** 2 * sin_t / (4.0 * np.pi)

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
    L, _ = packed_world(env)
    d = _sphere_grid(2000, np.random.default_rng(4))
    pdf = map_pdf(L, d)
    integral = pdf.mean() * 4.0 * np.pi
    print(mapping, "integral", integral)
    assert abs(integral - 1.0) < 1e-3
    if mapping == "scale":
        jac = env.abs_det / np.linalg.norm(d @ env.matrix.T, axis=1) ** 3
        assert abs((pdf / jac).mean() * 4.0 * np.pi - 1.0) > 0.05


# ------------------------------------------------------------------ radiance

@pytest.mark.parametrize("mapping", ["identity", "rotation", "scale"])
def test_an_escaped_ray_sees_the_texel_it_points_at(mapping):
    """With Closest interpolation, the direction through a texel's centre (the map's
    frame taken back to the world by the inverse mapping, computed here) sees that
    texel x the strength."""
    env = environment("Closest", mapping)
    L, _ = packed_world(env)
    h, w = env.texture.height, env.texture.width
    rows, cols = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    uv = np.stack([(cols.ravel() + 0.5) / w, (rows.ravel() + 0.5) / h], axis=1)
    dm, _ = uv_to_direction(uv)
    d = dm @ np.linalg.inv(env.matrix).T
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    rad, _ = world_escaped_batch(L, np.zeros(3), d)
    texels = random_map()[rows.ravel(), cols.ravel()] * env.strength
    np.testing.assert_allclose(rad, texels, rtol=1e-6)


@pytest.mark.parametrize("interp,mapping,srgb", [("Linear", "identity", False),
                                                 ("Closest", "rotation", False),
                                                 ("Linear", "scale", True)])
def test_light_samples_carry_what_escaped_rays_see(interp, mapping, srgb):
    """Beside a lamp, the world light's samples carry the radiance and the pdf that an
    escaped ray along the same direction finds (what MIS weighs it against), and the
    lamp pdf of the world entry is that pdf too."""
    env = environment(interp, mapping, srgb)
    L, ls = packed_world(env, [PointLight((0, 0, 2), (50.0, 50.0, 50.0))])
    k_env = ls.env_index
    rng = np.random.default_rng(3)
    n = 4000
    d, pdf, rad, k = map_sample(L, rng.random((n, 2)), rng.random(n))
    env_rows = k == k_env
    assert env_rows.sum() > n // 8          # (the light tree favours the lamp 2 m away)
    seen, pdf_seen = world_escaped_batch(L, np.zeros(3), np.ascontiguousarray(d[env_rows]))
    np.testing.assert_allclose(rad[env_rows], seen, rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(pdf[env_rows], pdf_seen, rtol=1e-12)
    recv = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, OMNI, 0.0)       # the origin, as map_sample's
    for x in d[env_rows][:50]:
        assert environment_pdf(L, *x, recv, 0.0) == world_escaped(L, np.zeros(3), 2, *x,
                                                                  recv, 0.0)[3]
        assert lamp_pdf(L, k_env, recv, *x, np.inf, 0.0) == environment_pdf(L, *x, recv,
                                                                            0.0)


def test_world_hidden_from_camera_rays_is_black_for_them():
    env = environment()
    world = World(texture=env.texture, visibility=31 & ~1)      # camera off
    L = pack_lights(LightSet([], 1.0, world=world_model(world)))
    recv = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, OMNI, 0.0)
    assert world_escaped(L, np.zeros(3), 1, 0.0, 0.0, 1.0, recv, 0.0) == (0.0, 0.0, 0.0, 0.0)
    assert world_escaped(L, np.zeros(3), 2, 0.0, 0.0, 1.0, recv, 0.0)[0] > 0.0   # diffuse


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
