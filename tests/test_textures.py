"""Image textures in the tracer (engine.textures) and their use per hit: texel lookup as
Cycles does it (closest vs bilinear, repeat / extend / clip / mirror, sRGB decoded after
interpolation), texture inputs on materials, UVs interpolated with the hit's
barycentrics, lobe colours, and stochastic transparency (alpha) with its bounce limit.
No Blender needed."""
import numpy as np
import pytest

from engine.bsdf.material_table import MaterialTable
from engine.kernels.bsdf import state as S
from engine.kernels.bsdf.batch import Principled
from engine.render import RenderContext
from engine.scene import Camera, Material, Scene, SunLight, TriangleMesh, World
from engine.settings import RenderSettings
from engine.textures import (Texture, TextureInput, apply_channel, linear_to_srgb,
                             srgb_to_linear)

from engine_scenes import look_at

# A 2 x 2 grey image, rows bottom-up: (row 0) 0.0 0.2 / (row 1) 0.6 1.0
GREY = np.array([[0.0, 0.2], [0.6, 1.0]], np.float32)


def tex(extension="REPEAT", interpolation="Linear", pixels=GREY, srgb=False):
    return Texture(pixels, interpolation, extension, srgb=srgb, name="t")


def val(t, u, v):
    return t.lookup(np.array([[u, v]]))[0, 0]


# --------------------------------------------------------------------------- lookup
def test_closest_reads_the_texel_under_the_point():
    t = tex(interpolation="Closest")
    # texel (i, j) covers [i/2, (i+1)/2) x [j/2, (j+1)/2), row 0 at v = 0
    assert val(t, 0.1, 0.1) == pytest.approx(0.0)
    assert val(t, 0.9, 0.1) == pytest.approx(0.2)
    assert val(t, 0.1, 0.9) == pytest.approx(0.6)
    assert val(t, 0.499, 0.9) == pytest.approx(0.6)
    assert val(t, 0.501, 0.9) == pytest.approx(1.0)


def test_bilinear_is_exact_at_texel_centres_and_blends_between():
    t = tex()
    assert val(t, 0.25, 0.25) == pytest.approx(0.0)
    assert val(t, 0.75, 0.75) == pytest.approx(1.0)
    # the middle of the four centres is their average (Closest would give one texel)
    assert val(t, 0.5, 0.5) == pytest.approx((0.0 + 0.2 + 0.6 + 1.0) / 4)
    assert val(tex(interpolation="Closest"), 0.5, 0.5) == pytest.approx(1.0)
    # a quarter of the way from the centre of texel (0, 0) to that of (1, 0)
    assert val(t, 0.25 + 0.125, 0.25) == pytest.approx(0.75 * 0.0 + 0.25 * 0.2)
    # Cubic and Smart are sampled as Linear
    assert val(tex(interpolation="Cubic"), 0.5, 0.5) == pytest.approx(0.45)


def test_repeat_tiles_the_image():
    t = tex("REPEAT")
    for u, v in [(0.3, 0.2), (0.05, 0.95), (0.5, 0.5)]:
        for du, dv in [(1, 0), (-1, 0), (0, 3), (-2, -5)]:
            assert val(t, u + du, v + dv) == pytest.approx(val(t, u, v), abs=1e-12)
    # bilinear across the seam: at u = 0, halfway between texel 1 (left, wrapped) and 0
    assert val(t, 0.0, 0.25) == pytest.approx(0.5 * (0.0 + 0.2))


def test_extend_stretches_the_border_texels():
    t = tex("EXTEND")
    assert val(t, -3.0, 0.25) == pytest.approx(0.0)
    assert val(t, 7.0, 0.25) == pytest.approx(0.2)
    assert val(t, 7.0, 9.0) == pytest.approx(1.0)
    assert val(t, 0.0, 0.25) == pytest.approx(0.0)     # both taps clamp to texel 0
    assert val(tex("EXTEND", "Closest"), -0.1, 1.5) == pytest.approx(0.6)


def test_clip_is_transparent_black_outside():
    t = tex("CLIP")
    rgba = t.lookup(np.array([[-0.5, 0.5], [1.5, 0.5], [0.5, 2.0]]))
    assert np.all(rgba == 0.0)                         # colour and alpha
    # on the border the outer tap reads zero: half of the border texel (Cycles)
    assert val(t, 1.0, 0.75) == pytest.approx(0.5 * 1.0)
    assert val(tex("CLIP", "Closest"), 1.01, 0.75) == 0.0
    assert val(tex("CLIP", "Closest"), 0.99, 0.75) == pytest.approx(1.0)


def test_mirror_reflects_every_other_tile():
    t = tex("MIRROR")
    for u in (0.1, 0.3, 0.45):
        assert val(t, 1.0 + u, 0.25) == pytest.approx(val(t, 1.0 - u, 0.25), abs=1e-12)
        assert val(t, -u, 0.25) == pytest.approx(val(t, u, 0.25), abs=1e-12)
        assert val(t, 2.0 + u, 0.25) == pytest.approx(val(t, u, 0.25), abs=1e-12)


def test_srgb_curve_values():
    assert srgb_to_linear(0.5) == pytest.approx(0.21404114, rel=1e-6)
    assert srgb_to_linear(0.04) == pytest.approx(0.04 / 12.92)
    assert srgb_to_linear(1.0) == pytest.approx(1.0)
    x = np.linspace(0, 1, 101)
    assert np.allclose(linear_to_srgb(srgb_to_linear(x)), x, atol=1e-12)


def test_srgb_images_are_decoded_after_interpolation_and_alpha_stays_linear():
    rgba = np.zeros((1, 2, 4), np.float32)
    rgba[0, 0] = (0.0, 0.0, 0.0, 0.5)
    rgba[0, 1] = (1.0, 1.0, 1.0, 1.0)
    t = Texture(rgba, "Linear", "EXTEND", srgb=True)
    mid = t.lookup(np.array([[0.5, 0.5]]))[0]
    # Cycles (NODE_IMAGE_COMPRESS_AS_SRGB): decode(lerp(encoded)), not lerp(decode)
    assert mid[:3] == pytest.approx([srgb_to_linear(0.5)] * 3)
    assert mid[3] == pytest.approx(0.75)
    lin = Texture(rgba, "Linear", "EXTEND", srgb=False).lookup(np.array([[0.5, 0.5]]))[0]
    assert lin[0] == pytest.approx(0.5)
    # texel average for the summaries: decoded per texel
    assert t.mean_rgba()[:3] == pytest.approx([0.5] * 3)


def test_grey_and_rgb_images_become_rgba_and_bad_texels_are_zeroed():
    t = Texture(np.array([[0.3, np.nan]], np.float32), "Closest", "REPEAT")
    px = t.lookup(np.array([[0.25, 0.5], [0.75, 0.5]]))
    assert px[0] == pytest.approx([0.3, 0.3, 0.3, 1.0])
    assert px[1] == pytest.approx([0.0, 0.0, 0.0, 1.0])
    with pytest.raises(ValueError):
        Texture(np.zeros((2, 2, 3)), "Nearest", "REPEAT")
    with pytest.raises(ValueError):
        Texture(np.zeros((2, 2, 3)), "Linear", "WRAP")


def test_lookup_is_vectorised_over_many_points():
    rng = np.random.default_rng(3)
    img = rng.random((7, 5, 4)).astype(np.float32)
    t = Texture(img, "Closest", "REPEAT")
    uv = rng.random((10000, 2)) * 4 - 2
    out = t.lookup(uv)
    ix = np.floor(uv[:, 0] * 5).astype(int) % 5
    iy = np.floor(uv[:, 1] * 7).astype(int) % 7
    assert np.allclose(out, img[iy, ix])


def test_texture_input_channels_scale_and_offset():
    rgba = np.array([[[0.2, 0.4, 0.8, 0.5]]], np.float32)
    t = Texture(rgba, "Closest", "REPEAT")
    uv = np.array([[0.5, 0.5]])
    lum = 0.2126729 * 0.2 + 0.7151522 * 0.4 + 0.0721750 * 0.8
    assert TextureInput(t, "luminance").evaluate(uv)[0] == pytest.approx(lum, rel=1e-6)
    assert TextureInput(t, "alpha").evaluate(uv)[0] == pytest.approx(0.5)
    assert TextureInput(t, "alpha_rgb").evaluate(uv)[0] == pytest.approx([0.5] * 3)
    ti = TextureInput(t, "rgb", (2.0, 1.0, 0.5), (0.1, 0.0, 0.0))
    assert ti.evaluate(uv)[0] == pytest.approx([0.5, 0.4, 0.4], rel=1e-6)
    assert ti.scaled(0.5, 0.2).evaluate(uv)[0] == pytest.approx([0.45, 0.4, 0.4], rel=1e-6)
    assert ti.mean() == pytest.approx((0.5, 0.4, 0.4), rel=1e-6)
    with pytest.raises(ValueError):
        apply_channel(rgba, "red")


# --------------------------------------------------------------------------- materials
CHECKER = np.array([[0.1, 0.9], [0.9, 0.1]], np.float32)    # grey checker, linear


def test_material_table_evaluates_textures_per_hit():
    t = Texture(CHECKER, "Closest", "REPEAT", name="checker")
    glow = Texture(np.array([[[1.0, 0.5, 0.25, 1.0]]], np.float32), "Closest", "REPEAT")
    mats = [Material("plain", (0.3, 0.4, 0.5)),
            Material("tex", base_color_texture=TextureInput(t, "rgb"),
                     roughness_texture=TextureInput(t, "luminance", 0.5, 0.1)),
            Material("glow", emission_texture=TextureInput(glow, "rgb", 4.0),
                     emission=(9.0, 9.0, 9.0))]
    table = MaterialTable(mats)
    assert len(table.textures) == 2          # one index per distinct image
    index = np.array([0, 1, 1, 2])
    uv = np.array([[0.25, 0.25], [0.25, 0.25], [0.75, 0.25], [0.5, 0.5]])
    base = table.base_color_at(index, uv)
    assert base[0] == pytest.approx([0.3, 0.4, 0.5])
    assert base[1] == pytest.approx([0.1] * 3)
    assert base[2] == pytest.approx([0.9] * 3)
    rough = table.roughness_at(index, uv)
    assert rough[1] == pytest.approx(0.5 * 0.1 + 0.1) and rough[2] == pytest.approx(0.55)
    assert rough[0] == pytest.approx(0.5)
    em = table.emission_at(index, uv)
    assert em[3] == pytest.approx([4.0, 2.0, 1.0]) and not em[:3].any()
    # light sampling's table leaves textured emission out (found by BSDF rays instead)
    assert not table.emission[2].any() and table.any_emission
    # no UVs on the mesh: Cycles reads UV (0, 0)
    assert table.base_color_at(np.array([1]), None)[0] == pytest.approx([0.1] * 3)


def test_lobe_colours_replace_principleds_own():
    table = MaterialTable([
        Material("glossy", (0.9, 0.6, 0.2), metallic=1.0, roughness=0.3),
        Material("mix", (0.8, 0.1, 0.1), metallic=0.3, metal_color=(1.0, 1.0, 1.0)),
        Material("glass", (0.5, 0.9, 0.5), transmission=1.0, roughness=0.0,
                 glass_color=(0.5, 0.9, 0.5))])
    st = Principled.from_materials(table, np.array([0, 1, 2])).states()
    f0 = st[:, S.S_METAL_F0:S.S_METAL_F0 + 3]
    assert st[0, S.S_W_METAL] == 1.0 and f0[0] == pytest.approx([0.9, 0.6, 0.2])
    assert st[1, S.S_W_METAL] == pytest.approx(0.3)
    assert f0[1] == pytest.approx([1.0, 1.0, 1.0])                 # metal F0: white
    # the diffuse keeps the base colour: weight 0.7 times what the specular layer leaves
    scale = st[1, S.S_DIFFUSE:S.S_DIFFUSE + 3] / np.array([0.8, 0.1, 0.1])
    assert scale == pytest.approx([scale[0]] * 3) and 0.6 < scale[0] < 0.7
    assert st[2, S.S_W_GLASS] == 1.0
    assert st[2, S.S_TINT:S.S_TINT + 3] == pytest.approx([0.5, 0.9, 0.5])  # not sqrt(base)


# --------------------------------------------------------------------------- in the tracer
def _plane_scene(materials, uvs=True, extra_meshes=(), sun=(0.0, 0.0, -1.0), world=0.0):
    """A 2 x 2 m plane at z = 0 (UV (0,0)..(1,1) over x, y in [-1, 1]) under a sun."""
    p = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
    tris = np.array([[0, 1, 2], [0, 2, 3]])
    uv = None
    if uvs:
        corner = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
        uv = corner[tris]
    meshes = [TriangleMesh("plane", p, tris, [0, 0], uvs=uv)] + list(extra_meshes)
    cam = Camera(look_at((0, 0, 5), (0, 0, 0), up=(0, 1, 0)))
    return Scene(cam, 4, 4, meshes, materials, [SunLight(sun, (np.pi,) * 3)],
                 World((world,) * 3))


def _trace(scene, points, settings=None, spp=64, origin_z=5.0):
    """Mean radiance along rays straight down onto the plane at (x, y) points."""
    settings = settings or RenderSettings(samples=spp, diffuse_bounces=0, threads=1)
    ctx = RenderContext(scene, settings)
    try:
        pts = np.asarray(points, float)
        n = len(pts)
        pixel = np.repeat(np.arange(n), spp)
        index = np.tile(np.arange(spp), n)
        o = np.column_stack([pts[pixel], np.full(len(pixel), origin_z)])
        d = np.tile([0.0, 0.0, -1.0], (len(pixel), 1))
        L = ctx.integrator.radiance(pixel, index, o, d, np.full(len(pixel), np.inf))
        return L.reshape(n, spp, 3).mean(1)
    finally:
        ctx.close()


def test_uvs_are_interpolated_with_the_hit_barycentrics():
    scene = _plane_scene([Material()])
    ctx = RenderContext(scene, RenderSettings(samples=1, threads=1))
    try:
        rng = np.random.default_rng(1)
        xy = rng.uniform(-0.99, 0.99, (500, 2))
        o = np.column_stack([xy, np.full(500, 5.0)])
        d = np.tile([0.0, 0.0, -1.0], (500, 1))
        hits = ctx.accel.intersect(o, d, np.full(500, np.inf))
        si = ctx.surfaces.build(hits, np.arange(500), d)
        # the plane's UVs are (x + 1) / 2, (y + 1) / 2 everywhere
        assert np.allclose(si.uv, (xy + 1.0) / 2.0, atol=1e-6)
    finally:
        ctx.close()
    # a scene without UVs has none
    ctx = RenderContext(_plane_scene([Material()], uvs=False), RenderSettings(samples=1))
    try:
        hits = ctx.accel.intersect(o[:3], d[:3], np.full(3, np.inf))
        assert ctx.surfaces.build(hits, np.arange(3), d[:3]).uv is None
    finally:
        ctx.close()


@pytest.mark.parametrize("integrator", ["path", "whitted"])
def test_textured_plane_renders_its_texels(integrator):
    """Sun of irradiance pi at normal incidence on a Lambertian plane: radiance = albedo,
    so every texel shows its own value."""
    t = Texture(CHECKER, "Closest", "REPEAT", name="checker")
    mat = Material("checker", specular_ior_level=0.0, base_color_texture=TextureInput(t))
    pts = [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)]
    L = _trace(_plane_scene([mat]), pts,
               RenderSettings(samples=4, diffuse_bounces=0, integrator=integrator, threads=1),
               spp=4)
    assert L[:, 0] == pytest.approx([0.1, 0.9, 0.9, 0.1], rel=1e-6)


def test_textured_emission_is_seen_and_lights_through_bsdf_rays():
    t = Texture(np.array([[[2.0, 1.0, 0.5, 1.0]]], np.float32), "Closest", "REPEAT")
    glow = Material("glow", (0.0, 0.0, 0.0), specular_ior_level=0.0,
                    emission_texture=TextureInput(t, "rgb", 1.5))
    L = _trace(_plane_scene([glow]), [(0.0, 0.0)], spp=4)
    assert L[0] == pytest.approx([3.0, 1.5, 0.75], rel=1e-9)


def test_alpha_lets_light_through_stochastically():
    """A plane of alpha a at z = 1 over the textured plane at z = 0: the camera sees
    a x (its own radiance) + (1 - a) x the plane below, and the sun's light reaching the
    lower plane is (1 - a) of it (transparent shadow)."""
    a = 0.3
    top = np.array([[-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
    cover = TriangleMesh("cover", top, [[0, 1, 2], [0, 2, 3]], [1, 1])
    mats = [Material("floor", (0.5, 0.5, 0.5), specular_ior_level=0.0),
            Material("cover", (0.8, 0.8, 0.8), specular_ior_level=0.0, alpha=a)]
    scene = _plane_scene(mats, extra_meshes=[cover])
    L = _trace(scene, [(0.1, 0.2)], spp=4096)[0, 0]
    expect = a * 0.8 + (1 - a) * (1 - a) * 0.5
    assert L == pytest.approx(expect, rel=0.03)
    # Transparent bounces 0: no pass-through allowed, the path ends where it would pass
    s0 = RenderSettings(samples=4096, diffuse_bounces=0, transparent_bounces=0, threads=1)
    L0 = _trace(scene, [(0.1, 0.2)], s0, spp=4096)[0, 0]
    assert L0 == pytest.approx(a * 0.8, rel=0.03)
    # a coloured Transparent BSDF (alpha 0) tints what is seen through it
    mats[1] = Material("tinted", (0.0, 0.0, 0.0), specular_ior_level=0.0, alpha=0.0,
                       transparent_color=(1.0, 0.5, 0.25))
    Lt = _trace(_plane_scene(mats, extra_meshes=[cover]), [(0.1, 0.2)], spp=16)[0]
    assert Lt == pytest.approx(np.array([1.0, 0.5, 0.25]) ** 2 * 0.5, rel=1e-9)


def test_alpha_texture_cuts_out_and_opaque_materials_are_unchanged():
    """An alpha checker on the cover: opaque texels show the cover, clear ones the floor."""
    mask = Texture(np.array([[[1, 1, 1, 1.0], [1, 1, 1, 0.0]]], np.float32), "Closest",
                   "REPEAT")
    top = np.array([[-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
    corner = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    cover = TriangleMesh("cover", top, [[0, 1, 2], [0, 2, 3]], [1, 1],
                         uvs=corner[np.array([[0, 1, 2], [0, 2, 3]])])
    mats = [Material("floor", (0.5, 0.5, 0.5), specular_ior_level=0.0),
            Material("cover", (0.8, 0.8, 0.8), specular_ior_level=0.0,
                     alpha_texture=TextureInput(mask, "alpha"))]
    L = _trace(_plane_scene(mats, extra_meshes=[cover]), [(-0.5, 0.0), (0.5, 0.0)], spp=8)
    assert L[0, 0] == pytest.approx(0.8, rel=1e-9)       # opaque half: the cover, lit
    assert L[1, 0] == pytest.approx(0.5, rel=1e-9)       # clear half: floor in full sun


def test_textured_emission_lights_other_surfaces_without_bias():
    """A textured emitter is not light-sampled (one radiance per light triangle), only
    found by BSDF rays, with MIS weight 1: the floor it lights must get what a constant
    emitter of the same radiance (light-sampled, MIS'd) gives it."""
    top = np.array([[-0.5, -0.5, 1], [0.5, -0.5, 1], [0.5, 0.5, 1], [-0.5, 0.5, 1]], float)
    tris = np.array([[0, 2, 1], [0, 3, 2]])                  # facing down
    corner = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    lamp = TriangleMesh("lamp", top, tris, [1, 1], uvs=corner[tris])
    one = Texture(np.array([[[2.0, 2.0, 2.0, 1.0]]], np.float32), "Closest", "REPEAT")
    floor = Material("floor", (0.5, 0.5, 0.5), specular_ior_level=0.0)
    results = []
    for emitter in (Material("const", (0, 0, 0), specular_ior_level=0.0,
                             emission=(2.0, 2.0, 2.0)),
                    Material("tex", (0, 0, 0), specular_ior_level=0.0,
                             emission_texture=TextureInput(one))):
        scene = _plane_scene([floor, emitter], extra_meshes=[lamp], sun=(0.0, 0.0, 1.0))
        ctx_settings = RenderSettings(samples=8192, diffuse_bounces=1, threads=1)
        # look at the floor from below the lamp's edge (rays from z = 0.9, inside the gap)
        L = _trace(scene, [(0.7, 0.0), (0.9, 0.6)], ctx_settings, spp=8192, origin_z=0.9)
        results.append(L[:, 0])
    const, tex = results
    assert const.min() > 0.05
    assert tex == pytest.approx(const, rel=0.02)
