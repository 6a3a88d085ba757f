"""Each light's sampler against its own pdf, and next-event estimation against closed forms,
on the compiled light kernels (engine.kernels.lights, through their array drivers in
batch.py) that render.

1. Chi-square goodness of fit (tests/chi2.py, Mitsuba style, Sidak-corrected 1 % level over
   all the tests of this module): the directions `sample` returns must follow the pdf
   found the way multiple importance sampling finds it, through `hit_lamps` and
   `lamp_pdf` (a direction that misses the light has pdf 0).
   A light's support is a small, sharp-edged patch of the sphere, and Gauss-Legendre cell
   integrals of a discontinuous integrand are inaccurate; so each test bins its directions
   in a *chart*: a smooth bijection from the light's own parameter square (a, b) in
   [0,1]^2 onto the harness's sphere, cos(theta) = 2a - 1, phi = pi (2b - 1), which has
   constant Jacobian 4 pi. A sampled direction is mapped to the light point it reaches
   (ray-plane intersection in the test, not the light's code), then to (a, b); the density
   in the chart is pdf_omega(wi) x d(omega)/d(a, b) / (4 pi), smooth over the whole chart.
   Charts: planar (rectangle, parallelogram), polar (disk, ellipse), cone (sphere light,
   sun), triangles (one slab of a per triangle). Directions that fall outside the chart
   count as rejected samples, which fails the test (the pdf integrates to 1 over it).
2. Negative controls: a pdf that is wrong in shape (the area-sampling pdf offered for
   solid-angle samples) and a wrong light-selection pdf must both fail.
3. Irradiance by next-event estimation, E = mean(L cos / pdf) over 1e6 samples, against
   closed forms: on-axis rectangle and disk, Lambert's polygon formula (any polygon fully
   above the receiver's horizon), sphere light pi L sin^2(theta_max) cos(theta), sun
   E cos(theta); within 0.5 %.
4. Robustness: no NaN/Inf at the degenerate configurations listed in the issue.
"""
from __future__ import annotations

import zlib
from typing import NamedTuple

import numpy as np
import pytest

from chi2 import chi2_test, directions, spherical
from engine.kernels.lights import pack_lights
from engine.kernels.lights.batch import (hit_lamps_batch, lamp_pdf_batch, mesh_pdf_batch,
                                         sample_batch, sun_escaped_batch)
from engine.lights import (SOLID_ANGLE_MIN, AreaLightModel, LightSet, PointLightModel,
                           SunLightModel)
from engine.mesh_lights import EmissiveTriangles
from engine.scene import AreaLight, PointLight, SunLight

N_CHI2 = 1_000_000


def _seed(name: str) -> int:
    return zlib.crc32(name.encode()) % 100_000
N_TESTS = 20            # chi-square tests in this module (Sidak correction); see below
UP = np.array([0.0, 0.0, 1.0])


# ----------------------------------------------------------------------------- charts

def _ab_from_chart(w):
    c, phi = spherical(w)
    return 0.5 * (c + 1.0), (phi + np.pi) / (2.0 * np.pi)


def _chart_dir(a, b):
    return directions(2.0 * a - 1.0, np.pi * (2.0 * b - 1.0))


def _ray_plane(p, wi, origin, normal):
    den = wi @ normal
    with np.errstate(divide="ignore", invalid="ignore"):
        t = ((origin - p) @ normal) / den
    ok = np.isfinite(t) & (t > 0)
    return np.where(ok, t, np.nan), ok


class PlanarChart:
    """Points q = c + a e1 + b e2 (kind 'quad') or c + sqrt(a) (cos 2pi b e1 + sin 2pi b e2)
    (kind 'disk') of a planar light; dA = |e1 x e2| (quad) or pi |e1 x e2| (disk) da db."""

    def __init__(self, p, c, e1, e2, kind):
        self.p, self.c = np.asarray(p, float), np.asarray(c, float)
        self.e1, self.e2, self.kind = np.asarray(e1, float), np.asarray(e2, float), kind
        cr = np.cross(self.e1, self.e2)
        self.n = cr / np.linalg.norm(cr)
        self.dA = np.linalg.norm(cr) * (np.pi if kind == "disk" else 1.0)
        self.inv = np.linalg.inv(np.stack([self.e1, self.e2, self.n], 1))

    def point(self, a, b):
        if self.kind == "disk":
            r = np.sqrt(a)
            return self.c + (r * np.cos(2 * np.pi * b))[:, None] * self.e1 \
                + (r * np.sin(2 * np.pi * b))[:, None] * self.e2
        return self.c + a[:, None] * self.e1 + b[:, None] * self.e2

    def to_ab(self, wi):
        p = np.broadcast_to(self.p, wi.shape)
        t, ok = _ray_plane(p, wi, self.c, self.n)
        q = p + wi * np.nan_to_num(t)[:, None]
        st = (q - self.c) @ self.inv.T
        if self.kind == "disk":
            a = st[:, 0] ** 2 + st[:, 1] ** 2
            b = np.mod(np.arctan2(st[:, 1], st[:, 0]) / (2 * np.pi), 1.0)
        else:
            a, b = st[:, 0], st[:, 1]
        ok &= (a >= 0) & (a <= 1) & (b >= 0) & (b <= 1)
        return a, b, ok

    def jacobian(self, a, b):
        """d(omega)/d(a, b) and the direction to each chart point."""
        q = self.point(a, b)
        to = q - self.p
        d = np.linalg.norm(to, axis=1)
        wi = to / d[:, None]
        return np.abs(wi @ self.n) / (d * d) * self.dA, wi, d


class ConeChart:
    """Directions about `axis` with 1 - cos(theta) = a x om, phi = 2 pi b:
    d(omega) = 2 pi om da db."""

    def __init__(self, axis, om):
        self.axis = np.asarray(axis, float) / np.linalg.norm(axis)
        self.om = float(om)
        from engine.warp import orthonormal_basis
        t, b = orthonormal_basis(self.axis[None])
        self.t, self.b = t[0], b[0]

    def to_ab(self, wi):
        diff = wi - self.axis
        omc = 0.5 * (diff * diff).sum(1)                  # 1 - cos, cancellation-free
        a = omc / self.om
        b = np.mod(np.arctan2(wi @ self.b, wi @ self.t) / (2 * np.pi), 1.0)
        return a, b, (a >= 0) & (a <= 1)

    def jacobian(self, a, b):
        omz = a * self.om
        s = np.sqrt(np.maximum(0.0, omz * (2 - omz)))
        ph = 2 * np.pi * b
        wi = (s * np.cos(ph))[:, None] * self.t + (s * np.sin(ph))[:, None] * self.b \
            + (1 - omz)[:, None] * self.axis
        return np.full(len(a), 2 * np.pi * self.om), wi, None


def chart_chi2(sample_dirs, pdf_omega, chart, *, seed, rows=20, cols=20, adaptive=True,
               n=N_CHI2):
    """Run tests/chi2.py in `chart` space.

    sample_dirs(u2) -> (wi, valid); pdf_omega(wi, d) -> solid-angle pdf of wi (d: distance
    to the chart's point, None for cones)."""

    def sample(u):
        wi, valid = sample_dirs(u[:, 1:3])
        a, b, inside = chart.to_ab(wi)
        ok = np.asarray(valid, bool) & inside
        return _chart_dir(np.where(ok, a, 0.5), np.where(ok, b, 0.5)), ok

    def pdf(w):
        a, b = _ab_from_chart(w)
        jac, wi, d = chart.jacobian(a, b)
        return pdf_omega(wi, d) * jac / (4 * np.pi)

    return chi2_test(sample, pdf, n, seed=seed, n_tests=N_TESTS, rows=rows, cols=cols,
                     adaptive=adaptive)


# ----------------------------------------------------------------------------- lights

def area_light(shape, sx, sy=None, center=(0, 0, 1), matrix=None, strength=10.0):
    m = np.eye(4) if matrix is None else np.array(matrix, float)
    m[:3, 3] = center
    return AreaLight(m, (strength,) * 3, shape, sx, sy if sy is not None else sx)


def packed(*lights, mesh=None, radius=1.0):
    """The kernels' light tuple of these scene lights (and emissive triangles)."""
    return pack_lights(LightSet(list(lights), radius, mesh_lights=mesh), None, False)


class Samples(NamedTuple):
    entry: np.ndarray
    wi: np.ndarray
    dist: np.ndarray
    radiance: np.ndarray
    pdf: np.ndarray
    delta: np.ndarray
    light_prim: np.ndarray
    margin: np.ndarray


def kernel_sample(L, P, u, u_pick=None):
    """light_set.sample at the points P (n, 3) with numbers u (n, 2) (and u_pick (n,),
    one half when there is one light to pick)."""
    n = len(P)
    u_pick = np.full(n, 0.5) if u_pick is None else u_pick
    return Samples(*sample_batch(L, np.ascontiguousarray(P, np.float64),
                                 np.ascontiguousarray(u_pick, np.float64),
                                 np.ascontiguousarray(u, np.float64)))


def kernel_pdf_via_hit(L, P, wi):
    """The pdf of directions wi from P as MIS finds it: the lamp hit first, its pdf
    there, 0 where no lamp is hit. Returns (pdf, t, radiance)."""
    P = np.ascontiguousarray(P, np.float64)
    wi = np.ascontiguousarray(wi, np.float64)
    t, k, rad = hit_lamps_batch(L, P, wi, np.full(len(wi), np.inf))
    hit = k >= 0
    out = np.zeros(len(wi))
    if hit.any():
        out[hit] = lamp_pdf_batch(L, k[hit], P[hit], wi[hit], t[hit])
    return out, t, rad


def model_pdf_via_intersect(L, p):
    """pdf(p, wi) as MIS finds it (`kernel_pdf_via_hit`) for the chi-square harness."""
    def pdf(wi, d=None):
        return kernel_pdf_via_hit(L, np.broadcast_to(p, wi.shape), wi)[0]
    return pdf


def model_sampler(L, p):
    def sample(u2):
        s = kernel_sample(L, np.broadcast_to(p, (len(u2), 3)), u2)
        return s.wi, s.pdf > 0
    return sample


def rect_chart(model, p):
    return PlanarChart(p, model.center - model.ax - model.ay, 2 * model.ax, 2 * model.ay, "quad")


def disk_chart(model, p):
    return PlanarChart(p, model.center, model.ax, model.ay, "disk")


def grazing_point(center, normal, tangent, dist, degrees):
    """A point `dist` from `center` on the emitting (-normal) side, `degrees` off -normal."""
    th = np.radians(degrees)
    return np.asarray(center, float) + dist * (np.sin(th) * np.asarray(tangent, float)
                                               - np.cos(th) * np.asarray(normal, float))


def _solid_angle_used(L, p):
    """Whether the area lamp of L is sampled uniformly in solid angle from p: then every
    sample has the same pdf, 1 / the solid angle (by area, the pdf varies with the
    point)."""
    n = 64
    u = np.random.default_rng(0).random((n, 2))
    pdf = kernel_sample(L, np.tile(np.asarray(p, float), (n, 1)), u).pdf
    pdf = pdf[pdf > 0]
    assert pdf.size > n // 2
    return bool(np.ptp(pdf) <= 1e-9 * pdf.max())


RECT_CASES = [
    # (id, light kwargs, point, expect solid-angle sampling)
    ("square-near-axis", dict(shape="SQUARE", sx=1.0), (0.0, 0.0, 0.0), True),
    ("square-very-near", dict(shape="SQUARE", sx=1.0), (0.1, -0.2, 0.95), True),
    ("rect-offaxis", dict(shape="RECTANGLE", sx=2.0, sy=0.5), (1.5, 0.7, 0.2), True),
    ("rect-grazing-85", dict(shape="RECTANGLE", sx=1.0, sy=0.6), "graze", True),
    ("square-far-area-fallback", dict(shape="SQUARE", sx=0.1), (0.3, 0.2, -40.0), False),
]


@pytest.mark.parametrize("case", RECT_CASES, ids=[c[0] for c in RECT_CASES])
def test_rectangle_samples_follow_pdf(case):
    name, kw, p, spherical_expected = case
    light = area_light(**kw)
    model, L = AreaLightModel(light), packed(light)
    if p == "graze":
        p = grazing_point(model.center, model.normal, [1, 0, 0], 2.0, 85.0)
    p = np.asarray(p, float)
    assert _solid_angle_used(L, p) == spherical_expected
    res = chart_chi2(model_sampler(L, p), model_pdf_via_intersect(L, p),
                     rect_chart(model, p), seed=_seed(name))
    print(name, res)
    assert res.passed, str(res)
    assert abs(res.pdf_integral - 1.0) < 1e-4      # cell quadrature accuracy


def test_sheared_parallelogram_light_uses_area_sampling_and_passes():
    m = np.eye(4)
    m[:3, 1] = (0.5, 1.0, 0.0)                         # sheared: edges not perpendicular
    light = area_light("RECTANGLE", 1.0, 0.8, matrix=m)
    model, L = AreaLightModel(light), packed(light)
    assert not model.solid_angle_ok
    p = np.array([0.2, 0.1, 0.3])
    assert not _solid_angle_used(L, p)
    res = chart_chi2(model_sampler(L, p), model_pdf_via_intersect(L, p),
                     rect_chart(model, p), seed=11)
    print(res)
    assert res.passed, str(res)


DISK_CASES = [
    ("disk-axis", dict(shape="DISK", sx=1.0), (0.0, 0.0, 0.2)),
    ("disk-grazing-85", dict(shape="DISK", sx=1.0), "graze"),
    ("ellipse-offaxis", dict(shape="ELLIPSE", sx=2.0, sy=0.5), (0.8, -0.4, 0.5)),
    ("ellipse-grazing-85", dict(shape="ELLIPSE", sx=0.4, sy=1.5), "graze"),
]


@pytest.mark.parametrize("case", DISK_CASES, ids=[c[0] for c in DISK_CASES])
def test_disk_and_ellipse_samples_follow_pdf(case):
    name, kw, p = case
    light = area_light(**kw)
    model, L = AreaLightModel(light), packed(light)
    if p == "graze":
        p = grazing_point(model.center, model.normal, [0.6, 0.8, 0], 1.5, 85.0)
    p = np.asarray(p, float)
    res = chart_chi2(model_sampler(L, p), model_pdf_via_intersect(L, p),
                     disk_chart(model, p), seed=_seed(name))
    print(name, res)
    assert res.passed, str(res)


SPHERE_CASES = [
    ("sphere-near", dict(radius=0.5), (0.0, 0.3, -0.4)),
    ("sphere-far", dict(radius=0.05), (3.0, -2.0, 1.0)),
    ("sphere-spot", dict(radius=0.2, spot_size=np.radians(60), spot_blend=0.5), (0.1, 0.0, -1.0)),
]


@pytest.mark.parametrize("case", SPHERE_CASES, ids=[c[0] for c in SPHERE_CASES])
def test_sphere_light_outside_samples_follow_pdf(case):
    name, kw, p = case
    light = PointLight((0.0, 0.0, 0.5), (5.0, 5.0, 5.0), **kw)
    model, L = PointLightModel(light), packed(light)
    p = np.asarray(p, float)
    to = model.position - p
    d2 = to @ to
    # the cone the sphere subtends: 1 - cos = 1 - sqrt(1 - r^2 / d^2)
    one_minus = model.radius ** 2 / d2 / (1.0 + np.sqrt(1.0 - model.radius ** 2 / d2))
    chart = ConeChart(to, one_minus)
    res = chart_chi2(model_sampler(L, p), model_pdf_via_intersect(L, p), chart,
                     seed=_seed(name))
    print(name, res)
    assert res.passed, str(res)


def test_sphere_light_inside_samples_follow_pdf():
    L = packed(PointLight((0.0, 0.0, 0.5), (5.0, 5.0, 5.0), radius=1.0))
    p = np.array([0.3, -0.2, 0.9])

    def sample(u):
        return model_sampler(L, p)(u[:, 1:3])

    res = chi2_test(sample, model_pdf_via_intersect(L, p), N_CHI2, seed=5,
                    n_tests=N_TESTS)
    print(res)
    assert res.passed, str(res)


def test_soft_falloff_disc_samples_follow_pdf():
    light = PointLight((0.0, 0.0, 0.5), (5.0, 5.0, 5.0), radius=0.4)
    light.soft_falloff = True                        # attribute may postdate this test
    model, L = PointLightModel(light), packed(light)
    assert model.disc
    p = np.array([0.2, 0.1, -0.3])
    axis = (model.position - p) / np.linalg.norm(model.position - p)
    from engine.warp import orthonormal_basis
    t, b = orthonormal_basis(axis[None])
    chart = PlanarChart(p, model.position, model.radius * t[0], model.radius * b[0], "disk")
    res = chart_chi2(model_sampler(L, p), model_pdf_via_intersect(L, p), chart, seed=8)
    print(res)
    assert res.passed, str(res)


SUN_CASES = [("sun-10deg", 10.0), ("sun-180deg", 180.0)]


@pytest.mark.parametrize("case", SUN_CASES, ids=[c[0] for c in SUN_CASES])
def test_sun_cone_samples_follow_pdf(case):
    name, degrees = case
    light = SunLight((0.3, -0.2, -1.0), (3.0, 3.0, 3.0), np.radians(degrees))
    model, L = SunLightModel(light), packed(light)
    p = np.zeros(3)

    def pdf(wi, d=None):                                 # escaped rays find the sun
        return sun_escaped_batch(L, 0, np.ascontiguousarray(wi, np.float64))[1]

    res = chart_chi2(model_sampler(L, p), pdf, ConeChart(model.to_light, model.one_minus),
                     seed=_seed(name))
    print(name, res)
    assert res.passed, str(res)


# -------------------------------------------------------------- emissive triangle mesh

def emissive_mesh():
    """Five triangles: four coplanar ones of different sizes and radiances (z = 1, facing
    down and up alike, as emission is two-sided) and one tilted triangle elsewhere; no two
    overlap as seen from the test points."""
    v0 = np.array([[-1, -1, 1], [0.2, -1, 1], [-1, 0, 1], [0.1, 0.1, 1], [2.0, 0.5, 0.4]], float)
    v1 = np.array([[0, -1, 1], [1, -1, 1], [0, 0.05, 1], [1.2, 0.2, 1], [2.0, 1.5, 0.9]], float)
    v2 = np.array([[-1, -0.1, 1], [0.6, -0.2, 1], [-1, 0.9, 1], [0.3, 1.0, 1], [2.1, 0.9, 1.4]],
                  float)
    rad = np.array([[1, 1, 1], [5, 2, 1], [0.2, 0.2, 0.2], [3, 3, 3], [2, 0.5, 0.1]], float)
    return EmissiveTriangles(v0, v1, v2, rad, np.array([3, 7, 8, 10, 12]), 20)


class TriangleChart:
    """Slab j of a in [j/T, (j+1)/T) is triangle j: with a' = T a - j and s = sqrt(a'),
    q = v0 + s (1 - b) e1 + s b e2 (uniform in area): dA = T A_j da db."""

    def __init__(self, p, mesh: EmissiveTriangles):
        self.p, self.m, self.T = np.asarray(p, float), mesh, len(mesh)

    def hit(self, wi):
        """First triangle hit along p + t wi (brute-force Moller-Trumbore) and (s, b)."""
        m = self.m
        best = np.full(len(wi), np.inf)
        tri = np.full(len(wi), -1)
        uv = np.zeros((len(wi), 2))
        for j in range(self.T):
            e1, e2 = m.e1[j], m.e2[j]
            pv = np.cross(wi, e2)
            det = pv @ e1
            with np.errstate(divide="ignore", invalid="ignore"):
                inv = 1.0 / det
                tv = self.p - m.v0[j]
                u = (pv @ tv) * inv
                qv = np.cross(tv, e1)
                v = (wi @ qv) * inv
                t = (qv @ e2) * inv
            ok = (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0) & (t < best)
            best[ok], tri[ok] = t[ok], j
            uv[ok] = np.stack([u[ok], v[ok]], 1)
        return tri, uv, best

    def to_ab(self, wi):
        tri, uv, _ = self.hit(wi)
        s = uv.sum(1)
        b = np.where(s > 0, uv[:, 1] / np.where(s > 0, s, 1.0), 0.0)
        a = (np.maximum(tri, 0) + s * s) / self.T
        return a, b, tri >= 0

    def triangle_of(self, a):
        return np.clip((a * self.T).astype(int), 0, self.T - 1)

    def jacobian(self, a, b):
        m = self.m
        j = self.triangle_of(a)
        s = np.sqrt(np.clip(a * self.T - j, 0.0, 1.0))
        q = m.v0[j] + (s * (1 - b))[:, None] * m.e1[j] + (s * b)[:, None] * m.e2[j]
        to = q - self.p
        d = np.linalg.norm(to, axis=1)
        wi = to / d[:, None]
        jac = np.abs((wi * m.normal[j]).sum(1)) / (d * d) * self.T * m.area[j]
        self._last = (j, q)
        return jac, wi, d


MESH_POINTS = [("mesh-below", (0.1, 0.0, 0.0)), ("mesh-above", (0.2, -0.3, 1.7)),
               ("mesh-grazing-85", "graze")]


def _mesh_point(p):
    if p == "graze":
        return grazing_point((0.0, 0.0, 1.0), (0, 0, 1), (0.0, 1.0, 0.0), 3.0, 85.0)
    return np.asarray(p, float)


def _mesh_case(p, light_set):
    chart = TriangleChart(p, light_set.mesh)
    L = pack_lights(light_set, None, False)

    def sample(u2):
        P = np.broadcast_to(p, (len(u2), 3))
        # the pick number is independent of the point's numbers
        u_pick = np.random.default_rng(len(u2)).random(len(u2))
        ls = kernel_sample(L, P, u2, u_pick)
        return ls.wi, ls.pdf > 0

    def pdf(wi, d=None):
        tri, _, t = chart.hit(wi)
        P = np.ascontiguousarray(np.broadcast_to(p, wi.shape))
        prim = np.where(tri >= 0, light_set.mesh.prim[np.maximum(tri, 0)], -1)
        q = P + wi * np.where(np.isfinite(t), t, 0.0)[:, None]
        return mesh_pdf_batch(L, prim.astype(np.int64), P, np.ascontiguousarray(q))

    return chart, sample, pdf


@pytest.mark.parametrize("case", MESH_POINTS, ids=[c[0] for c in MESH_POINTS])
def test_emissive_triangle_samples_follow_pdf(case):
    name, p = case
    p = _mesh_point(p)
    ls = LightSet([], 1.0, mesh_lights=emissive_mesh())
    chart, sample, pdf = _mesh_case(p, ls)
    res = chart_chi2(sample, pdf, chart, seed=_seed(name), rows=40, cols=10,
                     adaptive=False)
    print(name, res)
    assert res.passed, str(res)


# Sidak bookkeeping: the number of chi-square tests above that must pass.
def test_number_of_chi2_tests_matches_the_sidak_correction():
    n = (len(RECT_CASES) + 1 + len(DISK_CASES) + len(SPHERE_CASES) + 1 + 1 + len(SUN_CASES)
         + len(MESH_POINTS))
    assert n == N_TESTS


# ----------------------------------------------------------------- negative controls

def test_negative_control_area_pdf_for_solid_angle_samples_fails():
    """Solid-angle samples of a near rectangle checked against the area-sampling pdf."""
    light = area_light("SQUARE", 1.0)
    model, L = AreaLightModel(light), packed(light)
    p = np.array([0.1, 0.0, 0.4])
    assert _solid_angle_used(L, p)

    def wrong_pdf(wi, d):
        return d * d / (model.area * np.abs(wi @ model.normal))

    res = chart_chi2(model_sampler(L, p), wrong_pdf, rect_chart(model, p), seed=3)
    print(res)
    assert not res.passed
    assert abs(res.pdf_integral - 1.0) < 1e-4     # right normalisation, wrong shape


def test_negative_control_wrong_selection_pdf_fails():
    """Triangles picked by area (Cycles' distribution without the tree), pdf claiming
    they are picked by power (their radiances differ)."""
    mesh = emissive_mesh()
    ls = LightSet([], 1.0, mesh_lights=mesh)
    p = np.array([0.1, 0.0, 0.0])
    chart, sample, pdf = _mesh_case(p, ls)
    np.testing.assert_allclose(ls.select_pdf, mesh.area / mesh.area.sum())
    by_power = mesh.power / mesh.power.sum()

    def wrong_pdf(wi, d=None):
        tri, _, t = chart.hit(wi)
        j = np.maximum(tri, 0)
        right = pdf(wi)
        return np.where(tri >= 0, right / ls.select_pdf[j] * by_power[j], 0.0)

    res = chart_chi2(sample, wrong_pdf, chart, seed=4, rows=40, cols=10, adaptive=False)
    print(res)
    assert not res.passed


# ------------------------------------------------------------- irradiance by NEE

N_NEE = 1_000_000


def nee_irradiance(sample_fn, p, n_r, n=N_NEE, seed=0):
    """E = mean(L cos / pdf) (luminance channel 0), with its standard error."""
    rng = np.random.default_rng(seed)
    P = np.broadcast_to(np.asarray(p, float), (n, 3)).copy()
    s = sample_fn(P, rng.random((n, 2)), rng)
    cos = np.maximum(s.wi @ np.asarray(n_r, float), 0.0)
    ok = s.pdf > 0
    val = np.where(ok, s.radiance[:, 0] * cos / np.where(ok, s.pdf, 1.0), 0.0)
    assert np.all(np.isfinite(val))
    return val.mean(), val.std() / np.sqrt(n)


def lambert_polygon(p, n_r, verts, L):
    """Irradiance at p (normal n_r) from a uniform polygon of radiance L fully above the
    horizon: E = L/2 |sum_i theta_i n_r . normalize(v_i x v_i+1)| (Lambert 1760)."""
    v = np.asarray(verts, float) - np.asarray(p, float)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    w = np.roll(v, -1, axis=0)
    theta = np.arccos(np.clip((v * w).sum(1), -1, 1))
    g = np.cross(v, w)
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    return 0.5 * L * abs((theta * (g @ np.asarray(n_r, float))).sum())


def rect_on_axis(L, a, b, h):
    """Irradiance on the axis of a 2a x 2b rectangle at distance h, parallel planes."""
    A, B = a / h, b / h
    return 2 * L * (A / np.sqrt(1 + A * A) * np.arctan(B / np.sqrt(1 + A * A))
                    + B / np.sqrt(1 + B * B) * np.arctan(A / np.sqrt(1 + B * B)))


def _lamp_sampler(L):
    return lambda P, u, rng: kernel_sample(L, P, u)


def test_closed_forms_agree_with_each_other():
    """The references: Lambert's polygon formula reproduces the on-axis closed forms."""
    L, a, b, h = 2.0, 0.7, 0.3, 0.9
    verts = [(-a, -b, h), (a, -b, h), (a, b, h), (-a, b, h)]
    assert lambert_polygon((0, 0, 0), UP, verts, L) == pytest.approx(rect_on_axis(L, a, b, h),
                                                                     rel=1e-12)
    R = 0.5
    ang = np.linspace(0, 2 * np.pi, 20000, endpoint=False)
    circle = np.stack([R * np.cos(ang), R * np.sin(ang), np.full_like(ang, h)], 1)
    assert lambert_polygon((0, 0, 0), UP, circle, L) == pytest.approx(
        np.pi * L * R * R / (h * h + R * R), rel=1e-7)


NEE_CASES = [
    # id, light factory, point, receiver normal
    ("square-axis", lambda: area_light("SQUARE", 1.0), (0, 0, 0), UP),
    ("rect-offaxis-tilted", lambda: area_light("RECTANGLE", 2.0, 0.5), (1.2, 0.4, 0.3),
     (0.3, -0.2, 0.93)),
    ("rect-grazing-85", lambda: area_light("RECTANGLE", 1.0, 0.6), "graze", UP),
    ("rect-far", lambda: area_light("RECTANGLE", 0.1, 0.05), (0.5, 0.2, -30.0), UP),
    ("disk-axis", lambda: area_light("DISK", 1.2), (0, 0, 0.1), UP),
    ("ellipse-offaxis", lambda: area_light("ELLIPSE", 2.0, 0.5), (0.5, 0.3, 0.2), (0.2, 0.1, 0.97)),
]


def _area_closed_form(model, p, n_r):
    if model.round:
        ang = np.linspace(0, 2 * np.pi, 20000, endpoint=False)
        verts = model.center + np.cos(ang)[:, None] * model.ax + np.sin(ang)[:, None] * model.ay
    else:
        c, ax, ay = model.center, model.ax, model.ay
        verts = [c - ax - ay, c + ax - ay, c + ax + ay, c - ax + ay]
    return lambert_polygon(p, n_r, verts, model.radiance[0])


@pytest.mark.parametrize("case", NEE_CASES, ids=[c[0] for c in NEE_CASES])
def test_area_light_irradiance_by_nee(case):
    name, make, p, n_r = case
    light = make()
    model, L = AreaLightModel(light), packed(light)
    if isinstance(p, str):
        p = grazing_point(model.center, model.normal, [1, 0, 0], 2.0, 85.0)
        n_r = model.center - p                        # facing the light's centre
    n_r = np.asarray(n_r, float) / np.linalg.norm(n_r)
    expected = _area_closed_form(model, p, n_r)
    if name == "square-axis":
        assert expected == pytest.approx(rect_on_axis(model.radiance[0], 0.5, 0.5, 1.0), rel=1e-12)
    if name == "disk-axis":
        assert expected == pytest.approx(np.pi * model.radiance[0] * 0.36 / (0.81 + 0.36), rel=1e-7)
    est, se = nee_irradiance(_lamp_sampler(L), p, n_r, seed=_seed(name))
    err = est / expected - 1
    print(f"{name}: E={est:.6g} expected={expected:.6g} err={100 * err:+.3f}% "
          f"(se {100 * se / expected:.3f}%)")
    assert abs(err) < 0.005


def test_sphere_light_irradiance_by_nee():
    light = PointLight((0.0, 0.0, 1.0), (20.0, 20.0, 20.0), radius=0.3)
    model, L = PointLightModel(light), packed(light)
    p = np.array([0.4, 0.0, 0.0])
    to = model.position - p
    d = np.linalg.norm(to)
    n_r = np.array([0.0, 0.0, 1.0])
    expected = np.pi * model.sphere_radiance[0] * (0.3 / d) ** 2 * (to @ n_r) / d
    est, se = nee_irradiance(_lamp_sampler(L), p, n_r, seed=1)
    print(f"sphere: E={est:.6g} expected={expected:.6g} err={100 * (est / expected - 1):+.3f}% "
          f"(se {100 * se / expected:.3f}%)")
    assert abs(est / expected - 1) < 0.005


def test_sun_irradiance_by_nee():
    light = SunLight((0.3, -0.2, -1.0), (3.0, 3.0, 3.0), np.radians(20.0))
    model = SunLightModel(light)
    n_r = np.array([0.0, 0.0, 1.0])
    expected = 3.0 * (model.to_light @ n_r)
    est, se = nee_irradiance(_lamp_sampler(packed(light)), np.zeros(3), n_r, seed=2)
    print(f"sun: E={est:.6g} expected={expected:.6g} err={100 * (est / expected - 1):+.3f}%")
    assert abs(est / expected - 1) < 0.005


def test_emissive_triangles_and_mixed_light_set_irradiance_by_nee():
    """All lights at once through the light set's sample: selection pdf x light pdf."""
    mesh = emissive_mesh()
    lamps = [area_light("SQUARE", 0.5, center=(0.0, 0.0, 2.0)),
             PointLight((0.5, 0.5, 1.5), (8.0, 8.0, 8.0), radius=0.1),
             SunLight((0.0, 0.0, -1.0), (1.0, 1.0, 1.0), np.radians(5.0))]
    ls = LightSet(lamps, 5.0, mesh_lights=mesh)
    p = np.array([0.1, 0.0, 0.0])
    n_r = UP
    expected = sum(lambert_polygon(p, n_r, [mesh.v0[j], mesh.v0[j] + mesh.e1[j],
                                            mesh.v0[j] + mesh.e2[j]], mesh.radiance[j, 0])
                   for j in range(len(mesh)))
    expected += _area_closed_form(ls.models[0], p, n_r)
    sph = ls.models[1]
    to = sph.position - p
    d = np.linalg.norm(to)
    expected += np.pi * sph.sphere_radiance[0] * (0.1 / d) ** 2 * (to @ n_r) / d
    expected += 1.0

    L = pack_lights(ls, None, False)

    def sample(P, u, rng):
        return kernel_sample(L, P, u, rng.random(len(P)))

    est, se = nee_irradiance(sample, p, n_r, seed=9)
    print(f"mixed: E={est:.6g} expected={expected:.6g} err={100 * (est / expected - 1):+.3f}% "
          f"(se {100 * se / expected:.3f}%)")
    assert abs(est / expected - 1) < 0.005


# ------------------------------------------------------------------------ robustness

def _finite_sample(L, P, u):
    s = kernel_sample(L, P, u)
    assert np.all(np.isfinite(s.wi)) and np.all(np.isfinite(s.radiance))
    assert np.all(np.isfinite(s.pdf)) and np.all(s.pdf >= 0)
    assert not np.any(np.isnan(s.dist))
    pdf, t, r = kernel_pdf_via_hit(L, P, s.wi)
    assert not np.any(np.isnan(t)) and np.all(np.isfinite(r))
    assert np.all(np.isfinite(pdf)) and np.all(pdf >= 0)
    return s


def _probe_points(center, normal, size):
    c, n = np.asarray(center, float), np.asarray(normal, float)
    t = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    t /= np.linalg.norm(t)
    pts = [c, c - n * 1e-300, c + n * 1e-12, c - n * 1e-12 * size, c + t * 0.3 * size,
           c + t * 2 * size, c + t * 2 * size - n * 1e-9 * size, c - n * size, c + n * size,
           c - n * 1e6 * size, c + t * 0.5 * size]
    return np.array(pts)


@pytest.mark.parametrize("size", [1e-6, 1.0, 1e4])
@pytest.mark.parametrize("shape", ["SQUARE", "RECTANGLE", "DISK", "ELLIPSE"])
def test_area_lights_stay_finite_at_degenerate_points(shape, size):
    light = area_light(shape, size, 0.5 * size, center=(1.0, 2.0, 3.0))
    model, L = AreaLightModel(light), packed(light)
    P = _probe_points(model.center, model.normal, size)
    rng = np.random.default_rng(0)
    for u in (rng.random((len(P), 2)), np.zeros((len(P), 2)), np.full((len(P), 2), 1 - 1e-16)):
        _finite_sample(L, P, u)


@pytest.mark.parametrize("light", [
    PointLight((0, 0, 0), (1, 1, 1)),
    PointLight((0, 0, 0), (1, 1, 1), radius=1e-6),
    PointLight((0, 0, 0), (1, 1, 1), radius=1e4),
    PointLight((0, 0, 0), (1, 1, 1), spot_size=np.radians(45), spot_blend=0.0),
    PointLight((0, 0, 0), (1, 1, 1), spot_size=np.radians(45), spot_blend=1.0),
    PointLight((0, 0, 0), (1, 1, 1), radius=0.1, spot_size=np.radians(180), spot_blend=1.0),
    PointLight((0, 0, 0), (1, 1, 1), spot_size=0.0, spot_blend=1.0),
], ids=["point", "sphere-1e-6", "sphere-1e4", "spot-blend0", "spot-blend1", "spot-sphere-180",
        "spot-size0"])
def test_point_and_spot_lights_stay_finite_including_at_the_light(light):
    model = PointLightModel(light)
    P = np.array([[0, 0, 0], [0, 0, -1e-300], [0, 0, -1], [1e4, 0, 0], [0, 0, 1e-8],
                  [0, 0, -2e4]], float)
    rng = np.random.default_rng(0)
    s = _finite_sample(packed(light), P, rng.random((len(P), 2)))
    assert np.all(s.radiance[0] == 0) or not model.delta   # exactly at a point light: nothing


def test_point_light_disc_mode_stays_finite():
    light = PointLight((0, 0, 0), (1, 1, 1), radius=0.5)
    light.soft_falloff = True
    assert PointLightModel(light).disc
    P = np.array([[0, 0, 0], [0, 0, 1e-300], [0, 0.2, 0], [3, 0, 0]], float)
    _finite_sample(packed(light), P, np.random.default_rng(0).random((len(P), 2)))


@pytest.mark.parametrize("degrees", [0.0, 1e-9, 1e-4, 0.5, 90.0, 180.0, 360.0])
def test_sun_stays_finite_for_any_angle(degrees):
    light = SunLight((0.0, 0.0, -1.0), (2.0, 2.0, 2.0), np.radians(degrees))
    model, L = SunLightModel(light), packed(light)
    P = np.zeros((4, 3))
    s = kernel_sample(L, P, np.random.default_rng(0).random((4, 2)))
    assert np.all(np.isfinite(s.wi)) and np.all(np.isfinite(s.radiance))
    assert np.all(np.isfinite(s.pdf)) and np.all(s.pdf > 0)
    if not model.delta:
        # the estimate of irradiance at normal incidence is the strength, whatever the angle
        est, _ = nee_irradiance(_lamp_sampler(L), np.zeros(3), UP, n=200_000, seed=3)
        assert est == pytest.approx(2.0, rel=0.01)


def test_emissive_triangles_stay_finite_on_and_in_the_plane():
    mesh = emissive_mesh()
    L = packed(mesh=mesh)
    P = np.array([[-0.5, -0.9, 1.0], [0.0, 0.0, 1.0], [5.0, 5.0, 1.0], [0.1, 0, 1 + 1e-300],
                  mesh.v0[0], mesh.v0[0] + 0.5 * mesh.e1[0]])
    rng = np.random.default_rng(1)
    for _ in range(20):
        s = kernel_sample(L, P, rng.random((len(P), 2)), rng.random(len(P)))
        assert np.all(np.isfinite(s.wi)) and np.all(np.isfinite(s.pdf))
        assert np.all(np.isfinite(s.radiance)) and np.all(np.isfinite(s.margin))
        # each sample names the emissive triangle it lies on (its shadow ray skips it)
        ok = s.entry >= 0
        assert ok.any() and np.all(s.light_prim[ok] == mesh.prim[s.entry[ok]])
        assert np.all(s.light_prim[~ok] == -1)
    tiny = EmissiveTriangles([[0, 0, 0]], [[1e-7, 0, 0]], [[0, 1e-7, 0]], [[1, 1, 1]], [0], 1)
    huge = EmissiveTriangles([[0, 0, 0]], [[1e4, 0, 0]], [[0, 1e4, 0]], [[1, 1, 1]], [0], 1)
    for m in (tiny, huge):
        s = kernel_sample(packed(mesh=m), np.array([[0.0, 0.0, 1.0], [0, 0, 0]]),
                          np.array([[0.3, 0.4], [0.5, 0.5]]), np.array([0.5, 0.5]))
        assert np.all(np.isfinite(s.pdf)) and np.all(np.isfinite(s.radiance))


def test_degenerate_and_dark_triangles_are_not_lights():
    m = EmissiveTriangles([[0, 0, 0], [0, 0, 0], [0, 0, 0]],
                          [[1, 0, 0], [1, 0, 0], [1, 0, 0]],
                          [[2, 0, 0], [0, 1, 0], [0, 1, 0]],
                          [[1, 1, 1], [0, 0, 0], [1, 1, 1]], [0, 1, 2], 3)
    assert len(m) == 1 and m.prim.tolist() == [2]
    assert m.entry_of(np.array([-1, 0, 1, 2, 99])).tolist() == [-1, -1, -1, 0, -1]


def test_solid_angle_threshold_is_where_the_docstring_says():
    L = packed(area_light("SQUARE", 1.0))
    near = np.array([0.0, 0.0, 0.0])
    far = np.array([0.0, 0.0, 1.0 - 1.0 / np.sqrt(SOLID_ANGLE_MIN) * 1.5])
    assert _solid_angle_used(L, near)
    assert not _solid_angle_used(L, far)
    in_plane = np.array([0.1, 0.1, 1.0 - 1e-9])
    assert not _solid_angle_used(L, in_plane)
