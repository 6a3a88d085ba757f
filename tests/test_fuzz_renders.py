"""Property-based fuzzing in CI (tests/fuzz_renders.py): a few derandomised hypothesis
examples over the ranges Blender's RNA gives for the material, lamp, camera and world,
each exported and rendered at 8 x 8 pixels, 2 samples: no crash, no NaN or infinite
sample, no negative pixel. The findings of longer runs are the named regression tests
below (each failed before its fix)."""
import math

import pytest
from hypothesis import HealthCheck, given, settings

import fuzz_renders as fuzz

EXAMPLES = 20


@pytest.fixture(scope="module")
def fuzz_scene(bpy_drt):
    scene = fuzz.build_scene(bpy_drt)
    return bpy_drt, scene, fuzz.blender_ranges(bpy_drt)


@pytest.fixture
def fresh(fuzz_scene):
    """The fuzz scene rebuilt at its defaults (a named case changes only what it names)."""
    bpy, _, params = fuzz_scene
    return bpy, fuzz.build_scene(bpy), params


def test_ranges_are_blenders(fuzz_scene):
    """The fuzzed ranges are the RNA's: spot-check a few against Blender's documented
    limits, and check every range is non-empty."""
    bpy, _, params = fuzz_scene
    by_name = {(p.owner, p.name, p.only_for): p for p in params}
    assert (by_name[("material", "Roughness", "")].lo, by_name[("material", "Roughness", "")].hi) \
        == (0.0, 1.0)
    assert by_name[("camera", "lens", "")].lo == 1.0
    assert math.isclose(by_name[("light", "spot_size", "SPOT")].lo, math.radians(1.0),
                        rel_tol=1e-6)
    assert by_name[("dof", "aperture_blades", "")].hi == 16
    assert all(p.lo <= p.hi for p in params if p.kind in ("float", "color", "int"))
    assert len([p for p in params if p.owner == "material"]) >= 20


def _case(fuzz_scene, **changes):
    """The default scene's lamp and camera as a case, with some parameters changed
    ({'camera.clip_end': 0.5}); material and world inputs keep their defaults unless a
    test sets them."""
    bpy, scene, params = fuzz_scene
    case = {}
    for p in params:
        key = (p.owner, p.name, p.only_for)
        if p.owner in ("material", "world"):
            continue
        target = {"light": scene.objects["Lamp"].data, "camera": scene.camera.data,
                  "dof": scene.camera.data.dof}[p.owner]
        if p.name == "type" and p.owner == "light":
            case[key] = target.type
        elif hasattr(target, p.name):
            case[key] = tuple(getattr(target, p.name)) if p.kind == "color" \
                else getattr(target, p.name)
    for name, value in changes.items():
        owner, prop = name.split(".")
        keys = [k for k in case if k[0] == owner and k[1] == prop] or [(owner, prop, "")]
        for k in keys:
            case[k] = value
    return case


def _render_again(bpy):
    """The current scene exported and rendered again (1 sample): its film."""
    from drt_addon.engine_link import engine
    from drt_addon.export import Reporter, export_scene
    film, _ = engine.render(export_scene(bpy.context.evaluated_depsgraph_get(), Reporter(),
                                         size=(fuzz.SIZE, fuzz.SIZE)),
                            engine.RenderSettings(samples=1))
    return film


@pytest.mark.parametrize("changes", [
    {"camera.clip_start": 10.0, "camera.clip_end": 1.0},
    {"camera.clip_start": 5.0, "camera.clip_end": 5.0},
    {"camera.type": "ORTHO", "camera.ortho_scale": 0.0},
], ids=["clip end before clip start", "clip end at clip start", "ortho scale 0"])
def test_camera_that_sees_nothing_renders_the_world(fresh, changes):
    """Found by the fuzzer: a clip end not beyond the clip start, or an orthographic
    scale of 0, stopped the render with a ValueError. Cycles renders the world alone
    (measured with the default scene); DRT now does too."""
    bpy, scene, _ = fresh
    case = _case(fresh, **changes)
    case[("world", "Color", "")] = (0.2, 0.3, 0.4)
    case[("world", "Strength", "")] = 1.0
    assert fuzz.render_case(bpy, scene, case) == []
    film = _render_again(bpy)
    assert abs(film.mean()[..., 0] - 0.2).max() < 1e-6
    assert abs(film.mean()[..., 2] - 0.4).max() < 1e-6


def test_overflowing_throughput_gives_no_nan(fresh):
    """Found by the fuzzer (reduced from its case): a base colour of 3.8e20 under a coat
    tinted 1.2e38 (both inside Blender's ranges) overflowed float64 over the bounces
    (the coat tints by its colour to the power of the path length in it), and inf x 0
    made NaN samples. Now a path whose throughput overflows ends, and an infinite
    contribution clamps to the clamp value."""
    bpy, scene, _ = fresh
    case = _case(fresh)
    case[("material", "Base Color", "")] = (3.785e20, 0.0, 6.483e16)
    case[("material", "Coat Tint", "")] = (1.187e38, 0.0, 6.025e16)
    case[("material", "Coat Weight", "")] = 0.5
    case[("material", "Alpha", "")] = 0.5
    for seed in range(3):
        assert fuzz.render_case(bpy, scene, case, seed=seed) == []


@settings(max_examples=EXAMPLES, derandomize=True, database=None, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(data=fuzz.st.data())
def test_fuzzed_render_is_finite_and_non_negative(fuzz_scene, data):
    bpy, _, params = fuzz_scene
    scene = bpy.context.scene              # the latest build_scene's (fixtures rebuild it)
    case = data.draw(fuzz.case_strategy(params))
    problems = fuzz.render_case(bpy, scene, case)
    assert problems == [], f"{problems}: {fuzz.describe(case)}"


@pytest.mark.parametrize("scale", [(0.0, 0.0, 0.0), (1.0, 1.0, 0.0), (1e-30, 1e-30, 1e-30)])
def test_object_scaled_to_zero_in_blender(fresh, scale):
    """A smooth-shaded sphere scaled to a point or flattened to a disc: its split normals
    go through the (singular) object transform at export; the render stays finite, and
    the floor still renders (the image is not black)."""
    bpy, scene, _ = fresh
    sphere = next(o for o in scene.objects if o.type == "MESH" and len(o.data.polygons) > 1)
    for poly in sphere.data.polygons:
        poly.use_smooth = True
    sphere.scale = scale
    case = _case(fresh)
    case[("light", "energy", "")] = 1000.0
    assert fuzz.render_case(bpy, scene, case) == []
    assert _render_again(bpy).mean().max() > 0
