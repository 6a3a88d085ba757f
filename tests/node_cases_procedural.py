"""The procedural textures' node graphs tests/test_nodes_vs_cycles.py compares with
Cycles (White Noise, Noise, Voronoi, Wave, Magic, Brick), one family per kind, on tiles
of TILE pixels so that a pattern's features span several pixels.

Patterns read Generated coordinates (the tile's [0, 1] square) unless a case says
otherwise. White Noise hashes the bits of its input, so its input is quantised (Snap)
to cells of a few pixels: both engines then hash the same float32 values, and only the
pixels across cell edges mix neighbouring cells (antialiasing, the same in both).
"""
from __future__ import annotations

from node_cases import axis, gen, ident, shown

TILE = 32


def _set(node, **inputs):
    for name, value in inputs.items():
        ident(node.inputs, name).default_value = value


def _snapped(nt, p, step=0.25):
    """Generated coordinates snapped to a grid of `step` (z to 0)."""
    snap = p.node(nt, "ShaderNodeVectorMath", operation="SNAP")
    nt.links.new(gen(nt, p), snap.inputs[0])
    snap.inputs[1].default_value = (step, step, 1.0)
    return snap.outputs[0]


def _linked_w(nt, p, node, scale=1.0):
    """The node's W from the tile's generated x (times scale)."""
    m = p.node(nt, "ShaderNodeMath", operation="MULTIPLY")
    nt.links.new(axis(nt, p, gen(nt, p), 0), m.inputs[0])
    m.inputs[1].default_value = scale
    nt.links.new(m.outputs[0], node.inputs["W"])


# ---------------------------------------------------------------- white noise
def _white_noise(dims, output):
    def build(nt, p):
        n = p.node(nt, "ShaderNodeTexWhiteNoise", noise_dimensions=dims)
        if dims == "1D":
            w = p.node(nt, "ShaderNodeMath", operation="SNAP")
            nt.links.new(axis(nt, p, gen(nt, p), 0), w.inputs[0])
            w.inputs[1].default_value = 0.125
            nt.links.new(w.outputs[0], n.inputs["W"])
        else:
            nt.links.new(_snapped(nt, p), n.inputs["Vector"])
            _set(n, W=0.37)
        return n.outputs[output]
    return build


# ---------------------------------------------------------------- noise
def _noise(kind="FBM", dims="3D", output="Fac", normalize=True, show=None, **inputs):
    def build(nt, p):
        n = p.node(nt, "ShaderNodeTexNoise", noise_type=kind, noise_dimensions=dims,
                   normalize=normalize)
        _set(n, **dict(dict(Scale=3.0, Detail=2.0), **inputs))
        if dims == "1D":
            _linked_w(nt, p, n)
        if show is not None:
            return shown(nt, p, n.outputs[output], *show)
        return n.outputs[output]
    return build


NOISE = [
    ("noise_fbm", _noise()), ("noise_fbm_color", _noise(output="Color")),
    ("noise_fbm_rough", _noise(Detail=3.5, Roughness=0.7, Lacunarity=2.5)),
    ("noise_fbm_unnormalized", _noise(normalize=False, show=(0.4, 0.5))),
    ("noise_distortion", _noise(Distortion=1.5, output="Color")),
    ("noise_1d", _noise(dims="1D", Scale=4.0)), ("noise_2d", _noise(dims="2D")),
    ("noise_4d", _noise(dims="4D", W=0.6, output="Color")),
    ("noise_multifractal", _noise("MULTIFRACTAL", show=(0.4, 0.1))),
    ("noise_ridged", _noise("RIDGED_MULTIFRACTAL", show=(0.5, 0.0), Offset=1.0, Gain=2.0)),
    ("noise_hybrid", _noise("HYBRID_MULTIFRACTAL", show=(0.3, 0.2), Offset=0.5, Gain=1.5)),
    ("noise_hetero", _noise("HETERO_TERRAIN", show=(0.3, 0.3), Offset=0.5)),
]


# ---------------------------------------------------------------- voronoi
def _voronoi(feature="F1", output="Distance", dims="3D", metric="EUCLIDEAN",
             normalize=False, show=None, **inputs):
    def build(nt, p):
        v = p.node(nt, "ShaderNodeTexVoronoi", feature=feature, voronoi_dimensions=dims,
                   distance=metric, normalize=normalize)
        _set(v, **dict(dict(Scale=4.0), **inputs))
        if dims == "1D":
            _linked_w(nt, p, v)
        out = v.outputs[output]
        if output == "Position":
            show_pos = p.node(nt, "ShaderNodeVectorMath", operation="FRACTION")
            nt.links.new(out, show_pos.inputs[0])
            return show_pos.outputs[0]
        return shown(nt, p, out, *show) if show else out
    return build


VORONOI = [
    ("voronoi_f1", _voronoi()), ("voronoi_f1_color", _voronoi(output="Color")),
    ("voronoi_f1_position", _voronoi(output="Position")),
    ("voronoi_f2", _voronoi("F2", show=(0.7, 0.0))),
    ("voronoi_f2_color", _voronoi("F2", output="Color")),
    ("voronoi_smooth_f1", _voronoi("SMOOTH_F1")),
    ("voronoi_smooth_f1_color", _voronoi("SMOOTH_F1", output="Color", Smoothness=0.6)),
    ("voronoi_edge", _voronoi("DISTANCE_TO_EDGE", show=(2.0, 0.0))),
    ("voronoi_radius", _voronoi("N_SPHERE_RADIUS", output="Radius", show=(1.5, 0.0))),
    ("voronoi_manhattan", _voronoi(metric="MANHATTAN", show=(0.7, 0.0))),
    ("voronoi_chebychev", _voronoi(metric="CHEBYCHEV")),
    ("voronoi_minkowski", _voronoi(metric="MINKOWSKI", Exponent=1.5)),
    ("voronoi_2d_color", _voronoi(dims="2D", output="Color", Randomness=0.6)),
    ("voronoi_1d", _voronoi(dims="1D", Scale=5.0)),
    ("voronoi_4d_color", _voronoi(dims="4D", output="Color", W=0.3)),
    ("voronoi_fractal", _voronoi(Detail=2.0, Roughness=0.6, normalize=True)),
    ("voronoi_fractal_edge", _voronoi("DISTANCE_TO_EDGE", Detail=1.5, normalize=True)),
]


# ---------------------------------------------------------------- wave, magic, brick
def _wave(kind="BANDS", direction="X", profile="SIN", **inputs):
    def build(nt, p):
        w = p.node(nt, "ShaderNodeTexWave", wave_type=kind, bands_direction=direction
                   if kind == "BANDS" else "X", rings_direction=direction
                   if kind == "RINGS" else "X", wave_profile=profile)
        _set(w, **dict(dict(Scale=0.6), **inputs))
        return w.outputs["Fac"]
    return build


def _magic(depth, **inputs):
    def build(nt, p):
        m = p.node(nt, "ShaderNodeTexMagic", turbulence_depth=depth)
        _set(m, **dict(dict(Scale=1.0), **inputs))
        return m.outputs["Color"]
    return build


def _brick(output="Color", **settings):
    def build(nt, p):
        b = p.node(nt, "ShaderNodeTexBrick", **settings)
        _set(b, Scale=1.0, **{"Mortar Size": 0.04, "Mortar Smooth": 0.3, "Bias": 0.1,
                              "Color1": (0.8, 0.3, 0.1, 1.0), "Color2": (0.2, 0.5, 0.7, 1.0),
                              "Mortar": (0.05, 0.05, 0.05, 1.0)})
        return b.outputs[output]
    return build


PATTERNS = [
    ("white_noise_2d", _white_noise("2D", "Value")),
    ("white_noise_3d", _white_noise("3D", "Value")),
    ("white_noise_3d_color", _white_noise("3D", "Color")),
    ("white_noise_4d_color", _white_noise("4D", "Color")),
    ("white_noise_1d", _white_noise("1D", "Color")),
    ("wave_bands", _wave()), ("wave_bands_diagonal_saw", _wave(direction="DIAGONAL",
                                                               profile="SAW")),
    ("wave_rings_tri", _wave("RINGS", "SPHERICAL", "TRI", **{"Phase Offset": 1.0})),
    ("wave_rings_z_distorted", _wave("RINGS", "Z", Distortion=4.0, Detail=3.0,
                                     **{"Detail Scale": 2.0})),
    ("magic_2", _magic(2)), ("magic_4", _magic(4, Distortion=1.5)),
    ("magic_fac", lambda nt, p: _magic(3, Scale=1.5)(nt, p).node.outputs["Fac"]),
    ("brick", _brick()), ("brick_fac", _brick("Fac")),
    ("brick_squash", _brick(offset=0.3, offset_frequency=3, squash=0.6, squash_frequency=2)),
]

FAMILIES = {"procedural_noise": (NOISE, "plane"), "procedural_voronoi": (VORONOI, "plane"),
            "procedural_patterns": (PATTERNS, "plane")}
TILES = {name: TILE for name in FAMILIES}
