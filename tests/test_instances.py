"""Instances (engine.scene.Instances, engine.instancing): one mesh kept once in object
space and traced by Embree as K instances. The oracle is the same mesh expanded into K
world-space copies (`instancing.expand`), which the tracer renders as plain meshes: hits,
images, Object Info per place and both integrators must agree; memory must grow with
the places, not with places x triangles; extreme scales and far-away scenes render as
near the origin."""
from __future__ import annotations

import copy
import dataclasses

import numpy as np
import pytest

from engine import RenderContext, RenderSettings, render
from engine import instancing
from engine.accel import Accelerator
from engine.motion import RigidMotion
from engine.nodes import context as C
from engine.nodes import input_nodes as I
from engine.nodes import texture_nodes as X
from engine.nodes.program import ProgramBuilder
from engine.scene import Instances, Material, ObjectInfo, World
from engine.surface import SurfaceBuilder
from engine_scenes import cornell_box, instanced_boxes, scaled, translated, uv_sphere
from extreme_checks import sane, z_test


def _rotation(angle, axis):
    c, s = np.cos(angle), np.sin(angle)
    m = np.eye(4)
    i, j = [(1, 2), (0, 2), (0, 1)][axis]
    m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
    return m


def _balls(material=0):
    """A smooth unit sphere at five places: scaled unevenly, rotated, one high up, the
    last one mirrored."""
    ball = uv_sphere((0, 0, 0), 1.0, 12, 24, "ball", material)
    corners = ball.positions[ball.triangles]
    ball.corner_normals = (corners / np.linalg.norm(corners, axis=2, keepdims=True)
                           ).astype(np.float32)
    places = []
    for k, (x, y, z, s) in enumerate([(-0.6, -0.6, 0.2, 0.2), (0.5, -0.7, 0.15, 0.15),
                                      (0.0, -0.3, 1.5, 0.25), (0.6, 0.5, 0.9, 0.3),
                                      (-0.4, 0.3, 0.7, -0.25)]):
        m = np.eye(4)
        m[:3, :3] = np.diag([s, abs(s), 1.5 * abs(s)])
        m[:3, 3] = (x, y, z)
        places.append(m @ _rotation(0.4 * k, 2) @ _rotation(0.3, 0))
    ball.instances = Instances(np.array(places), colors=[(0.9, 0.1, 0.1), (0.1, 0.9, 0.1),
                                                         (0.1, 0.1, 0.9), (0.9, 0.9, 0.1),
                                                         (0.1, 0.9, 0.9)])
    return ball


def _scene(ball, extra=None, size=32):
    """The Cornell box's walls with `ball`; extra: a fourth material (index 3)."""
    scene = cornell_box(size, size)
    walls = [m for m in scene.meshes if m.name not in ("tall", "short")]
    materials = list(scene.materials) + ([extra] if extra is not None else [])
    return dataclasses.replace(scene, meshes=walls + [ball], materials=materials)


def _expanded(scene):
    out = copy.copy(scene)
    out.meshes = [c for m in scene.meshes for c in instancing.expand(m)]
    return out


def _agrees(z) -> bool:
    """The z-test's verdict of tests/test_extremes_scale.py: the same image up to noise."""
    return z.pass_rate > 0.95 and abs(z.mean_z) < 0.15


def _hits(scene, n=20000, seed=1):
    rng = np.random.default_rng(seed)
    o = np.tile([0.0, -3.9, 1.0], (n, 1))
    d = rng.normal(size=(n, 3)) * [0.3, 0.0, 0.3] + [0.0, 1.0, 0.0]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    accel = Accelerator(scene.meshes, threads=1)
    h = accel.intersect(o, d, np.full(n, np.inf))
    hit = np.nonzero(h.hit)[0]
    return accel, h, hit, SurfaceBuilder(accel).build(h, hit, d)


def test_hits_on_instances_are_the_hits_on_copies():
    scene = _scene(_balls())
    accel, h, hit, si = _hits(scene)
    accel2, h2, hit2, si2 = _hits(_expanded(scene))
    assert len(accel.prototypes) == 1 and accel.instance_count == 5
    assert accel.total_triangles == accel2.total_triangles - 4 * len(scene.meshes[-1].triangles)
    assert np.array_equal(hit, hit2)
    # every place is hit, and a hit names its place (its object-table row)
    assert set(np.unique(h.inst[hit])) == {-1, 0, 1, 2, 3, 4}
    on_ball = h.inst[hit] >= 0
    assert on_ball.sum() > 1000
    # the camera is outside every ball, the mirrored one too: front faces only, and
    # shading normals out of the ball's centre
    assert si.front_facing[on_ball].all()
    centre = scene.meshes[-1].instances.matrices[h.inst[hit][on_ball], :3, 3]
    out = ((si.shading_normal[on_ball]) * (si.position[on_ball] - centre)).sum(1)
    assert (out > 0).all()
    # the same surface points, to Embree's float32 barycentrics (1e-5 of the 2 m box)
    assert np.abs(si.position - si2.position).max() < 2e-5
    assert np.abs(si.geometric_normal - si2.geometric_normal).max() < 1e-9
    assert np.abs(si.shading_normal - si2.shading_normal).max() < 2e-4
    assert np.array_equal(si.front_facing, si2.front_facing)
    # the control: the object-space corner normals, not placed, are not the copies'
    local = si.prim[on_ball] - accel.prototypes[0].prim_offset
    raw = scene.meshes[-1].corner_normals[local].astype(np.float64).mean(axis=1)
    raw /= np.linalg.norm(raw, axis=1, keepdims=True)
    assert np.abs(raw - si2.shading_normal[on_ball]).max() > 0.1


@pytest.mark.parametrize("integrator", ["path", "whitted"])
def test_an_instanced_scene_renders_like_its_copies(integrator):
    scene = _scene(_balls())
    settings = RenderSettings(samples=64, seed=3, integrator=integrator)
    film, stats = render(scene, settings)
    assert not sane(film, stats)
    copies, _ = render(_expanded(scene), settings)
    # same samples: the images differ only where float32 rounding sent a path elsewhere
    assert abs(film.mean().mean() / copies.mean().mean() - 1.0) < 0.003
    z = z_test(film, render(_expanded(scene), dataclasses.replace(settings, seed=4))[0])
    assert _agrees(z), z


def test_transparent_instances_render_like_their_copies():
    """Alpha (transparent layers, engine.kernels.transparency) on an instanced mesh."""
    scene = _scene(_balls(material=3), Material("leaf", (0.2, 0.7, 0.2), alpha=0.4))
    settings = RenderSettings(samples=64, seed=3)
    film, stats = render(scene, settings)
    assert not sane(film, stats)
    copies, _ = render(_expanded(scene), dataclasses.replace(settings, seed=4))
    z = z_test(film, copies)
    assert _agrees(z), z
    opaque = copy.deepcopy(scene)
    opaque.materials[3] = dataclasses.replace(opaque.materials[3], alpha=1.0)
    z = z_test(render(opaque, settings)[0], copies)     # the control
    assert not _agrees(z), z


def _object_program():
    """Base colour = Object Info's colour x a checker of the object-space position."""
    b = ProgramBuilder()
    color = b.emit(I.IN_HIT3, "color", [C.H_OBJ_COLOR], varying=True)
    obj = b.emit(I.IN_HIT3, "vector", [C.H_OBJECT], varying=True)
    checker = b.emit(X.TEX_CHECKER_COLOR, "color", [obj, color, b.constant((0.05,) * 3),
                                                    b.constant(3.0)])
    b.output("base_color", checker)
    return b.build()


def test_object_info_and_coordinates_per_place():
    """Each place reads its own Object Info colour and its own object coordinates: the
    same samples render the copies' image (measured: mean |difference| 1e-4, where
    float32 rounding sent a path elsewhere), and the control, one colour for all places,
    is 190x further from it."""
    ball = _balls(material=3)
    ball.object_info = ObjectInfo(np.eye(4))
    scene = _scene(ball, Material("painted", (0.8,) * 3, shader=_object_program()), size=48)
    settings = RenderSettings(samples=64, seed=3)
    ctx = RenderContext(scene, settings)
    assert ctx.accel.instance_count == 5 and ctx.surfaces.objects.shape[0] == 5 + 6
    film, stats = render(scene, settings, context=ctx)
    assert not sane(film, stats)
    copies = render(_expanded(scene), settings)[0].mean()
    grey = copy.deepcopy(scene)
    grey.meshes[-1].instances.colors[:] = 0.5          # the control: one colour for all
    control = np.abs(render(grey, settings)[0].mean() - copies).mean()
    assert np.abs(film.mean() - copies).mean() < 0.05 * control


def test_shadow_terminator_offset_on_instances():
    """Coarse smooth spheres lit from the side: shadow rays start from the curved surface
    (engine.kernels.terminator) on instances as on copies (rotated places, where the
    lift in object space placed by the matrix is the lift of the copy); with the offset
    off the image is another (the control)."""
    ball = uv_sphere((0, 0, 0), 0.3, 6, 8, "coarse", 0)
    corners = ball.positions[ball.triangles]
    ball.corner_normals = (corners / np.linalg.norm(corners, axis=2, keepdims=True)
                           ).astype(np.float32)
    places = [np.eye(4) for _ in range(4)]
    for k, (x, y) in enumerate([(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.4), (0.5, 0.4)]):
        places[k] = _rotation(0.5 * k + 0.2, 2) @ _rotation(0.3 * k, 0)
        places[k][:3, 3] = (x, y, 0.6)
    ball.instances = Instances(np.array(places))
    scene = _scene(ball, size=48)
    sun_dir = np.array([1.0, 0.2, -0.15])
    from engine.scene import SunLight
    scene.lights = [SunLight(tuple(sun_dir / np.linalg.norm(sun_dir)), (4.0, 4.0, 4.0))]
    settings = RenderSettings(samples=16, seed=3, diffuse_bounces=0)
    ctx = RenderContext(scene, settings)
    assert ctx.accel.prototypes and (ctx.surfaces.terminator_cutoff > 0).any()
    film = render(scene, settings, context=ctx)[0].mean()
    copies = render(_expanded(scene), settings)[0].mean()
    off = copy.deepcopy(scene)
    off.meshes[-1].terminator_offset = 0.0
    control = np.abs(render(off, settings)[0].mean() - copies).mean()
    print(f"instances against copies {np.abs(film - copies).mean():.2e}, offset off "
          f"{control:.2e}")
    assert np.abs(film - copies).mean() < 0.05 * control


def test_memory_grows_with_places_not_triangles():
    """20,000 places of a 4,992-triangle sphere: as copies 1e8 triangles (4.8 GB of
    float64 positions alone); instanced, the accelerator and the object table take
    tens of megabytes, and the scene renders."""
    def rss_mb():
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmRSS"):
                    return int(line.split()[1]) / 1024.0
    ball = uv_sphere((0, 0, 0), 0.4, 40, 64)
    k = 20000
    grid = np.stack(np.meshgrid(np.arange(200.0), np.arange(k // 200)), -1).reshape(-1, 2)
    places = np.tile(np.eye(4), (k, 1, 1))
    places[:, :2, 3] = grid
    ball.instances = Instances(places)
    before = rss_mb()
    accel = Accelerator([ball], threads=1)
    surfaces = SurfaceBuilder(accel)
    grown = rss_mb() - before
    print(f"{k} places of {len(ball.triangles)} triangles: {grown:.0f} MB")
    assert accel.total_triangles == len(ball.triangles) and accel.instance_count == k
    assert surfaces.objects.shape[0] == k + 1        # the places, then the mesh's own row
    assert grown < 300.0
    scene = dataclasses.replace(cornell_box(16, 16), meshes=[ball], lights=[],
                                world=World((0.5, 0.5, 0.5)))
    scene.camera.matrix[:3, 3] = (100.0, -20.0, 30.0)
    film, stats = render(scene, RenderSettings(samples=1))
    assert not sane(film, stats) and film.mean().max() > 0.0


def test_meshes_that_emit_or_hold_a_volume_are_expanded():
    from engine.scene import Volume
    glowing = _balls(material=3)
    scene = _scene(glowing, Material("glow", (0.5,) * 3, emission=(2.0, 2.0, 2.0)))
    ctx = RenderContext(scene, RenderSettings(samples=1))
    assert not ctx.accel.prototypes and ctx.accel.total_triangles == (
        sum(len(m.triangles) for m in scene.meshes[:-1]) + 5 * len(glowing.triangles))
    assert len(ctx.lights.mesh) == 5 * len(glowing.triangles)   # the copies are lights
    foggy = _scene(_balls(material=3), Material("fog", surface=False,
                                                volume=Volume(scattering=(1.0, 1.0, 1.0))))
    assert not RenderContext(foggy, RenderSettings(samples=1)).accel.prototypes
    plain = _scene(_balls())
    assert len(RenderContext(plain, RenderSettings(samples=1)).accel.prototypes) == 1


def test_bad_instances_are_refused():
    with pytest.raises(ValueError, match="not finite"):
        Instances(np.full((2, 4, 4), np.nan))
    with pytest.raises(ValueError, match=r"\(K, 4, 4\)"):
        Instances(np.eye(4))
    ball = _balls()
    with pytest.raises(ValueError, match="cannot move"):
        dataclasses.replace(ball, motion=RigidMotion(np.array([0.0, 1.0]),
                                                     np.stack([np.eye(4)] * 2)))


SIZE, SAMPLES = 24, 64


@pytest.fixture(scope="module")
def boxes_reference():
    film, stats = render(cornell_box(SIZE, SIZE, light_size=1.0),
                         RenderSettings(samples=SAMPLES, seed=1, sampler="random"))
    assert not sane(film, stats)
    return film


def _boxes_check(scene, reference, what):
    film, stats = render(scene, RenderSettings(samples=SAMPLES, seed=2, sampler="random"))
    assert not sane(film, stats), what
    z = z_test(film, reference)
    print(f"{what}: {z}")
    assert _agrees(z), f"{what}: {z}"


def test_instanced_boxes_render_the_cornell_box(boxes_reference):
    """The two boxes as places of one cube give the box's image (the z-test of
    tests/test_extremes_scale.py)."""
    _boxes_check(instanced_boxes(SIZE, SIZE), boxes_reference, "instanced boxes")


@pytest.mark.parametrize("s", [1e-3, 1e4])
def test_instances_at_extreme_scales(boxes_reference, s):
    _boxes_check(scaled(instanced_boxes(SIZE, SIZE), s), boxes_reference, f"scale {s:g}")


@pytest.mark.parametrize("d", [1e5, 1e6])
def test_instances_far_from_the_origin(boxes_reference, d):
    _boxes_check(translated(instanced_boxes(SIZE, SIZE), (d, -d, d)), boxes_reference,
                 f"moved by {d:g}")
