"""The compiled light kernels (engine.kernels.lights) against the NumPy LightSet.

Every light model and the LightSet's own rules (pick CDF, strategy choice, pdfs with the
pick probability, margins, deltas, visible_camera) are ported as scalar Numba code; here
both run on the same inputs and must agree to RTOL = 1e-9 (directions to 1e-12 absolute,
being unit vectors). The two compute the same operations in the same order, so most
values agree to the last bits, but no comparison asks for bit equality.

The one place they may not: NumPy's `@` on a batch of rows is BLAS (gemv, fusing
multiply-adds), the kernels' dot products are plain sums, so an area lamp's frame
coordinates of p (x0, y0, z of SphericalRectangle; the plane distance in intersect; the
cosine at the lamp) can differ by an ulp of |p - light|. Near the lamp's plane that ulp
is a relative error eps |p - light| / h in the height h, which the spherical rectangle's
solid angle and sampling map amplify (measured: wi off by 1.7e-8 at h = 5e-6 m with
omega = 1.2e-4 sr), and where the exact value is a tie (a direction in the lamp's plane,
a ray through its rim) rounding decides it. For one row, NumPy's (1, 3) @ (3,) is the
plain sum (checked on this machine's OpenBLAS), so every row that differs from the batch
NumPy result beyond the tolerance is evaluated again by NumPy alone and must match that
to the same tolerance (`agree`); at most 2 % of the rows may need this. The lamp
coordinates of a hit, (1, 3) @ (3, 3), still go through BLAS for one row, so a ray
exactly through an area lamp's rim (a sample at a uniform of 0 or 1 aims there) may hit
in one code and miss in the other: accepted only when it is at the rim (`compare_hits`).

Scenes: each light type alone (point, spots, sphere, soft-falloff disc, suns with zero,
tiny and finite angles, area SQUARE / RECTANGLE / DISK / ELLIPSE scaled, rotated,
sheared and mirrored with normalize on and off, world, emissive triangles), tiny lights,
all together, and an empty set. Shading points: a box about each light, close to it
(1e-8 .. 3), near an area light's plane, inside sphere lights, at a light's centre and
1e4 away. A negative control checks that the comparison does fail on a 1e-5 change of a
value three rows see, and on a 1e-6 change every row sees.
"""
from __future__ import annotations

import numpy as np
import pytest

from engine.kernels.lights import (environment_pdf, environment_radiance, hit_lamps,
                                   lamp_pdf, entry_visibility, mesh_pdf, n_entries,
                                   n_suns, pack_lights, sample, sun_escaped)
from engine.kernels.lights.batch import (hit_lamps_batch, lamp_pdf_batch, mesh_pdf_batch,
                                         sample_batch, sun_escaped_batch)
from engine.kernels.lights.pack import C_RAD, LAMP_SLICES, LAMPS, SELECT_PDF, SLICE_OF
from engine.lights import LightSet
from engine.mesh_lights import EmissiveTriangles
from engine.scene import AreaLight, PointLight, SunLight

# engine.lights divides by r^2 = 0 for the 1e-170 m sphere of the "tiny" scene (which then
# becomes a point light, as intended)
pytestmark = pytest.mark.filterwarnings("ignore:divide by zero:RuntimeWarning")

RTOL = 1e-9
WI_ATOL = 1e-12
ONE_MINUS = 1.0 - 2.0 ** -53          # the largest uniform below 1


# ------------------------------------------------------------------ scene builders

def rotation(axis, angle):
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)


def matrix(center, axis=(1, 0, 0), angle=0.0, scale=(1, 1, 1), shear=0.0):
    """light-to-world T R Sh S: scaled, sheared (x gains shear * y) and rotated."""
    m = np.eye(4)
    sh = np.eye(3)
    sh[0, 1] = shear
    m[:3, :3] = rotation(axis, angle) @ sh @ np.diag(scale)
    m[:3, 3] = center
    return m


def triangles(offset=(0.0, 0.0, 0.0), size=1.0):
    o = np.asarray(offset, float)
    v0 = o + size * np.array([[0, 0, 0], [1, 0, 0.2], [0, 1, 0.5], [2, 2, 2], [-1, 0, 0],
                              [0.5, 0.5, 0.5], [3, 0, 1]])
    v1 = o + size * np.array([[1, 0, 0], [1, 1, 0.1], [0.2, 1, 1.5], [2, 2, 2], [-1, 1, 0],
                              [0.6, 0.5, 0.5], [3, 1, 1]])
    v2 = o + size * np.array([[0, 1, 0], [2, 0, 0.3], [0, 2, 0.4], [2, 2, 2], [-1, 0, 1],
                              [0.5, 0.7, 0.5], [3, 0, 2]])
    rad = np.array([[1, 1, 1], [4, 2, 1], [0.2, 0.5, 3], [5, 5, 5], [0, 0, 0],
                    [1, 0, 0], [2, 2, 0]], float)    # row 3 degenerate, row 4 dark
    prims = np.array([2, 5, 6, 7, 9, 11, 14])
    return EmissiveTriangles(v0, v1, v2, rad, prims, 16)


def scene(name):
    """(lights, mesh, world, scene_radius, anchors): anchors are points the shading
    points gather around (light positions and centres)."""
    if name == "point":
        lights = [PointLight((0.3, -0.2, 1.5), (10, 8, 6)),
                  PointLight((-1, 0.5, 2.0), (5, 5, 9), spot_size=1.0, spot_blend=0.3,
                             direction=(0.2, 0.1, -1)),
                  PointLight((1, 1, 1.0), (3, 4, 5), spot_size=0.8, spot_blend=0.0,
                             direction=(-0.3, 0.0, -1))]
    elif name == "sphere":
        lights = [PointLight((0.3, -0.2, 1.5), (10, 8, 6), radius=0.25),
                  PointLight((-1, 0.5, 2.0), (5, 5, 9), radius=0.4, spot_size=1.2,
                             spot_blend=0.5, direction=(0.2, 0.1, -1))]
    elif name == "disc":
        lights = [PointLight((0.3, -0.2, 1.5), (10, 8, 6), radius=0.25, soft_falloff=True),
                  PointLight((-1, 0.5, 2.0), (5, 5, 9), radius=0.4, soft_falloff=True,
                             spot_size=1.2, spot_blend=0.5, direction=(0.2, 0.1, -1))]
    elif name == "sun":
        lights = [SunLight((0.3, -0.2, -1), (2, 2, 2), angle=0.0),
                  SunLight((-0.5, 0.1, -1), (1, 2, 3), angle=0.05),
                  SunLight((0.0, 0.6, -1), (3, 2, 1), angle=0.6),
                  SunLight((0.1, 0.1, -1), (1, 1, 1), angle=1e-9)]     # a delta
    elif name == "area":
        lights = [AreaLight(matrix((0, 0, 2), (1, 0, 0), np.pi, (1.5, 0.7, 1)),
                            (20, 18, 16), "SQUARE", 0.7),
                  AreaLight(matrix((1, -1, 1.5), (1, 1, 0), 2.6, (1, 2, 1)),
                            (9, 9, 9), "RECTANGLE", 1.2, 0.4, normalize=False),
                  AreaLight(matrix((-1, 0.5, 2.2), (0.3, 1, 0.2), 2.9, (0.5, 0.5, 0.5)),
                            (5, 6, 7), "DISK", 0.5),
                  AreaLight(matrix((0.5, 1.5, 1.8), (1, 0, 0.4), 3.0, (1.3, 0.6, 1)),
                            (8, 4, 2), "ELLIPSE", 0.8, 0.3, visible_camera=False),
                  AreaLight(matrix((-1.2, -1.0, 1.0), (0, 1, 0), 2.8, (1, 1, 1), shear=0.4),
                            (6, 6, 6), "RECTANGLE", 1.0, 0.5),           # parallelogram
                  AreaLight(matrix((0.2, 0.0, 3.0), (1, 0, 0), np.pi, (-1, 1, 1)),
                            (7, 7, 7), "SQUARE", 0.9, normalize=False)]  # mirrored
    elif name == "world":
        lights = [PointLight((0.3, -0.2, 1.5), (10, 8, 6))]
    elif name == "triangles":
        lights = []
    elif name == "tiny":
        lights = [PointLight((0.3, -0.2, 1.5), (1e-9, 1e-9, 1e-9), radius=1e-6),
                  PointLight((0.0, 0.2, 1.0), (1e-9, 1e-9, 1e-9), radius=1e-6,
                             soft_falloff=True),
                  PointLight((0.1, 0.3, 1.2), (1, 1, 1), radius=1e-170),    # r^2 = 0: a point
                  AreaLight(matrix((0, 0, 2), (1, 0, 0), np.pi), (1e-9, 1e-9, 1e-9),
                            "SQUARE", 1e-6),
                  AreaLight(matrix((1, 0, 2), (1, 0, 0), np.pi), (1e-9, 1e-9, 1e-9),
                            "DISK", 1e-6)]
    elif name == "all":
        lights = (scene("point")[0] + scene("sphere")[0] + scene("disc")[0]
                  + scene("sun")[0] + scene("area")[0])
    elif name == "empty":
        lights = []
    else:
        raise KeyError(name)
    mesh = {"triangles": triangles(), "all": triangles((0.5, 0.5, -0.5)),
            "tiny": triangles((0.0, 0.0, 1.0), 1e-6)}.get(name)
    world = {"world": (0.2, 0.3, 0.4), "all": (0.05, 0.04, 0.03)}.get(name)
    anchors = [np.asarray(getattr(l, "position", (0, 0, 0)), float) if not isinstance(
        l, AreaLight) else np.asarray(l.matrix)[:3, 3] for l in lights
        if not isinstance(l, SunLight)]
    if mesh is not None and len(mesh):
        anchors += list(mesh.v0 + (mesh.e1 + mesh.e2) / 3.0)
    if not anchors:
        anchors = [np.zeros(3)]
    return lights, mesh, world, 5.0, np.array(anchors)


SCENES = ["point", "sphere", "disc", "sun", "area", "world", "triangles", "tiny", "all",
          "empty"]


def light_set(name):
    lights, mesh, world, radius, anchors = scene(name)
    return LightSet(lights, radius, mesh_lights=mesh, world=world), anchors


# ------------------------------------------------------------------ inputs

def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def near_plane_points(ls, rng, n):
    """Points at heights 1e-6 .. 1 (relative to the light's size) above and below each
    area lamp's plane, over and beside it."""
    out = []
    for m in ls.models:
        if not hasattr(m, "ax"):
            continue
        size = np.linalg.norm(m.ax) + np.linalg.norm(m.ay)
        st = rng.uniform(-1.6, 1.6, (n, 2))
        h = size * 10.0 ** rng.uniform(-6, 0, n) * rng.choice([-1.0, 1.0], n)
        out.append(m.center + st[:, :1] * m.ax + st[:, 1:2] * m.ay + h[:, None] * m.normal)
    return np.concatenate(out) if out else np.zeros((0, 3))


def inside_points(ls, rng, n):
    out = []
    for m in ls.models:
        if getattr(m, "radius", 0.0) > 0.0:
            r = m.radius * rng.uniform(0, 1, n) ** (1 / 3)
            out.append(m.position + r[:, None] * unit(rng.normal(size=(n, 3))))
    return np.concatenate(out) if out else np.zeros((0, 3))


def shading_points(ls, anchors, rng, n=400):
    a = anchors[rng.integers(0, len(anchors), n)]
    pts = [rng.uniform(-3, 3, (n, 3)) + a,                                   # a box
           a + unit(rng.normal(size=(n, 3))) * 10.0 ** rng.uniform(-8, 0.5, (n, 1)),
           a[: n // 4] + unit(rng.normal(size=(n // 4, 3))) * 1e4,          # far away
           anchors,                                                          # at centres
           near_plane_points(ls, rng, n // 2),
           inside_points(ls, rng, n // 4)]
    return np.ascontiguousarray(np.concatenate(pts))


def uniforms(rng, n):
    """Random uniforms with the edges mixed in: 0, 0.5, u0 == u1, the largest < 1."""
    u = rng.random((n, 2))
    edges = np.array([0.0, 0.5, ONE_MINUS, 0.25])
    m = n // 8
    u[:m, 0] = rng.choice(edges, m)
    u[m:2 * m, 1] = rng.choice(edges, m)
    u[2 * m:3 * m, 1] = u[2 * m:3 * m, 0]
    return u


def pick_uniforms(ls, rng, n):
    """Uniform picks plus the CDF's own values (side='right' ties) and 0."""
    u = rng.random(n)
    if len(ls):
        m = n // 8
        u[:m] = rng.choice(np.concatenate([ls.cdf[:-1], [0.0, ONE_MINUS]]), m)
    return u


# ------------------------------------------------------------------ comparison

MAX_REDONE = 0.02          # share of rows that may need NumPy's one-row evaluation
EXACT = (0.0, 0.0)
VALUE = (RTOL, 0.0)
DIRECTION = (0.0, WI_ATOL)


def mismatched(kernel, numpy, rtol, atol):
    """Rows where kernel and numpy disagree: beyond atol + rtol |numpy|, or one finite
    and the other not, or different infinities / NaNs."""
    k = np.asarray(kernel, float).reshape(len(kernel), -1)
    n = np.asarray(numpy, float).reshape(len(numpy), -1)
    assert k.shape == n.shape
    with np.errstate(invalid="ignore", over="ignore"):
        ok = (k == n) | (np.isnan(k) & np.isnan(n)) | (
            np.isfinite(k) & np.isfinite(n) & (np.abs(k - n) <= atol + rtol * np.abs(n)))
    return ~ok.all(axis=1)


def close(kernel, numpy, what, rtol=RTOL, atol=0.0):
    """Every row agrees (no NumPy `@` on these paths: no fallback)."""
    bad = mismatched(np.atleast_1d(kernel), np.atleast_1d(numpy), rtol, atol)
    assert not bad.any(), (f"{what}: {bad.sum()} rows differ, first kernel "
                           f"{np.atleast_1d(kernel)[bad][:2]} vs NumPy "
                           f"{np.atleast_1d(numpy)[bad][:2]}")


# A row NumPy evaluates alone goes through BLAS too ((1, 3) @ (3,)): a plain sum on some
# CPUs' OpenBLAS kernels, fused multiply-adds on others (seen on AMD EPYC), so such a row
# may still differ from the kernel by the amplified ulp the module docstring measures
# (wi 8e-12, pdf 6e-7 relative near a lamp's plane), and a ray through a lamp's rim may
# hit in one and miss in the other (a pdf of 0 against one that is not), and a direction
# along a lamp's plane has a pdf (d^2 / (A cos)) above PLANE that the last ulp of the
# cosine decides: at most MAX_TIES of the rows.
REDO_VALUE, REDO_DIRECTION = (1e-6, 0.0), (0.0, 1e-10)
PLANE = 1e12
MAX_TIES = 0.005
# NumPy's transcendental functions are not libm's everywhere: on CPUs with AVX-512 its
# float64 sin, cos, arccos, exp and log are SVML's, up to 4 ulp from libm's, which the
# kernels call. Where the row's own conditioning amplifies such ulps (near a lamp's
# plane, as above), the tolerance is measured, not guessed: NumPy's row again with the
# shading point nudged by NUDGE (4 ulp, relative), and the kernel may differ from NumPy
# by CONDITIONING times what that nudge changed (seen on an Intel Xeon: one sampled wi of
# 593 rows past REDO_DIRECTION).
NUDGE = 2.0 ** -50
CONDITIONING = 4.0


def agree(what, names, tols, kernel, numpy, numpy_row, numpy_row_nudged=None):
    """The kernel's arrays equal NumPy's batch results to the tolerances, or, for the
    rows where they do not, NumPy's result for that row alone (`numpy_row(i)`) to
    REDO_* tolerances (exact fields stay exact), or to the row's measured conditioning
    (`numpy_row_nudged(i)`, see NUDGE), or are a rim tie; see above."""
    redo = np.zeros(len(kernel[0]), dtype=bool)
    for k, n, (rtol, atol) in zip(kernel, numpy, tols):
        redo |= mismatched(k, n, rtol, atol)
    assert redo.mean() <= MAX_REDONE, \
        f"{what}: {redo.sum()} of {len(redo)} rows differ from NumPy's batch"
    ties = 0
    for i in np.nonzero(redo)[0]:
        one = numpy_row(i)
        for name, k, n, o, tol in zip(names, kernel, numpy, one, tols):
            rtol, atol = tol if tol == EXACT else (REDO_DIRECTION if tol == DIRECTION
                                                   else REDO_VALUE)
            if not mismatched(k[i:i + 1], o, rtol, atol)[0]:
                continue
            mine, theirs = np.atleast_1d(k[i]), np.atleast_1d(o[0])
            if tol != EXACT and numpy_row_nudged is not None:
                moved = np.atleast_1d(numpy_row_nudged(i)[names.index(name)][0])
                spread = np.abs(moved - theirs)
                if np.all(np.isfinite(spread)) and \
                        np.all(np.abs(mine - theirs) <= CONDITIONING * spread):
                    continue           # ill-conditioned: within what 4 ulp of p move
            if tol == VALUE and (((mine == 0) != (theirs == 0)).any()
                                 or np.abs(np.concatenate([mine, theirs])).max() > PLANE):
                ties += 1              # a ray through a lamp's rim or along its plane
                continue
            raise AssertionError(f"{what}, row {i}, {name}: kernel {k[i]} vs NumPy {o[0]} "
                                 f"(in a batch {n[i]})")
    assert ties <= max(1, MAX_TIES * len(redo)), f"{what}: {ties} rim ties"


SAMPLE_FIELDS = ("entry", "wi", "dist", "radiance", "pdf", "delta", "margin")
SAMPLE_TOLS = (EXACT, DIRECTION, VALUE, VALUE, VALUE, EXACT, VALUE)


def compare_sample(L, ls, p, up, u):
    """LightSet.sample against sample_batch; returns NumPy's (LightSample, entries)."""
    def fields(s, idx, delta):
        return idx, s.wi, s.dist, s.radiance, s.pdf, delta, s.margin

    s, idx, delta = ls.sample(p, up, u)
    agree("sample", SAMPLE_FIELDS, SAMPLE_TOLS, sample_batch(L, p, up, u),
          fields(s, idx, delta),
          lambda i: fields(*ls.sample(p[i:i + 1], up[i:i + 1], u[i:i + 1])),
          lambda i: fields(*ls.sample(p[i:i + 1] * (1 + NUDGE), up[i:i + 1], u[i:i + 1])))
    return s, idx


def on_rim(ls, k, o, d, eps=1e-12):
    """Rays that meet area lamp k's plane within eps of its rim (|s|, |t| or s^2 + t^2 at
    1 in the lamp's own coordinates): hit or miss is a tie there, decided by rounding."""
    m = ls.models[k]
    if not hasattr(m, "ax"):
        return np.zeros(len(o), dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = ((m.center - o) @ m.normal) / (d @ m.normal)
        st = (o + d * t[:, None] - m.center) @ m.inv.T
    edge = (st[:, 0] ** 2 + st[:, 1] ** 2 if m.round
            else np.maximum(np.abs(st[:, 0]), np.abs(st[:, 1])))
    return np.abs(edge - 1.0) < eps


def compare_hits(L, ls, o, d, tmax):
    """hit_surfaces against hit_lamps_batch; a row where one finds lamp j and the other
    not (or another lamp) is accepted when the ray meets j's rim (`on_rim`): a sample at
    a uniform of 0 or 1 lies exactly there, and single-row NumPy still uses BLAS (gemm)
    for the lamp coordinates. Such rows are few and must be exactly at the rim."""
    kernel = hit_lamps_batch(L, o, d, tmax)
    numpy = ls.hit_surfaces(o, d, tmax)
    tie = np.zeros(len(o), dtype=bool)
    for i in np.nonzero(kernel[1] != numpy[1])[0]:
        tie[i] = all(on_rim(ls, j, o[i:i + 1], d[i:i + 1])[0]
                     for j in {kernel[1][i], numpy[1][i]} - {-1})
    assert tie.mean() <= MAX_REDONE
    keep = ~tie

    def numpy_hits(rows):
        return ls.hit_surfaces(o[keep][rows], d[keep][rows], tmax[keep][rows])

    agree("hit_surfaces", ("t", "lamp", "radiance"), (VALUE, EXACT, VALUE),
          tuple(a[keep] for a in kernel), tuple(a[keep] for a in numpy),
          lambda i: numpy_hits(slice(i, i + 1)))
    return numpy[0], numpy[1]


def compare_pdf(L, ls, k, p, wi, t, what="pdf"):
    def numpy_pdf(rows, scale=1.0):
        return (ls.pdf(k[rows], p[rows] * scale, wi[rows], t[rows]),)

    agree(what, ("pdf",), (VALUE,), (lamp_pdf_batch(L, k, p, wi, t),),
          numpy_pdf(slice(None)), lambda i: numpy_pdf(slice(i, i + 1)),
          lambda i: numpy_pdf(slice(i, i + 1), 1 + NUDGE))


# ------------------------------------------------------------------ tests

@pytest.mark.parametrize("name", SCENES)
def test_sample_matches_numpy(name):
    ls, anchors = light_set(name)
    L = pack_lights(ls)
    rng = np.random.default_rng(SCENES.index(name))
    p = shading_points(ls, anchors, rng)
    compare_sample(L, ls, p, pick_uniforms(ls, rng, len(p)), uniforms(rng, len(p)))
    assert n_entries(L) == len(ls)


@pytest.mark.parametrize("name", SCENES)
def test_each_entry_sampled_and_pdf_matches(name):
    """Every entry forced (u_pick inside its CDF step), then LightSet.pdf for every lamp
    index (and -1, and triangle entries) with the sampled directions and distances."""
    ls, anchors = light_set(name)
    L = pack_lights(ls)
    rng = np.random.default_rng(100 + SCENES.index(name))
    p = shading_points(ls, anchors, rng, n=200)
    lo = np.concatenate([[0.0], ls.cdf[:-1]])
    for k in range(len(ls)):
        if not ls.cdf[k] > lo[k]:
            continue                                      # a step lost to rounding
        up = lo[k] + rng.random(len(p)) * (ls.cdf[k] - lo[k])
        up = np.clip(up, lo[k], np.nextafter(ls.cdf[k], 0.0))
        s, idx = compare_sample(L, ls, p, up, uniforms(rng, len(p)))
        assert np.all(idx == k)
        for kk in range(-1, len(ls) + 1):
            kidx = np.full(len(p), kk, dtype=np.int64)
            compare_pdf(L, ls, kidx, p, s.wi, s.dist,
                        f"pdf of lamp {kk} for samples of entry {k}")


@pytest.mark.parametrize("name", SCENES)
def test_hits_and_their_pdfs_match(name):
    ls, anchors = light_set(name)
    L = pack_lights(ls)
    rng = np.random.default_rng(200 + SCENES.index(name))
    o = shading_points(ls, anchors, rng, n=300)
    n = len(o)
    s, _, _ = ls.sample(o, pick_uniforms(ls, rng, n), uniforms(rng, n))   # rims too
    a = anchors[rng.integers(0, len(anchors), n)]
    towards = unit(a + rng.normal(scale=0.3, size=(n, 3)) - o + 1e-300)
    d = np.concatenate([s.wi, unit(rng.normal(size=(n, 3))), towards])
    o3 = np.concatenate([o, o, o])
    tmax = np.where(rng.random(3 * n) < 0.7, np.inf, rng.uniform(0, 4, 3 * n))
    t, k = compare_hits(L, ls, o3, np.ascontiguousarray(d), tmax)
    assert name in ("point", "sun", "world", "triangles", "empty") or np.any(k >= 0), \
        "no ray hit a lamp: the test would show nothing"
    compare_pdf(L, ls, k, o3, d, t, "pdf of the lamps hit")
    vis = [m.visibility for m in ls.models]
    assert [entry_visibility(L, j) for j in range(len(vis))] == vis
    assert all((v & 1 == 1) == getattr(m, "visible_camera", True)
               for v, m in zip(vis, ls.models))


@pytest.mark.parametrize("name", ["triangles", "all", "tiny", "area", "empty"])
def test_mesh_pdf_matches(name):
    ls, anchors = light_set(name)
    L = pack_lights(ls)
    rng = np.random.default_rng(300 + SCENES.index(name))
    p = shading_points(ls, anchors, rng, n=200)
    n = len(p)
    prims = rng.integers(-2, 20, n)
    q = rng.normal(size=(n, 3))
    if ls.mesh is not None:
        j = rng.integers(0, len(ls.mesh), n)
        s = ls.mesh.sample(p, j, uniforms(rng, n))
        q[: n // 2] = (p + s.wi * s.dist[:, None])[: n // 2]
        prims[: n // 2] = ls.mesh.prim[j[: n // 2]]
        q[-5:] = p[-5:]                                           # q == p: pdf 0
    agree("mesh pdf", ("pdf",), (VALUE,), (mesh_pdf_batch(L, prims, p, q),),
          (ls.mesh_pdf(prims, p, q),), lambda i: (ls.mesh_pdf(prims[i:i + 1], p[i:i + 1],
                                                             q[i:i + 1]),))
    assert mesh_pdf(L, 10 ** 6, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0) == 0.0


@pytest.mark.parametrize("name", ["sun", "all", "world", "empty"])
def test_suns_and_world_match(name):
    ls, _ = light_set(name)
    L = pack_lights(ls)
    rng = np.random.default_rng(400 + SCENES.index(name))
    suns = ls.suns()
    assert n_suns(L) == len(suns)
    for j, (k, sun) in enumerate(suns):
        half = np.sqrt(sun.one_minus * 2.0)
        around = unit(sun.to_light + rng.normal(scale=half, size=(500, 3)))
        s = sun.sample(np.zeros((200, 3)), uniforms(rng, 200))
        d = np.ascontiguousarray(np.concatenate([around, s.wi, unit(rng.normal(size=(200, 3))),
                                                 [sun.to_light]]))
        rad, pdf = sun_escaped_batch(L, j, d)
        close(rad, sun.escaped(d), f"sun {j} radiance")
        close(pdf, sun.pdf(None, d, None) * ls.select_pdf[k], f"sun {j} pdf")
        assert 0 < np.count_nonzero(pdf) < len(d)          # inside and outside the disc
        assert sun_escaped(L, j, *d[-1], 0.0)[:3] == tuple(sun.radiance)
    up = np.array([[0.0, 0.0, 1.0]])
    close(environment_pdf(L, *up[0]), ls.environment_pdf(up)[0], "world pdf")
    world = (ls.models[ls.env_index].radiance if ls.env_index is not None else np.zeros(3))
    assert environment_radiance(L) == tuple(world)
    assert (environment_pdf(L, *up[0]) > 0) == (name in ("world", "all"))


def test_scalar_kernels_equal_batch_rows():
    ls, anchors = light_set("all")
    L = pack_lights(ls)
    rng = np.random.default_rng(5)
    p = shading_points(ls, anchors, rng, n=20)[:40]
    up, u = pick_uniforms(ls, rng, len(p)), uniforms(rng, len(p))
    rows = sample_batch(L, p, up, u)
    for i in range(len(p)):
        one = sample(L, *p[i], up[i], *u[i], 0.0)
        assert one[0] == rows[0][i] and one[9] == rows[5][i]
        assert one[1:4] == tuple(rows[1][i]) and one[5:8] == tuple(rows[3][i])
        assert (one[4], one[8], one[10]) == (rows[2][i], rows[4][i], rows[6][i])
        d = rows[1][i]
        t, k, r, g, b = hit_lamps(L, *p[i], *d, np.inf, 31, 0.0)
        assert (t, k) == tuple(x[0] for x in hit_lamps_batch(L, p[i:i + 1], d[None],
                                                             np.array([np.inf]))[:2])
        assert lamp_pdf(L, k, *p[i], *d, t, 0.0) == lamp_pdf_batch(
            L, np.array([k]), p[i:i + 1], d[None], np.array([t]))[0]


def test_empty_set():
    ls = LightSet([], 1.0)
    L = pack_lights(ls)
    assert n_entries(L) == 0 and n_suns(L) == 0
    k, wx, wy, wz, dist, r, g, b, pdf, delta, margin = sample(L, 0.0, 0.0, 0.0, 0.3, 0.5, 0.5,
                                                              0.0)
    s, idx, dl = ls.sample(np.zeros((1, 3)), np.array([0.3]), np.array([[0.5, 0.5]]))
    assert k == idx[0] == -1 and pdf == s.pdf[0] == 0.0 and not delta
    assert (wx, wy, wz) == tuple(s.wi[0]) and (r, g, b) == (0.0, 0.0, 0.0)
    assert hit_lamps(L, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 7.0, 31, 0.0) == (7.0, -1, 0.0, 0.0, 0.0)
    assert environment_pdf(L, 0.0, 0.0, 1.0) == 0.0
    assert environment_radiance(L) == (0.0, 0.0, 0.0)
    black = pack_lights(LightSet([], 1.0, world=(0.0, 0.0, 0.0)))   # a black world: no light
    assert n_entries(black) == 0 and environment_radiance(black) == (0.0, 0.0, 0.0)


def test_one_compilation_serves_every_scene():
    """pack_lights gives the same Numba type for every scene (the empty and mesh-less
    packs included), so the kernels compile once, not once per scene."""
    from numba import typeof
    types = {typeof(pack_lights(light_set(name)[0])) for name in SCENES}
    assert len(types) == 1, types


def test_a_moving_lamp_packs_to_the_same_type():
    """Time slices add rows, not types: a scene with a moving lamp runs the kernels
    compiled for still ones."""
    from numba import typeof
    moving = PointLight((0, 0, 1), (1, 1, 1), motion_slices=[
        PointLight((0, 0, 1), (1, 1, 1)), PointLight((0, 0, 2), (1, 1, 1))])
    L = pack_lights(LightSet([PointLight((1, 0, 1), (1, 1, 1)), moving], 1.0))
    assert typeof(L) == typeof(pack_lights(light_set("all")[0]))
    assert L[SLICE_OF].tolist() == [[0, 0], [0, 2]] and L[LAMP_SLICES].shape[0] == 2
    still = pack_lights(LightSet([PointLight((1, 0, 1), (1, 1, 1)), moving], 1.0),
                        timed=False)                   # a closed shutter: the middle slice
    assert still[SLICE_OF].tolist() == [[0, 0], [0, 0]]


def test_a_moving_lamp_is_its_slice_at_the_rays_time():
    """A lamp that moves during the shutter (TimeSlicedLight: K slices) is, for a ray at
    shutter time t, exactly the still lamp of slice min(floor(t K), K - 1): sampling,
    hits, pdfs and an escaped ray's sun, against the still slice packed alone. Its pick
    probability is the moving lamp's (the slices' mean power), so the comparison scales
    by the ratio; a still lamp ignores the time."""
    K = 4
    kinds = {
        "point": lambda x: PointLight((x, 0.2, 2.0), (40.0, 30.0, 20.0), radius=0.1),
        "area": lambda x: AreaLight(matrix((x, 0.0, 2.0), (1, 0, 0), np.pi, (0.5, 0.5, 1)),
                                    (5.0, 5.0, 5.0), "SQUARE", 1.0, 1.0),
        "sun": lambda x: SunLight((np.sin(x), 0.3, -np.cos(x)), (3.0, 3.0, 3.0),
                                  angle=0.2)}
    rng = np.random.default_rng(9)
    p = rng.uniform(-1.0, 1.0, (64, 3)) * (1.0, 1.0, 0.2)
    u = rng.random((64, 2))
    up = np.full(64, 0.5)
    for name, at in kinds.items():
        xs = [-0.6 + 0.4 * j for j in range(K)]
        moving = at(0.0)
        moving.motion_slices = [at(x) for x in xs]
        L = pack_lights(LightSet([moving, at(5.0)], 1.0))   # a still lamp beside it
        for j, x in enumerate(xs):
            still = pack_lights(LightSet([at(x), at(5.0)], 1.0))
            ratio = L[SELECT_PDF][0] / still[SELECT_PDF][0]
            for t in (j / K, (j + 0.5) / K, (j + 1) / K - 1e-9):
                time = np.full(64, t)
                k, wi, dist, rad, pdf, delta, _ = sample_batch(L, p, up * 0.0, u, time)
                k1, wi1, dist1, rad1, pdf1, _, _ = sample_batch(still, p, up * 0.0, u)
                assert np.all(k == 0) and np.all(k1 == 0), name
                assert np.array_equal(wi, wi1) and np.array_equal(rad, rad1), (name, t)
                np.testing.assert_allclose(pdf, pdf1 * ratio, rtol=1e-12)
                if name == "sun":
                    j_sun = 0
                    a = sun_escaped_batch(L, j_sun, wi, time)
                    b = sun_escaped_batch(still, j_sun, wi)
                    assert np.array_equal(a[0], b[0])
                    np.testing.assert_allclose(a[1], b[1] * ratio, rtol=1e-12)
                    continue
                far = np.full(64, np.inf)
                th, kh, rh = hit_lamps_batch(L, p, wi, far, time)
                th1, kh1, rh1 = hit_lamps_batch(still, p, wi, far)
                assert np.array_equal(th, th1) and np.array_equal(kh, kh1), (name, t)
                assert np.array_equal(rh, rh1)
                np.testing.assert_allclose(lamp_pdf_batch(L, kh, p, wi, th, time),
                                           lamp_pdf_batch(still, kh1, p, wi, th1) * ratio,
                                           rtol=1e-12)
        # slices differ, so the time matters; without one a ray sees the middle slice
        a0 = sample_batch(L, p, up * 0.0, u, np.zeros(64))[1]
        a3 = sample_batch(L, p, up * 0.0, u, np.full(64, 0.99))[1]
        assert not np.allclose(a0, a3), name
        assert np.array_equal(pack_lights(LightSet([moving], 1.0))[LAMPS][0],
                              pack_lights(LightSet([at(xs[K // 2])], 1.0))[LAMPS][0])
