"""The compiled texture kernels (engine.kernels.textures) against the NumPy code:
`Texture.lookup`, `TextureInput.evaluate` through `MaterialTable.lookup`, `emission_at`,
`alpha_at`, and the per-hit material row the integrator patches (`apply_to_row`).

Both compute the same float64 operations in the same order, so results must be EQUAL
(within the tolerance below), with one exception: the 'luminance' channel, which NumPy computes as
`rgba[:, :3] @ LUMINANCE`. On a batch of rows that is BLAS (gemv, with its own summation
order / fused multiply-adds) and differs from the plain sum r Lr + g Lg + b Lb by up to
~2 ulp; for a single row NumPy's `@` is the plain sum. So rows of a luminance input that
differ from the batch result are evaluated again by NumPy one row at a time and must
then be equal (`agree`), and they must be within 16 ulp of the batch result anyway.
A negative control shows the comparison fails on a swapped extension / sRGB flag.

"Equal" is a tolerance derived from the operations, not bit equality: NumPy's vectorised
`**`, `exp` and `log` are SVML's on CPUs with AVX-512 (up to 4 ulp from libm's, which
the kernels call), and a lookup is a few products and sums of texels, scales and
offsets of order 1 after that: values agree within ULPS ulp of themselves, or within
SCALE_EPS float64 epsilons of the operands' scale (max(|value|, 1)), where a result
near 0 comes out of a difference of O(1) terms (a texel times a negative scale plus an
offset: roughness -0.0223 differed by 7.5 ulp of itself on an Intel Xeon, 1.7e-16 of
its operands).
"""
from __future__ import annotations

import numpy as np
import pytest

from engine.bsdf.material_table import MaterialTable
from engine.kernels.bsdf.params import P_BASE, P_METALLIC, P_ROUGHNESS, pack_materials
from engine.kernels.texture_batch import (alpha_at_batch, apply_to_rows_batch,
                                          emission_at_batch, lookup_batch, rgba_batch)
from engine.kernels.textures import (EXT_MIRROR, EXT_REPEAT, INPUTS, PIXELS,
                                     SCALE_OFFSET, TEX_BASE_COLOR,
                                     TEX_EMISSION, TEX_METALLIC, TEXTURES,
                                     X_EXTENSION, X_SRGB, alpha_at, emission_at,
                                     is_textured, pack_textures, texture_rgba,
                                     textured_value)
from engine.scene import Material
from engine.textures import EXTENSIONS, Texture, TextureInput

SHAPES = [(1, 1), (1, 5), (7, 3), (16, 16)]          # (H, W)
INTERPOLATIONS = ["Linear", "Closest", "Cubic"]      # Cubic is sampled as Linear
PARAMS = MaterialTable.PARAMS


def _image(rng, h, w, c, srgb):
    px = rng.random((h, w, c))
    if srgb:                                          # byte / 255, as Blender stores them
        px = np.round(px * 255.0) / 255.0
    else:                                             # float image: also > 1 and < 0
        px = px * 3.0 - 0.5
    return px.astype(np.float32)


def _uvs(rng, w, h, n_random=400):
    """Random points far outside [0, 1], every texel border and centre (of the image and
    of the next tiles), and non-finite coordinates."""
    coords = np.concatenate([rng.uniform(-5.0, 14.0, n_random),
                             [-3.7, 12.2, 0.0, -0.0, 1.0, -1.0, 2.0, 1e-300, -1e-12, 1e6,
                              -2.5e7, np.nextafter(1.0, 0.0), np.nextafter(0.0, -1.0)]])
    bu = np.arange(-2 * w, 3 * w + 1) / w
    bv = np.arange(-2 * h, 3 * h + 1) / h
    cu = (np.arange(-w, 2 * w) + 0.5) / w
    cv = (np.arange(-h, 2 * h) + 0.5) / h
    u = np.concatenate([coords, bu, cu, rng.choice(coords, len(bv) + len(cv))])
    v = np.concatenate([rng.permutation(coords), rng.choice(coords, len(bu) + len(cu)),
                        bv, cv])
    uv = np.stack([u, v], 1)
    grid = np.stack(np.meshgrid(np.concatenate([bu, cu]), np.concatenate([bv, cv])),
                    -1).reshape(-1, 2)
    bad = np.array([[np.nan, 0.3], [0.7, np.nan], [np.inf, 0.2], [-np.inf, 0.6],
                    [0.4, np.inf], [0.9, -np.inf], [np.nan, np.inf], [np.nan, np.nan]])
    return np.concatenate([uv, grid, bad])


def _table_of(texture):
    return MaterialTable([Material(base_color_texture=TextureInput(texture))])


ULPS = 4
SCALE_EPS = 16


def same(a, b):
    """Elementwise: equal within ULPS ulp, or SCALE_EPS epsilons of max(|b|, 1) (NaNs at
    the same places)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    with np.errstate(invalid="ignore"):
        diff = np.abs(a - b)
        near = (diff <= ULPS * np.spacing(np.abs(b))) | \
            (diff <= SCALE_EPS * np.finfo(float).eps * np.maximum(np.abs(b), 1.0))
    return (a == b) | (np.isnan(a) & np.isnan(b)) | near


def assert_same(a, b, what=""):
    """Equality as `same` has it (NaNs at the same places)."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, what
    bad = ~same(a, b)
    if bad.any():
        i = np.argwhere(bad)[0]
        raise AssertionError(f"{what}: {bad.sum()} values differ, first at {tuple(i)}: "
                             f"kernel {a[tuple(i)]!r} vs NumPy {b[tuple(i)]!r}")


# --------------------------------------------------------------------------- Texture.lookup
@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("channels", [1, 2, 3, 4])
@pytest.mark.parametrize("srgb", [False, True])
def test_texture_rgba_equals_lookup(shape, channels, srgb):
    rng = np.random.default_rng(hash((shape, channels, srgb)) % 2 ** 32)
    h, w = shape
    px = _image(rng, h, w, channels, srgb)
    for interp in INTERPOLATIONS:
        for ext in EXTENSIONS:
            t = Texture(px, interp, ext, srgb=srgb)
            T = pack_textures(_table_of(t))
            uv = _uvs(rng, w, h)
            assert_same(rgba_batch(T, 0, uv), t.lookup(uv), f"{t} {shape} x{channels}")


def test_scalar_kernel_and_special_points():
    """texture_rgba called directly; known values of the 2 x 2 image of test_textures."""
    grey = np.array([[0.0, 0.2], [0.6, 1.0]], np.float32)
    cases = [("Linear", "REPEAT", 0.0, 0.25, 0.1, 1.0),
             ("Linear", "CLIP", 1.0, 0.75, 0.5, 0.5),       # outer taps read (0, 0, 0, 0)
             ("Linear", "EXTEND", 7.0, 9.0, 1.0, 1.0),
             ("Closest", "CLIP", 1.01, 0.75, 0.0, 0.0),
             ("Closest", "MIRROR", 1.2, 0.3, 0.2, 1.0),
             ("Closest", "MIRROR", -0.2, 0.3, 0.0, 1.0),
             ("Linear", "REPEAT", np.nan, np.inf, (0.0 + 0.2 + 0.6 + 1.0) / 4, 1.0)]
    for interp, ext, u, v, want, want_alpha in cases:
        t = Texture(grey, interp, ext)
        T = pack_textures(_table_of(t))
        r, g, b, a = texture_rgba(T, 0, u, v)
        ref = t.lookup([[u, v]])[0]
        assert (r, g, b, a) == tuple(ref)
        assert r == g == b and r == pytest.approx(want) and a == pytest.approx(want_alpha)


def test_shared_pixels_and_many_textures_in_one_table():
    """Several textures (some sharing one pixel array, so one block in T) in one T: each
    id reads its own image with its own settings."""
    rng = np.random.default_rng(7)
    rgba = _image(rng, 5, 4, 4, False)
    other = _image(rng, 3, 9, 3, True)
    texs = [Texture(rgba, "Linear", "REPEAT"), Texture(rgba, "Closest", "MIRROR"),
            Texture(other, "Linear", "CLIP", srgb=True), Texture(rgba, "Linear", "EXTEND",
                                                                 srgb=True)]
    assert texs[0].pixels is texs[1].pixels
    mats = [Material(base_color_texture=TextureInput(texs[0])),
            Material(roughness_texture=TextureInput(texs[1], "luminance")),
            Material(emission_texture=TextureInput(texs[2])),
            Material(metallic_texture=TextureInput(texs[3], "alpha"))]
    table = MaterialTable(mats)
    T = pack_textures(table)
    assert len(T[PIXELS]) == rgba.size + 3 * 9 * 4          # rgba stored once
    uv = _uvs(rng, 4, 5)
    for t in texs:
        k = table.texture_index[id(t)]
        assert_same(rgba_batch(T, k, uv), t.lookup(uv), repr(t))


# --------------------------------------------------------------------------- materials
def _materials(rng):
    """Untextured materials mixed with every textured parameter, channel kind and
    scale / offset form (via TextureInput.scaled, as the exporter builds them)."""
    img = {k: Texture(_image(rng, h, w, c, s), i, e, srgb=s, name=k) for k, (h, w, c, s, i, e)
           in dict(a=(16, 16, 4, True, "Linear", "REPEAT"),
                   b=(7, 3, 3, False, "Closest", "MIRROR"),
                   c=(1, 5, 1, False, "Linear", "CLIP"),
                   d=(1, 1, 4, True, "Closest", "EXTEND"),
                   e=(7, 3, 2, False, "Linear", "MIRROR")).items()}
    ti = TextureInput
    return [
        Material("plain", base_color=(0.2, 0.3, 0.4), metallic=0.3, roughness=0.7,
                 emission=(1.0, 2.0, 3.0), alpha=0.6),
        Material("base_rgb", base_color_texture=ti(img["a"], "rgb")),
        Material("base_scaled", base_color_texture=ti(img["b"], "rgb").scaled(
            (0.5, 2.0, -1.0), (0.1, 0.0, 0.3)), metallic=0.9),
        Material("base_alpha_rgb", base_color_texture=ti(img["a"], "alpha_rgb").scaled(0.8),
                 roughness_texture=ti(img["e"], "alpha").scaled(0.5, 0.25)),
        Material("metal_lum", metallic_texture=ti(img["a"], "luminance"),
                 roughness_texture=ti(img["b"], "luminance").scaled(1.5, -0.2)),
        Material("metal_alpha", metallic_texture=ti(img["e"], "alpha").scaled(-1.0, 1.0),
                 base_color=(0.9, 0.1, 0.1)),
        Material("emit", emission=(5.0, 5.0, 5.0),
                 emission_texture=ti(img["c"], "rgb").scaled(5.0),
                 base_color_texture=ti(img["d"], "rgb")),
        Material("emit_scaled", emission_texture=ti(img["a"], "rgb").scaled((3.0, 1.0, 0.5),
                                                                           0.01)),
        Material("emit_alpha", emission_texture=ti(img["e"], "alpha_rgb").scaled(2.0, 0.5)),
        Material("cut_alpha", alpha_texture=ti(img["a"], "alpha")),
        Material("cut_lum", alpha_texture=ti(img["b"], "luminance").scaled(2.0, -0.5),
                 alpha=0.3),
        Material("cut_scaled", alpha_texture=ti(img["c"], "alpha").scaled(0.5, 0.7),
                 emission=(0.5, 0.0, 0.0)),
        Material("plain2", base_color=(1.0, 1.0, 1.0), roughness=0.05, alpha=1.0),
        Material("everything", base_color_texture=ti(img["e"], "rgb").scaled(0.9),
                 metallic_texture=ti(img["c"], "luminance"),
                 roughness_texture=ti(img["d"], "alpha"),
                 emission_texture=ti(img["b"], "rgb").scaled(4.0, (0.0, 0.1, 0.0)),
                 alpha_texture=ti(img["b"], "alpha").scaled(1.0, -0.1)),
    ]


def _hits(rng, n_mat, n=3000):
    index = rng.integers(0, n_mat, n)
    uv = np.concatenate([rng.uniform(-3.0, 4.0, (n - 8, 2)),
                         [[-3.7, 12.2], [12.2, -3.7], [0.5, 0.5], [1.0, 0.0],
                          [np.nan, 0.5], [np.inf, -np.inf], [0.25, np.nan], [1e5, -1e5]]])
    return index, uv


def _luminance_rows(table, name, index):
    inputs = table._inputs.get(name)
    if inputs is None:
        return np.zeros(len(index), bool)
    lum = np.array([t is not None and t.channel == "luminance" for t in inputs])
    return lum[index]


def agree(kernel_out, numpy_out, numpy_one_row, loose_rows, what):
    """Equal, except rows of luminance inputs, which may differ by NumPy's batched `@`:
    those must equal NumPy's one-row result and lie within 16 ulp of the batch one."""
    k, b = np.asarray(kernel_out), np.asarray(numpy_out)
    rows = np.nonzero(np.any((~same(k, b)).reshape(len(k), -1), axis=1))[0]
    if len(rows):
        assert loose_rows[rows].all(), f"{what}: rows {rows[~loose_rows[rows]][:5]} differ"
        tol = 16 * np.finfo(float).eps * np.maximum(np.abs(b[rows]), 1.0)
        assert np.all(np.abs(k[rows] - b[rows]) <= tol), what
        for i in rows[:200]:
            assert_same(k[i], numpy_one_row(i), f"{what} row {i} alone")
    assert_same(k[~loose_rows], b[~loose_rows], what)


@pytest.fixture(scope="module")
def scene():
    rng = np.random.default_rng(2024)
    table = MaterialTable(_materials(rng))
    index, uv = _hits(rng, len(table.metallic))
    return table, pack_textures(table), index, uv


@pytest.mark.parametrize("name", PARAMS)
def test_lookup_equals_material_table(scene, name):
    table, T, index, uv = scene
    assert table.textured[name].any() and not table.textured[name].all()
    agree(lookup_batch(T, name, index, uv), table.lookup(name, index, uv),
          lambda i: table.lookup(name, index[i:i + 1], uv[i:i + 1])[0],
          _luminance_rows(table, name, index), name)
    # the same through the parameter id, and without UVs (read as (0, 0))
    p = PARAMS.index(name)
    agree(lookup_batch(T, p, index, None), table.lookup(name, index, None),
          lambda i: table.lookup(name, index[i:i + 1], None)[0],
          _luminance_rows(table, name, index), name + " no uv")


def test_emission_and_alpha_at(scene):
    table, T, index, uv = scene
    agree(emission_at_batch(T, table.emission, index, uv), table.emission_at(index, uv),
          lambda i: table.emission_at(index[i:i + 1], uv[i:i + 1])[0],
          np.zeros(len(index), bool), "emission_at")
    alpha = alpha_at_batch(T, table.alpha, index, uv)
    agree(alpha, table.alpha_at(index, uv),
          lambda i: table.alpha_at(index[i:i + 1], uv[i:i + 1])[0],
          _luminance_rows(table, "alpha", index), "alpha_at")
    assert alpha.min() == 0.0 and alpha.max() == 1.0 and ((alpha > 0) & (alpha < 1)).any()
    # the scalar kernels, called directly
    for i in range(0, len(index), 97):
        m, u, v = int(index[i]), uv[i, 0], uv[i, 1]
        assert same(emission_at(T, table.emission, m, u, v),
                    table.emission_at(index[i:i + 1], uv[i:i + 1])[0]).all()
        assert same(alpha_at(T, table.alpha, m, u, v),
                    table.alpha_at(index[i:i + 1], uv[i:i + 1])[0])


def test_is_textured_and_textured_value(scene):
    table, T, index, uv = scene
    for p, name in enumerate(PARAMS):
        flags = table.textured.get(name, np.zeros(len(table.metallic), bool))
        for m in range(len(table.metallic)):
            assert is_textured(T, m, p) == bool(flags[m])
            x, y, z = textured_value(T, m, p, 0.3, 0.8)
            if not flags[m]:
                assert (x, y, z) == (0.0, 0.0, 0.0)
                continue
            ref = table._inputs[name][m].evaluate([[0.3, 0.8]])[0]
            assert same((x, y, z), tuple(ref) if np.ndim(ref) else (ref, 0.0, 0.0)).all()


@pytest.mark.parametrize("columns", [(P_BASE, P_METALLIC, P_ROUGHNESS), (9, 2, 0)])
def test_apply_to_row(scene, columns):
    table, T, index, uv = scene
    pb, pm, pr = columns
    rng = np.random.default_rng(5)
    if columns == (P_BASE, P_METALLIC, P_ROUGHNESS):
        before = pack_materials(table)[index]
    else:
        before = rng.normal(size=(len(index), 13))
    after = apply_to_rows_batch(T, index, uv, before, pb, pm, pr)
    # textured parameters: the NumPy per-hit values; untextured: the row untouched
    for name, cols in (("base_color", slice(pb, pb + 3)), ("metallic", pm),
                       ("roughness", pr)):
        tex = table.textured.get(name)[index]
        want = np.where(tex[:, None] if name == "base_color" else tex,
                        table.lookup(name, index, uv), before[:, cols])
        agree(after[:, cols], want,
              lambda i: table.lookup(name, index[i:i + 1], uv[i:i + 1])[0]
              if tex[i] else before[i, cols],
              _luminance_rows(table, name, index), "row " + name)
    other = np.ones(before.shape[1], bool)
    other[[pb, pb + 1, pb + 2, pm, pr]] = False
    assert_same(after[:, other], before[:, other], "other columns")
    if columns == (P_BASE, P_METALLIC, P_ROUGHNESS):   # the untextured rows: plain values
        plain = ~table.textured["base_color"][index]
        assert_same(after[plain, P_BASE:P_BASE + 3], table.base_color[index[plain]])


def test_table_without_textures():
    table = MaterialTable([Material("a", emission=(1.0, 0.5, 0.0), alpha=0.4),
                           Material("b", metallic=1.0, roughness=0.2, alpha=1.7)])
    T = pack_textures(table)
    assert T[PIXELS].shape == (0,) and T[TEXTURES].shape == (0, 6)
    assert (T[INPUTS][:, :, 0] == -1).all()
    rng = np.random.default_rng(3)
    index, uv = _hits(rng, 2, 200)
    for name in PARAMS:
        assert_same(lookup_batch(T, name, index, uv), table.lookup(name, index, uv), name)
    assert_same(emission_at_batch(T, table.emission, index, uv), table.emission_at(index, uv))
    assert_same(alpha_at_batch(T, table.alpha, index, uv), table.alpha_at(index, uv))
    rows = pack_materials(table)[index]
    assert_same(apply_to_rows_batch(T, index, uv, rows, P_BASE, P_METALLIC, P_ROUGHNESS),
                rows)
    assert not is_textured(T, 0, TEX_BASE_COLOR)
    assert textured_value(T, 1, TEX_METALLIC, 0.5, 0.5) == (0.0, 0.0, 0.0)
    assert texture_rgba(T, 0, 0.5, 0.5) == (1.0, 0.0, 1.0, 1.0)   # no such texture


def test_scalar_parameter_with_colour_channel_is_refused():
    t = Texture(np.ones((2, 2, 3), np.float32))
    with pytest.raises(ValueError, match="colour channel"):
        pack_textures(MaterialTable([Material(roughness_texture=TextureInput(t, "rgb"))]))
    with pytest.raises(ValueError, match="one scale"):
        pack_textures(MaterialTable([Material(
            metallic_texture=TextureInput(t, "luminance").scaled((1.0, 2.0, 3.0)))]))


# --------------------------------------------------------------------------- negative control
def _swap_extension(T):
    ext = T[TEXTURES][:, X_EXTENSION]
    ext[:] = np.where(ext == EXT_REPEAT, EXT_MIRROR, EXT_REPEAT)


def _flip_srgb(T):
    T[TEXTURES][:, X_SRGB] ^= 1


def _nudge_emission_scale(T):
    so = T[SCALE_OFFSET][13, TEX_EMISSION]          # material "everything": scale 4
    assert so[1] == 4.0
    so[1] = 4.0 * (1.0 + 1e-13)                       # some 400 ulp: beyond ULPS


@pytest.mark.parametrize("perturb, names", [(_swap_extension, ("base_color", "emission")),
                                            (_flip_srgb, ("base_color", "emission")),
                                            (_nudge_emission_scale, ("emission",))])
def test_negative_control_comparison_can_fail(scene, perturb, names):
    """A swapped extension, a flipped sRGB flag or a scale 1e-13 off in T makes the
    very comparison used above fail; the untouched T passes it."""
    table, T, index, uv = scene
    bad = tuple(np.array(a, copy=True) for a in T)
    perturb(bad)
    for name in names:
        check = (lambda T_: agree(lookup_batch(T_, name, index, uv),
                                  table.lookup(name, index, uv),
                                  lambda i: table.lookup(name, index[i:i + 1], uv[i:i + 1])[0],
                                  _luminance_rows(table, name, index), "control " + name))
        check(T)
        with pytest.raises(AssertionError):
            check(bad)
