"""Baking in the engine (engine.bake), without Blender, on closed forms: a Lambertian
plane under a uniform world L leaves albedo x L towards its normal (Combined, and Diffuse with
Blender's default filter), its Diffuse light without the Color filter is L and its
colour alone the albedo, its normal is the
plane's and nothing occludes it (AO 1); Blender's barycentrics (u weighs corner 0, v
corner 1) land on the points they name; a box standing on the plane darkens the AO and
the light around it, never above the open plane's."""
import numpy as np
import pytest

from engine import RenderContext, RenderSettings
from engine import bake
from engine.scene import Camera, Material, Scene, World
from engine_scenes import box, look_at, quad

ALBEDO, SKY = 0.6, (0.3, 0.4, 0.5)


def _context(kind, filt=-1, with_box=False, samples=64):
    plane = quad((0, 0, 0), (50, 0, 0), (0, 50, 0), "plane")
    meshes = [plane] + ([box((-0.5, -0.5, 0.0), (0.5, 0.5, 1.0), "box")] if with_box else [])
    mat = Material("lambert", (ALBEDO,) * 3, specular_ior_level=0.0)
    cam = Camera(look_at((0.0, -2.0, 1.5), (0.0, 0.0, 0.0)), lens=50.0)
    scene = Scene(cam, 4, 4, meshes, [mat], [], World(SKY))
    settings = bake.settings_for(RenderSettings(samples=samples, threads=1), kind, filt)
    return RenderContext(scene, settings)


def _points_near(x, y, n=16):
    """Blender barycentrics of n points of the plane's first triangle near (x, y): the
    quad's corners are (-50, -50), (50, -50), (50, 50), so y <= x (a point past the
    diagonal would lie on the other triangle, which its rays, naming only this one, meet
    at distance 0: engine.embree.self_hits)."""
    assert y <= x
    # P = u c0 + v c1 + (1 - u - v) c2 in Blender's convention
    u = np.full(n, (50.0 - x) / 100.0)
    v = np.full(n, (x - y) / 100.0)
    return np.zeros(n, np.int64), u, v


def test_points_land_where_blenders_barycentrics_say():
    ctx = _context("NORMAL")
    try:
        prim, u, v = _points_near(10.0, -20.0, 1)
        pts = bake.points(ctx, prim, u, v)
    finally:
        ctx.close()
    np.testing.assert_allclose(pts.origins - pts.normal, [[10.0, -20.0, 0.0]], atol=1e-9)
    np.testing.assert_allclose(pts.normal, [[0.0, 0.0, 1.0]], atol=1e-12)
    np.testing.assert_allclose(pts.directions, -pts.normal)


@pytest.mark.parametrize("kind, filt, expected", [
    ("COMBINED", -1, ALBEDO * np.array(SKY)),
    ("DIFFUSE", -1, ALBEDO * np.array(SKY)),        # Blender's default: light x colour
    ("DIFFUSE", -1 & ~bake.COLOR, np.array(SKY)),    # without Color: the light alone
    ("DIFFUSE", bake.COLOR, np.full(3, ALBEDO)),               # colour alone
    ("DIFFUSE", bake.DIRECT | bake.INDIRECT | bake.COLOR, ALBEDO * np.array(SKY)),
    ("NORMAL", -1, np.array([0.0, 0.0, 1.0])),
    ("AO", -1, np.ones(3)),
    ("EMIT", -1, np.zeros(3)),
])
def test_a_plane_under_a_uniform_world(kind, filt, expected):
    ctx = _context(kind, filt)
    try:
        prim, u, v = _points_near(4.0, 3.0)
        got = bake.bake(ctx, prim, u, v, kind, filt)
    finally:
        ctx.close()
    print(kind, filt, got.mean(axis=0), "expected", expected)
    np.testing.assert_allclose(got.mean(axis=0), expected, rtol=0.02, atol=1e-9)


def test_a_box_on_the_plane_shadows_its_foot():
    near = _points_near(0.6, 0.0, 32)
    far = _points_near(20.0, 0.0, 32)
    out = {}
    for kind in ("AO", "COMBINED"):
        ctx = _context(kind, with_box=True)
        try:
            out[kind] = [bake.bake(ctx, *p, kind).mean() for p in (near, far)]
        finally:
            ctx.close()
    print(out)
    assert out["AO"][0] < 0.8 and out["AO"][1] > 0.98
    assert out["COMBINED"][0] < 0.9 * out["COMBINED"][1]


def test_what_it_cannot_bake_is_refused():
    ctx = _context("NORMAL")
    try:
        with pytest.raises(ValueError, match="cannot bake 'ROUGHNESS'"):
            bake.bake(ctx, *_points_near(0.0, 0.0, 1), "ROUGHNESS")
    finally:
        ctx.close()
