"""Heterogeneous volumes in the engine (engine.kernels.medium_density): media whose
coefficients a shader program computes per point, against closed forms; no Blender.

- Emission varying in space in a uniform absorber integrates exactly.
- Transmittance: a sphere of absorber whose density grows as (y + 1)^2 along the view
  axis, seen through its centre, transmits exp(-sigma 8/3) (the integral of the density
  along the chord), not the exp(-sigma 2.4) of its average density: ratio tracking
  (camera rays) is unbiased.
- Volume furnace: a sphere of scattering-only medium whose density varies in space
  (albedo 1 everywhere, a different extinction per channel) in a white world: every
  pixel sees the world. This exercises delta tracking's scattering distances, its
  spectral MIS, ratio tracking on the shadow rays and the volume stack.
- The majorant: bound from samples of the program over the mesh.
- Cost: a scene of homogeneous media runs no program inside a medium (the integrator's
  counter stays 0); the heterogeneous one does.
"""
import numpy as np

from engine import RenderSettings, Volume, render
from engine.kernels.volume import V_HET, V_MAJ
from engine.nodes import context as C
from engine.nodes import converter_nodes as CV
from engine.nodes import input_nodes as I
from engine.nodes import vector_nodes as VN
from engine.nodes.program import ProgramBuilder
from engine.render import RenderContext
from test_volumes import R, _sphere_scene as volume_sphere


def _graded(output, coeffs, constants=None):
    """A program whose `output` is coeffs x (y + 1)^2, y the object-space height along
    the view axis (the identity object: world y); `constants`: {output: RGB} more
    outputs that do not vary."""
    b = ProgramBuilder()
    for name, value in (constants or {}).items():
        b.output(name, b.constant(tuple(value), "vector"))
    y = b.emit(I.IN_HIT1, "float", [C.H_OBJECT + 1], varying=True)
    s = b.emit(CV.CV_MATH, "float", [y, b.constant(1.0), b.constant(0.0),
                                     CV.MATH_OPS.index("ADD"), 0])
    s2 = b.emit(CV.CV_MATH, "float", [s, s, b.constant(0.0), CV.MATH_OPS.index("MULTIPLY"),
                                      0])
    c = b.constant(tuple(coeffs), "vector")
    v = b.emit(VN.VEC_MATH, "vector", [c, c, c, s2, VN.VECTOR_OPS.index("SCALE")])
    b.output(output, v)
    return b.build()


def _sphere_scene(volume, program, **kw):
    """test_volumes' sphere of medium of radius R, its material running `program`."""
    scene = volume_sphere(volume, **kw)
    scene.materials[0].shader = program
    return scene


def test_graded_absorber_transmits_exp_minus_integral():
    """A narrow camera (every pixel's chord within 1 % of the diameter): the image
    mean against the centre chord's exp(-integral), which lies at most 2 % below the
    exact mean of the pixels' chords."""
    sigma = np.array([0.3, 0.6, 1.0])
    mean_density = 1.2                                  # E[(y + 1)^2] over the ball
    vol = Volume(absorption=tuple(sigma * mean_density))
    film, _ = render(_sphere_scene(vol, _graded("volume_absorption", sigma), lens=1000.0),
                     RenderSettings(samples=1024, seed=0))
    got = film.mean().mean(axis=(0, 1))
    expected = np.exp(-sigma * 8.0 / 3.0)
    averaged = np.exp(-sigma * mean_density * 2 * R)
    print("transmittance", got, "expected", expected, "averaged density", averaged)
    np.testing.assert_allclose(got, expected, rtol=0.035)
    # a control: the averaged density's transmittance is outside the tolerance
    assert np.all(np.abs(averaged - got) > 0.06 * got)


def test_graded_emission_through_an_absorber_integrates_exactly():
    """Emission e (y + 1)^2 in a uniform absorber sigma: along the centre chord the
    camera sees the integral of e u^2 exp(-sigma u) over u = y + 1 in [0, 2] (the
    emission gathered at the tracking's collisions, attenuated by their null weights)."""
    e, sigma = np.array([0.2, 0.5, 1.0]), np.array([1.0, 0.5, 0.2])
    program = _graded("volume_emission", e, {"volume_absorption": sigma})
    vol = Volume(absorption=tuple(sigma), emission=tuple(e * 1.2))
    film, _ = render(_sphere_scene(vol, program, world=(0, 0, 0), lens=1000.0),
                     RenderSettings(samples=256, seed=1))
    got = film.mean().mean(axis=(0, 1))
    # the integral of u^2 exp(-s u) over [0, 2]
    expected = e * (2.0 - np.exp(-2.0 * sigma) * (4.0 * sigma ** 2 + 4.0 * sigma + 2.0)) \
        / sigma ** 3
    print("emission", got, "expected", expected)
    np.testing.assert_allclose(got, expected, rtol=0.03)


def test_heterogeneous_white_furnace():
    """Albedo 1 at every point, density varying as (y + 1)^2: the image is the world."""
    sigma = np.array([0.15, 0.4, 0.8])
    vol = Volume(scattering=tuple(sigma * 1.2), anisotropy=0.3)
    settings = RenderSettings(samples=64, seed=5, max_bounces=400, volume_bounces=400,
                              clamp_indirect=0.0)
    scene = _sphere_scene(vol, _graded("volume_scattering", sigma), lens=60.0)
    ctx = RenderContext(scene, settings)
    try:
        film, _ = render(scene, settings, context=ctx)
        integ = ctx.integrator
        assert integ.heterogeneous and integ.het_runs[0] > 0
        # the majorant bounds the program's largest value, 4 x sigma at y = 1
        assert integ.vol[0, V_HET] == 1.0
        assert 4.0 * sigma.max() <= integ.vol[0, V_MAJ] <= 1.5 * 4.0 * sigma.max() + 1e-9
    finally:
        ctx.close()
    mean = film.mean().mean(axis=(0, 1))
    print(f"furnace: image mean per channel {mean}")
    np.testing.assert_allclose(mean, 1.0, atol=0.015)


def test_homogeneous_volumes_run_no_heterogeneous_work():
    settings = RenderSettings(samples=4, seed=0)
    scene = _sphere_scene(Volume(scattering=(0.5, 0.5, 0.5)), None)
    ctx = RenderContext(scene, settings)
    try:
        render(scene, settings, context=ctx)
        assert not ctx.integrator.heterogeneous
        assert ctx.integrator.het_runs[0] == 0
        assert not ctx.integrator.vol[:, V_HET].any()
    finally:
        ctx.close()
