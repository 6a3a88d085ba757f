"""The procedural texture nodes (White Noise, Noise, Voronoi, Wave, Magic, Brick) as DRT
compiles and evaluates them, against Blender's own evaluation of the same node at the
same points (tests/blender_fields.py: geometry nodes run the functions Cycles' kernels
use, in float32), over every dimension, type, feature, metric, direction and profile.

Each case: a shader node tree with the texture node reading Object coordinates, compiled
by the exporter's NodeCompiler, run by the engine's interpreter at 200 random points
(the hit positions of the identity object), compared with Blender's values. Tolerances
are float32 rounding (1e-3 of the value's scale); the hashes must agree exactly. A
control shows the comparison fails for a different setting.
"""
from __future__ import annotations

import numpy as np
import pytest

from blender_fields import evaluate

N_POINTS = 200
RNG = np.random.default_rng(7)
POINTS = RNG.uniform(-3.0, 3.0, (N_POINTS, 3)).astype(np.float32).astype(np.float64)


class _Ctx:
    """What the node compiler needs of a material export: an issue list."""

    def __init__(self):
        self.issues = []
        self.cache = {}
        self.name = "probe"

    def issue(self, text):
        self.issues.append(text)


def drt_values(bpy, node_type, output, settings, inputs):
    """DRT's value of `output` of a `node_type` node at POINTS (Vector: Object; W: its
    x)."""
    from drt_addon.export.nodes import NodeCompiler
    from engine.nodes.context import hit_rows

    mat = bpy.data.materials.new("probe")
    mat.use_nodes = True
    nt = mat.node_tree
    try:
        node = nt.nodes.new(node_type)
        for k, v in settings.items():
            setattr(node, k, v)
        coords = nt.nodes.new("ShaderNodeTexCoord").outputs["Object"]
        if node.inputs.get("Vector") is not None:
            nt.links.new(coords, node.inputs["Vector"])
        if node.inputs.get("W") is not None:              # W: the point's x
            sep = nt.nodes.new("ShaderNodeSeparateXYZ")
            nt.links.new(coords, sep.inputs[0])
            nt.links.new(sep.outputs[0], node.inputs["W"])
        for name, value in inputs.items():
            if node.inputs.get(name) is not None:
                node.inputs[name].default_value = value
        c = NodeCompiler(_Ctx())
        out = next(s for s in node.outputs if output in (s.name, s.identifier))
        value = c.output(node, out)
        hits = hit_rows(POINTS, np.tile([0.0, 0.0, 1.0], (N_POINTS, 1)))
        return c.build().evaluate(value, hits)
    finally:
        bpy.data.materials.remove(mat)


def compare(bpy, node_type, output, settings, inputs):
    """(largest difference over the value's scale, the values' spread)."""
    ref = evaluate(bpy, node_type, POINTS, output, settings, dict(inputs, W=POINTS[:, 0]))
    mine = drt_values(bpy, node_type, output, settings, inputs)
    scale = max(1.0, float(np.abs(ref).max()))
    return float(np.abs(mine - ref).max()) / scale, float(ref.std())


def check(bpy, node_type, output, settings, inputs, tol=1e-3):
    err, spread = compare(bpy, node_type, output, settings, inputs)
    assert spread > 0.01, "the case does not vary: it would show nothing"
    assert err < tol, f"{node_type} {settings} {output}: largest error {err:.2e}"


DIMS = ("1D", "2D", "3D", "4D")


@pytest.mark.parametrize("dims", DIMS)
@pytest.mark.parametrize("output", ("Value", "Color"))
def test_white_noise_hashes_like_blender(bpy_drt, dims, output):
    check(bpy_drt, "ShaderNodeTexWhiteNoise", output, {"noise_dimensions": dims},
          {}, tol=1e-7)


NOISE_TYPES = ("FBM", "MULTIFRACTAL", "RIDGED_MULTIFRACTAL", "HYBRID_MULTIFRACTAL",
               "HETERO_TERRAIN")


@pytest.mark.parametrize("dims", DIMS)
@pytest.mark.parametrize("kind", NOISE_TYPES)
def test_noise(bpy_drt, kind, dims):
    inputs = {"Scale": 1.7, "Detail": 3.5, "Roughness": 0.6, "Lacunarity": 2.2,
              "Offset": 0.7, "Gain": 1.3, "Distortion": 0.8}
    for output in ("Fac", "Color"):
        check(bpy_drt, "ShaderNodeTexNoise", output,
              {"noise_dimensions": dims, "noise_type": kind}, inputs)


def test_noise_unnormalized(bpy_drt):
    check(bpy_drt, "ShaderNodeTexNoise", "Fac", {"normalize": False},
          {"Scale": 2.0, "Detail": 2.0})


FEATURES = ("F1", "F2", "SMOOTH_F1", "DISTANCE_TO_EDGE", "N_SPHERE_RADIUS")
METRICS = ("EUCLIDEAN", "MANHATTAN", "CHEBYCHEV", "MINKOWSKI")
VORONOI_OUTPUTS = {"F1": ("Distance", "Color", "Position", "W"),
                   "F2": ("Distance", "Color", "Position", "W"),
                   "SMOOTH_F1": ("Distance", "Color", "Position", "W"),
                   "DISTANCE_TO_EDGE": ("Distance",), "N_SPHERE_RADIUS": ("Radius",)}


@pytest.mark.parametrize("dims", DIMS)
@pytest.mark.parametrize("feature", FEATURES)
def test_voronoi(bpy_drt, feature, dims):
    metrics = METRICS if feature in ("F1", "F2", "SMOOTH_F1") and dims != "1D" else \
        ("EUCLIDEAN",)
    for metric in metrics:
        for normalize, detail in ((False, 0.0), (True, 2.5)):
            settings = {"voronoi_dimensions": dims, "feature": feature, "distance": metric,
                        "normalize": normalize}
            inputs = {"Scale": 1.3, "Detail": detail, "Roughness": 0.6,
                      "Lacunarity": 2.1, "Smoothness": 0.7, "Exponent": 1.5,
                      "Randomness": 0.9}
            for output in VORONOI_OUTPUTS[feature]:
                if output == "W" and dims not in ("1D", "4D") or \
                        output == "Position" and dims == "1D":
                    continue
                check(bpy_drt, "ShaderNodeTexVoronoi", output, settings, inputs)


@pytest.mark.parametrize("kind,direction", [("BANDS", d) for d in ("X", "Y", "Z", "DIAGONAL")]
                         + [("RINGS", d) for d in ("X", "Y", "Z", "SPHERICAL")])
def test_wave(bpy_drt, kind, direction):
    inputs = {"Scale": 0.8, "Distortion": 2.0, "Detail": 2.5, "Detail Scale": 1.5,
              "Detail Roughness": 0.6, "Phase Offset": 0.7}
    for profile in ("SIN", "SAW", "TRI"):
        settings = {"wave_type": kind, "wave_profile": profile,
                    ("bands_direction" if kind == "BANDS" else "rings_direction"): direction}
        check(bpy_drt, "ShaderNodeTexWave", "Fac", settings, inputs)


@pytest.mark.parametrize("depth", range(0, 8))
def test_magic(bpy_drt, depth):
    for output in ("Color", "Fac"):
        check(bpy_drt, "ShaderNodeTexMagic", output, {"turbulence_depth": depth},
              {"Scale": 0.7, "Distortion": 1.2})


@pytest.mark.parametrize("settings", [
    {}, {"offset": 0.3, "offset_frequency": 3, "squash": 0.6, "squash_frequency": 2},
    {"offset": 0.8, "offset_frequency": 1, "squash": 1.5, "squash_frequency": 3}])
def test_brick(bpy_drt, settings):
    inputs = {"Scale": 2.0, "Mortar Size": 0.05, "Mortar Smooth": 0.4, "Bias": 0.2,
              "Brick Width": 0.6, "Row Height": 0.3, "Color1": (0.8, 0.3, 0.1, 1.0),
              "Color2": (0.2, 0.5, 0.7, 1.0), "Mortar": (0.05, 0.1, 0.05, 1.0)}
    for output in ("Color", "Fac"):
        check(bpy_drt, "ShaderNodeTexBrick", output, settings, inputs)


def test_comparison_fails_for_another_setting(bpy_drt):
    """The control: DRT's FBM against Blender's Ridged, DRT's Voronoi F1 against
    Blender's F2, a different White Noise dimension: each comparison fails."""
    pairs = [("ShaderNodeTexNoise", "Fac", "noise_type", "FBM", "RIDGED_MULTIFRACTAL"),
             ("ShaderNodeTexVoronoi", "Distance", "feature", "F1", "F2"),
             ("ShaderNodeTexWhiteNoise", "Value", "noise_dimensions", "3D", "2D")]
    for node_type, output, prop, mine, theirs in pairs:
        ref = evaluate(bpy_drt, node_type, POINTS, output, {prop: theirs}, {"W": POINTS[:, 0]})
        got = drt_values(bpy_drt, node_type, output, {prop: mine}, {})
        assert np.abs(got - ref).max() > 0.1, (node_type, prop)


def test_texture_mapping_is_reported(bpy_drt):
    """The node's legacy texture mapping (sidebar > Mapping) is not evaluated: named in
    a warning."""
    ctx = _Ctx()
    mat = bpy_drt.data.materials.new("mapped")
    mat.use_nodes = True
    try:
        node = mat.node_tree.nodes.new("ShaderNodeTexNoise")
        node.texture_mapping.translation = (0.5, 0.0, 0.0)
        from drt_addon.export.nodes import NodeCompiler
        c = NodeCompiler(ctx)
        c.output(node, node.outputs["Fac"])
    finally:
        bpy_drt.data.materials.remove(mat)
    assert any("texture mapping" in i for i in ctx.issues), ctx.issues
