"""The compiled light kernels (engine.kernels.lights) on hard scenes, checked against
themselves the way rendering uses them (their distributions against their pdfs are
chi-square tested in tests/test_light_sampling.py).

- Every light sample, traced back, finds what it sampled (the lamp's surface at the
  sampled distance with the same radiance, the sun or world along an escaped ray, the
  emissive triangle at the sampled point), and the pdf found there, which weighs a
  BSDF-sampled ray that hits the light, is the sample's pdf (to 1e-6). A pdf evaluated
  from a point 1e-4 relative away (the negative control) is not.
- Entries are picked in proportion to their power, exactly.
- The scalar kernels equal the rows of their array drivers; one compiled type serves
  every scene; a moving lamp is its still slice at the ray's time.

Scenes: each light type alone (point, spots, sphere, soft-falloff disc, suns with zero,
tiny and finite angles, area SQUARE / RECTANGLE / DISK / ELLIPSE scaled, rotated,
sheared and mirrored with normalize on and off, world, emissive triangles), tiny lights,
all together, and an empty set. Shading points: a box about each light, close to it
(1e-8 .. 3), near an area light's plane, inside sphere lights, at a light's centre and
1e4 away.
"""
from __future__ import annotations

import zlib

import numpy as np
import pytest

from engine.kernels.lights import (OMNI, ONE_SIDED, TWO_SIDED, environment_pdf,
                                   environment_radiance, hit_lamps, lamp_hit, lamp_pdf,
                                   n_entries, n_suns, pack_lights, sample, select_pdf,
                                   sun_escaped)
from engine.kernels.lights.batch import (hit_lamps_batch, lamp_pdf_batch, mesh_pdf_batch,
                                         sample_batch, sun_escaped_batch)
from engine.kernels.lights.pack import LAMP_SLICES, LAMPS, SELECT_PDF, SLICE_OF, SUNS
from engine.lights import LightSet
from engine.mesh_lights import EmissiveTriangles
from engine.scene import AreaLight, PointLight, SunLight

# engine.lights divides by r^2 = 0 for the 1e-170 m sphere of the "tiny" scene (which then
# becomes a point light, as intended)
pytestmark = pytest.mark.filterwarnings("ignore:divide by zero:RuntimeWarning")

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
    elif name == "spread":
        # area lamps whose Spread narrows their emission (full angles, radians): sampled
        # in the part of the lamp that can light the point (kernels/lights/area.py)
        lights = [AreaLight(matrix((0, 0, 2), (1, 0, 0), np.pi, (1.5, 0.7, 1)),
                            (20, 18, 16), "SQUARE", 0.7, spread=1.0),
                  AreaLight(matrix((1, -1, 1.5), (1, 1, 0), 2.6, (1, 2, 1)),
                            (9, 9, 9), "RECTANGLE", 1.2, 0.4, spread=0.17),
                  AreaLight(matrix((-1, 0.5, 2.2), (0.3, 1, 0.2), 2.9, (0.5, 0.5, 0.5)),
                            (5, 6, 7), "DISK", 0.5, spread=0.5),
                  AreaLight(matrix((0.5, 1.5, 1.8), (1, 0, 0.4), 3.0, (1.3, 0.6, 1)),
                            (8, 4, 2), "ELLIPSE", 0.8, 0.3, spread=0.09),
                  AreaLight(matrix((-1.2, -1.0, 1.0), (0, 1, 0), 2.8, (1, 1, 1), shear=0.4),
                            (6, 6, 6), "RECTANGLE", 1.0, 0.5, spread=0.7),
                  AreaLight(matrix((0.2, 0.0, 3.0), (1, 0, 0), np.pi, (1, 1, 1)),
                            (7, 7, 7), "SQUARE", 2.0, spread=0.0)]      # the least spread
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
                  + scene("sun")[0] + scene("area")[0] + scene("spread")[0])
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


SCENES = ["point", "sphere", "disc", "sun", "area", "spread", "world", "triangles", "tiny",
          "all", "empty"]


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


# ------------------------------------------------------------------ consistency

def lamp_hits(L, k, p, wi):
    """Where the rays p + t wi meet lamp k[i] alone (engine.kernels.lights.lamp_hit):
    (t (n,), radiance (n, 3)); t inf where they miss it."""
    t = np.empty(len(p))
    rad = np.empty((len(p), 3))
    for i in range(len(p)):
        t[i], *rad[i] = lamp_hit(L, int(k[i]), *p[i], *wi[i], 31, 0.0)
    return t, rad


def _unresolvable(model, q):
    """Whether a sphere lamp's radius squared is below float64's resolution of its
    centre's squared distance from q."""
    r = getattr(model, "radius", 0.0)
    if not r > 0.0 or not hasattr(model, "position"):
        return False
    d2 = float(np.sum((np.asarray(model.position) - q) ** 2))
    return r * r < np.finfo(np.float64).eps * d2


def consistency(L, ls, p, up, u, shift=1.0, normals=None, mode=OMNI):
    """Sample every light entry from p (receivers with these normals and mode: the
    light tree picks for them), then find each sample again the way the path tracer
    finds emission (a lamp's surface hit by the ray, a sun or the world seen by an
    escaped ray, an emissive triangle hit at the sampled point) and evaluate its pdf
    there; `shift` scales p for that second evaluation (the negative control). Returns
    a dict of (what, mismatched rows, rows checked, rows at a uniform's edge among the
    mismatched)."""
    k, wi, dist, rad, pdf, delta, light_prim, margin = sample_batch(L, p, up, u, None, normals,
                                                                    mode)
    n_lamps = ls.n_lamps
    edge = np.any((u == 0.0) | (u == ONE_MINUS), axis=1)
    q = p * shift
    nq = np.zeros_like(q) if normals is None else normals

    def recv(r):
        return (*q[r], *nq[r], mode, 0.0)
    ok = pdf > 0
    out = {}
    lamp = ok & (k >= 0) & (k < n_lamps) & ~delta
    surface = lamp & np.isfinite(dist)
    if surface.any():
        rows = np.nonzero(surface)[0]
        t, rh = lamp_hits(L, k[rows], q[rows], wi[rows])
        found = np.isfinite(t)
        pdf_hit = np.zeros(len(rows))
        pdf_hit[found] = lamp_pdf_batch(L, k[rows][found], q[rows][found], wi[rows][found],
                                         t[found], None, nq[rows][found], mode)
        bad = ~found | ~np.isclose(t, dist[rows], rtol=1e-6) \
            | ~np.isclose(pdf_hit, pdf[rows], rtol=1e-6) \
            | ~np.all(np.isclose(rh, rad[rows], rtol=1e-9), axis=1)
        # a sphere lamp so small and far that its radius squared vanishes against the
        # squared distance in float64 (a 1e-6 m sphere 1e4 m away): no ray can resolve
        # it, and a ray back towards it may miss, as one on a rim may
        unresolved = np.array([_unresolvable(ls.models[int(k[r])], q[r]) for r in rows],
                              dtype=bool)
        out["lamp surfaces"] = (int(bad.sum()), len(rows),
                                int((bad & (edge[rows] | unresolved)).sum()))
    point = ok & (k >= 0) & (k < n_lamps) & delta   # point lamps and suns without a disc
    if point.any():
        rows = np.nonzero(point)[0]
        bad = np.zeros(len(rows), bool)
        for i, r in enumerate(rows):
            m = ls.models[int(k[r])]
            if hasattr(m, "position"):
                to = m.position - q[r]
                d = np.linalg.norm(to)
                bad[i] = not (np.isclose(dist[r], d, rtol=1e-9)
                              and np.allclose(wi[r], to / d, rtol=0, atol=1e-9))
            else:
                bad[i] = not (np.isinf(dist[r]) and np.allclose(wi[r], m.to_light, atol=1e-12))
            bad[i] |= not np.isclose(pdf[r], select_pdf(L, int(k[r]), recv(r), 0.0),
                                     rtol=1e-12)
        out["point lamps and delta suns"] = (int(bad.sum()), len(rows), 0)
    far = lamp & ~np.isfinite(dist)                # suns with a disc and the world
    if far.any():
        rows = np.nonzero(far)[0]
        suns = {int(e): j for j, e in enumerate(L[SUNS])}
        got = np.zeros(len(rows))
        for i, r in enumerate(rows):
            if int(k[r]) in suns:
                got[i] = sun_escaped(L, suns[int(k[r])], *wi[r], recv(r), 0.0)[3]
            else:
                got[i] = environment_pdf(L, *wi[r], recv(r), 0.0)
        bad = ~np.isclose(got, pdf[rows], rtol=1e-6)
        out["suns and world"] = (int(bad.sum()), len(rows), int((bad & edge[rows]).sum()))
    tri = ok & (k >= n_lamps)
    if tri.any():
        rows = np.nonzero(tri)[0]
        prim = ls.mesh.prim[k[rows] - n_lamps].astype(np.int64)
        point = p[rows] + wi[rows] * dist[rows, None]
        got = mesh_pdf_batch(L, prim, np.ascontiguousarray(q[rows]), point, nq[rows], mode)
        bad = ~np.isclose(got, pdf[rows], rtol=1e-6)
        out["emissive triangles"] = (int(bad.sum()), len(rows), int((bad & edge[rows]).sum()))
    return out


@pytest.mark.parametrize("tree", [True, False], ids=["tree", "no tree"])
@pytest.mark.parametrize("name", SCENES)
def test_every_sample_is_found_again_with_its_pdf(name, tree):
    """What multiple importance sampling relies on, on scenes of every light kind at
    hard shading points (a box about each light, 1e-8 .. 3 from it, near an area lamp's
    plane, inside sphere lights, at their centres, 1e4 away): a light sample's direction,
    traced back, finds the light it sampled at the sampled distance, with the same
    radiance, and the pdf found there (what a BSDF-sampled ray that hits the light uses)
    is the sample's pdf. Only a sample on a lamp's rim (a uniform of exactly 0 or 1,
    which `uniforms` mixes in) may miss: the ray then grazes the rim, a tie that rounding
    decides; or one of a sphere lamp too small for float64 to resolve from that far.
    With the light tree the pick depends on the receiver: the points are then
    taken with random normals as opaque, transmitting and volume receivers."""
    ls, anchors = light_set(name)
    L = pack_lights(ls, tree=tree)
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    p = shading_points(ls, anchors, rng)
    up, u = pick_uniforms(ls, rng, len(p)), uniforms(rng, len(p))
    normals = unit(rng.normal(size=p.shape))
    for mode in ((ONE_SIDED, TWO_SIDED, OMNI) if tree else (OMNI,)):
        found = consistency(L, ls, p, up, u, normals=normals, mode=mode)
        print(name, mode, found)
        if name == "empty":
            assert found == {}
            continue
        assert found, "no sample to check"
        for what, (bad, rows, at_edge) in found.items():
            assert bad == at_edge, (what, mode, bad, at_edge)   # only rim samples may miss


def test_the_consistency_check_fails_for_a_wrong_pdf():
    """Negative control: the pdf evaluated from a point 1e-4 relative away disagrees
    with the sample's on most rows of every light kind."""
    ls, anchors = light_set("all")
    L = pack_lights(ls)
    rng = np.random.default_rng(2)
    p = shading_points(ls, anchors, rng)
    found = consistency(L, ls, p, pick_uniforms(ls, rng, len(p)), uniforms(rng, len(p)),
                        shift=1.0 + 1e-4)
    for what, (bad, rows, _) in found.items():
        if what not in ("suns and world", "point lamps and delta suns"):
            # (an escaped ray's pdf ignores the point; a delta lamp's is its pick)
            assert bad > 0.5 * rows, (what, bad, rows)


@pytest.mark.parametrize("name", ["point", "area", "triangles", "all"])
def test_entries_are_picked_in_proportion_to_select_pdf(name):
    """The pick (a CDF searched from its guide table) gives entry k to the share
    select_pdf[k] of the uniforms: exactly, to one step of a grid of them."""
    ls, _ = light_set(name)
    L = pack_lights(ls, tree=False)
    n = 100_000
    up = (np.arange(n) + 0.5) / n
    k = sample_batch(L, np.zeros((n, 3)) + (0.1, 0.2, 0.3), up, np.full((n, 2), 0.5))[0]
    share = np.bincount(k, minlength=len(ls)) / n
    np.testing.assert_allclose(share, ls.select_pdf, atol=1.0 / n)


def test_scalar_kernels_equal_batch_rows():
    ls, anchors = light_set("all")
    L = pack_lights(ls)
    rng = np.random.default_rng(5)
    p = shading_points(ls, anchors, rng, n=20)[:40]
    up, u = pick_uniforms(ls, rng, len(p)), uniforms(rng, len(p))
    rows = sample_batch(L, p, up, u)
    for i in range(len(p)):
        recv = (*p[i], 0.0, 0.0, 0.0, OMNI, 0.0)
        one = sample(L, recv, up[i], *u[i], 0.0)
        assert one[0] == rows[0][i] and one[9] == rows[5][i]
        assert one[1:4] == tuple(rows[1][i]) and one[5:8] == tuple(rows[3][i])
        assert (one[4], one[8], one[10]) == (rows[2][i], rows[4][i], rows[6][i])
        d = rows[1][i]
        t, k, r, g, b = hit_lamps(L, *p[i], *d, np.inf, 31, 0.0)
        assert (t, k) == tuple(x[0] for x in hit_lamps_batch(L, p[i:i + 1], d[None],
                                                             np.array([np.inf]))[:2])
        assert lamp_pdf(L, k, recv, *d, t, 0.0) == lamp_pdf_batch(
            L, np.array([k]), p[i:i + 1], d[None], np.array([t]))[0]


def test_empty_set():
    ls = LightSet([], 1.0)
    L = pack_lights(ls)
    assert n_entries(L) == 0 and n_suns(L) == 0
    recv = (0.0, 0.0, 0.0, 0.0, 0.0, 1.0, ONE_SIDED, 0.0)
    k, wx, wy, wz, dist, r, g, b, pdf, delta, light_prim, margin = sample(
        L, recv, 0.3, 0.5, 0.5, 0.0)
    assert k == -1 and pdf == 0.0 and not delta and (r, g, b) == (0.0, 0.0, 0.0)
    assert hit_lamps(L, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 7.0, 31, 0.0) == (7.0, -1, 0.0, 0.0, 0.0)
    assert environment_pdf(L, 0.0, 0.0, 1.0, recv, 0.0) == 0.0
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
    probability is the moving lamp's (picked without the tree here, as the light tree's
    pick depends on where the lamp is), so the comparison scales by the
    ratio; a still lamp ignores the time."""
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
        L = pack_lights(LightSet([moving, at(5.0)], 1.0), tree=False)   # a still lamp beside
        for j, x in enumerate(xs):
            still = pack_lights(LightSet([at(x), at(5.0)], 1.0), tree=False)
            ratio = L[SELECT_PDF][0] / still[SELECT_PDF][0]
            for t in (j / K, (j + 0.5) / K, (j + 1) / K - 1e-9):
                time = np.full(64, t)
                k, wi, dist, rad, pdf, delta, _, _ = sample_batch(L, p, up * 0.0, u, time)
                k1, wi1, dist1, rad1, pdf1, _, _, _ = sample_batch(still, p, up * 0.0, u)
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
