"""An area lamp's Spread (engine/kernels/lights/area.py), against oracles that share none
of its code:

- the weight keeps the lamp's power: the integral of weight x cos over the hemisphere of
  directions a point emits into is pi, for wide, narrow and the narrowest spreads;
- next-event estimation's irradiance equals a quadrature of the lamp's radiance x
  weight x cosines / d^2 over a fine grid of its surface, for a square (spherical
  rectangle sampling of the part that can light the point), a rectangle, a disk and a
  parallelogram (uniform by area in that part), at points on and off the axis and where
  the window meets the lamp's edge; the control (the weight left out) is far off;
- a point outside every emitting cone of the lamp gets no sample at all.
(tests/test_kernel_lights.py's "spread" scene checks that every sample is found again,
with its pdf and radiance, by a ray.)
"""
from __future__ import annotations

import math
import zlib

import numpy as np
import pytest

from engine.kernels.lights import pack_lights
from engine.kernels.lights.area import spread_factor
from engine.kernels.lights.batch import sample_batch
from engine.kernels.lights.pack import LAMPS
from engine.lights import AreaLightModel, LightSet
from engine.scene import AreaLight

UP = np.array([0.0, 0.0, 1.0])


def _lamp(shape, sx, sy, spread, matrix=None):
    m = np.eye(4) if matrix is None else np.array(matrix, float)
    m[:3, 3] = (0.0, 0.0, 1.0)                         # at z = 1, emitting down (-Z)
    return AreaLight(m, (10.0, 10.0, 10.0), shape, sx, sy, spread=spread)


def _weights(L, dirs):
    """The kernel's weight for directions `dirs` from a receiver towards the lamp."""
    lamps = L[LAMPS]
    return np.array([spread_factor(lamps, 0, *d) for d in dirs])


@pytest.mark.parametrize("degrees", [120.0, 45.0, 10.0, 4.0, 0.5])
def test_the_spread_keeps_the_power(degrees):
    L = pack_lights(LightSet([_lamp("SQUARE", 1.0, 1.0, math.radians(degrees))], 1.0))
    half = math.radians(degrees) / 2
    # directions towards the lamp (+Z) at angle a from its axis, over [0, half]
    a = (np.arange(20000) + 0.5) / 20000 * half
    dirs = np.stack([np.sin(a), np.zeros_like(a), np.cos(a)], 1)
    f = _weights(L, dirs)
    power = 2 * math.pi * (f * np.cos(a) * np.sin(a)).sum() * half / 20000
    print(f"{degrees} degrees: on-axis weight {f[0]:.4g}, power / pi {power / math.pi:.6f}")
    # Cycles' normalisation: exact above a half angle of 0.05 rad, a Taylor series below
    assert power / math.pi == pytest.approx(1.0, abs=1e-4 if half > 0.05 else 2e-3)
    beyond = np.array([[math.sin(half * 1.001), 0.0, math.cos(half * 1.001)]])
    assert _weights(L, beyond)[0] == 0.0


def _quadrature(model, light, p, n_r, with_weight=True, n=1500):
    """E at p (normal n_r): radiance x weight x cos_r cos_l / d^2 summed over an n x n
    grid of the lamp's (s, t) square (the weight computed here, from the Spread)."""
    s = (np.arange(n) + 0.5) / n * 2 - 1
    S, T = np.meshgrid(s, s, indexing="ij")
    inside = (S * S + T * T <= 1.0) if model.round else np.ones_like(S, bool)
    q = model.center + S[..., None] * model.ax + T[..., None] * model.ay
    v = q - p
    d = np.linalg.norm(v, axis=-1)
    w = v / d[..., None]
    cos_l = w @ model.normal                     # > 0: the lamp faces p
    cos_r = np.maximum(w @ n_r, 0.0)
    weight = np.ones_like(d)
    if with_weight:
        half = 0.5 * light.spread
        tan_a = np.sqrt(np.maximum(1 - cos_l ** 2, 0)) / np.maximum(cos_l, 1e-300)
        norm = 1 / (math.tan(half) - half) if half > 0.05 else 3 / half ** 3
        weight = np.maximum((math.tan(half) - tan_a) * norm, 0.0)
    cell = 4 * np.linalg.norm(np.cross(model.ax, model.ay)) / (n * n)
    e = model.radiance[0] * weight * cos_r * np.maximum(cos_l, 0) / d ** 2 * cell
    return float(e[inside].sum())


SHEAR = [[1, 0.4, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
CASES = [
    # id, (shape, sx, sy, spread in degrees, matrix), point, receiver normal
    ("square-30-axis", ("SQUARE", 1.0, 1.0, 30.0, None), (0.0, 0.0, 0.0), UP),
    ("square-30-edge", ("SQUARE", 1.0, 1.0, 30.0, None), (0.55, 0.1, 0.2), UP),
    ("rect-8-offaxis", ("RECTANGLE", 2.0, 0.5, 8.0, None), (0.7, -0.1, -1.5),
     (0.3, -0.2, 0.93)),
    ("disk-40", ("DISK", 1.2, 1.2, 40.0, None), (0.3, 0.2, 0.1), UP),
    ("ellipse-20-edge", ("ELLIPSE", 1.6, 0.6, 20.0, None), (0.75, 0.2, -0.3), UP),
    ("parallelogram-25", ("RECTANGLE", 1.0, 0.8, 25.0, SHEAR), (0.2, 0.1, 0.0), UP),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_nee_irradiance_equals_a_quadrature_of_the_weighted_lamp(case):
    name, (shape, sx, sy, degrees, matrix), p, n_r = case
    light = _lamp(shape, sx, sy, math.radians(degrees), matrix)
    model = AreaLightModel(light)
    L = pack_lights(LightSet([light], 1.0), None, False)
    p, n_r = np.asarray(p, float), np.asarray(n_r, float) / np.linalg.norm(n_r)
    expected = _quadrature(model, light, p, n_r)
    n = 400_000
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    s = sample_batch(L, np.tile(p, (n, 1)), np.full(n, 0.5), rng.random((n, 2)))
    wi, rad, pdf = s[1], s[3], s[4]
    ok = pdf > 0
    val = np.where(ok, rad[:, 0] * np.maximum(wi @ n_r, 0) / np.where(ok, pdf, 1.0), 0.0)
    assert np.all(np.isfinite(val))
    est, se = val.mean(), val.std() / math.sqrt(n)
    control = _quadrature(model, light, p, n_r, with_weight=False)
    print(f"{name}: E {est:.6g} +- {se:.2g}, quadrature {expected:.6g}, "
          f"without the weight {control:.6g}")
    assert abs(est - expected) < max(4 * se, 2e-3 * expected)
    assert abs(control - expected) > 0.1 * expected


def test_a_point_outside_every_cone_gets_no_sample():
    """From beside a narrow-spread lamp (10 degrees) no point of it sends light: every
    sample is empty (pdf 0), where without the Spread all of them carry light."""
    narrow = _lamp("SQUARE", 1.0, 1.0, math.radians(10.0))
    p = np.array([3.0, 0.0, 0.0])                  # 1 m below the plane, 3 m aside
    u = np.random.default_rng(3).random((1000, 2))
    for light, lit in ((narrow, 0), (_lamp("SQUARE", 1.0, 1.0, math.pi), 1000)):
        L = pack_lights(LightSet([light], 1.0), None, False)
        s = sample_batch(L, np.tile(p, (1000, 1)), np.full(1000, 0.5), u)
        assert int((s[4] > 0).sum()) == lit
