"""Volume shaders (a Material Output's or World Output's Volume socket) to an
`engine.Volume`, with Cycles' meaning of each node (intern/cycles/kernel/svm/closure.h,
read for meaning only):

Principled Volume
    scattering = Color x Density, Henyey-Greenstein with Anisotropy; absorption =
    max(1 - Color, 0) x max(1 - sqrt(Absorption Color), 0) x Density (the light the
    colour does not scatter, tinted); emission = Emission Color x Emission Strength
    plus the blackbody emission of the Temperature (`_blackbody`). On a Volume object,
    the grids its Density, Color and Temperature Attributes name scale those inputs;
    all its coefficients scale by its Object-space density (export.volume_objects).
Volume Scatter
    scattering = Color x Density (Henyey-Greenstein; other phase functions reported and
    rendered as Henyey-Greenstein).
Volume Absorption
    absorption = (1 - Color) x Density.
Volume Coefficients
    its absorption, scattering and emission coefficients as they are.
Emission
    emission = Color x Strength (radiance per metre).
Add Shader, Mix Shader
    the coefficients add, or mix by the factor (the anisotropy is the
    scattering-weighted mean).

Inputs that vary in space (a texture on Density, Color, the emission or a Mix Shader's
Fac: a heterogeneous volume) are compiled into the material's shader program, whose
outputs volume_absorption, volume_scattering and volume_emission the engine evaluates
at points inside the medium (engine.kernels.medium_density); the Volume's own
coefficients are then their averages (a summary). Anisotropy is taken as its average
where it varies (reported). The world's volume has no program: a world volume that
varies is replaced by its average (reported).
"""
from __future__ import annotations

import importlib
import math

import numpy as np

from ..engine_link import engine
from .blackbody import blackbody_rgb
from .material_params import _is_tex
from .nodes.converter import blackbody_of
from .nodes.input import grid_value
from .volume_objects import attribute_name
from .nodes.links import _link
from .nodes.shader import _constant, _input
from .world import _WorldCtx, world_output

program = importlib.import_module(engine.__name__ + ".nodes.program")
cv = importlib.import_module(engine.__name__ + ".nodes.converter_nodes")
ve = importlib.import_module(engine.__name__ + ".nodes.vector_nodes")
VOLUME_OUTPUTS = importlib.import_module(engine.__name__ + ".kernels.volume").VOLUME_OUTPUTS

_ZERO = np.zeros(3)


def _varies(x) -> bool:
    return isinstance(x, program.Value)


class _Algebra:
    """Arithmetic on coefficients that are constants (floats, RGB arrays) or values of
    the material's program (engine.nodes.program.Value): constants are computed now,
    anything involving a Value becomes program instructions (vector results)."""

    def __init__(self, nodes):
        self.nodes = nodes

    def vector(self, x):
        if _varies(x):
            return self.nodes.convert(x, "vector")
        c = np.broadcast_to(np.asarray(x, np.float64), (3,))
        return self.nodes.const(tuple(float(v) for v in c), "vector")

    def _op(self, name, a, b):
        va, vb = self.vector(a), self.vector(b)
        return self.nodes.emit(ve.VEC_MATH, "vector", [va, vb, va, self.nodes.const(1.0),
                                                       ve.VECTOR_OPS.index(name)])

    def mul(self, a, b):
        if _varies(a) or _varies(b):
            return self._op("MULTIPLY", a, b)
        return np.asarray(a, np.float64) * np.asarray(b, np.float64)

    def add(self, a, b):
        if _varies(a) or _varies(b):
            return self._op("ADD", a, b)
        return np.asarray(a, np.float64) + np.asarray(b, np.float64)

    def one_minus(self, a):
        if _varies(a):
            return self._op("SUBTRACT", 1.0, a)
        return 1.0 - np.asarray(a, np.float64)

    def max0(self, a):
        if _varies(a):
            return self._op("MAXIMUM", a, 0.0)
        return np.maximum(np.asarray(a, np.float64), 0.0)

    def sqrt0(self, a):
        if _varies(a):
            return self._op("POWER", self.max0(a), 0.5)
        return np.sqrt(np.maximum(np.asarray(a, np.float64), 0.0))

    def clamp01(self, f):
        if _varies(f):
            return self.nodes.emit(cv.CV_CLAMP, "float", [self.nodes.convert(f, "float"),
                                                          self.nodes.const(0.0),
                                                          self.nodes.const(1.0), 0])
        return min(max(float(f), 0.0), 1.0)

    def mean(self, x):
        """A constant's value, or a Value's average (as engine.nodes.program.mean_value)."""
        if _varies(x):
            return np.asarray(self.nodes.mean(self.vector(x)), np.float64)
        return np.broadcast_to(np.asarray(x, np.float64), (3,)).copy()


def _read(node, name, ctx, default, color=False):
    """Input `name` of `node`: its own value, a folded constant, or (linked to a graph
    that varies) its program Value; the world, which runs no program, takes the average
    (reported)."""
    x = _input(node, name, ctx, color, default,
               texturable=getattr(ctx, "volume_programs", False))
    return x.value if _is_tex(x) else x


class _Coeffs:
    def __init__(self, sa=_ZERO, ss=_ZERO, gs=0.0, em=_ZERO):
        self.sa, self.ss, self.gs, self.em = sa, ss, float(gs), em

    def scaled(self, f, alg):
        return _Coeffs(alg.mul(self.sa, f), alg.mul(self.ss, f), self.gs * float(alg.mean(f)[0]),
                       alg.mul(self.em, f))

    def plus(self, o, alg):
        return _Coeffs(alg.add(self.sa, o.sa), alg.add(self.ss, o.ss), self.gs + o.gs,
                       alg.add(self.em, o.em))

    def varies(self) -> bool:
        return any(_varies(x) for x in (self.sa, self.ss, self.em))


def _scatter(alg, color, density, g):
    ss = alg.mul(alg.max0(color), density)
    return ss, float(alg.mean(ss).mean()) * g


# Cycles' blackbody emission of the Principled Volume: Stefan-Boltzmann's constant, per
# square micrometre (1e-6), over pi (radiance)
BLACKBODY_SIGMA = 5.670373e-8 * 1e-6 / math.pi


def _grid(ctx, node, socket):
    """The Volume object's grid that the node's attribute input names, or None."""
    grids = getattr(ctx, "volume_grids", None) or {}
    return grids.get(attribute_name(node, socket))


def _blackbody(node, ctx, alg):
    """The Principled Volume's blackbody emission, as Cycles: Tint x sigma x
    mix(1, T^4, Intensity) x the blackbody colour of T (luminance 1), where T is the
    Temperature times the temperature grid (when the object has it). Cycles 5 reads the
    grid by stochastic interpolation (one voxel's value per lookup), so the emission is
    the trilinear blend of the voxels' emissions, brighter than the emission of the
    blended temperature where it varies steeply; DRT reads it the same way. (The
    Density and Color grids, on which the coefficients depend linearly, are read
    trilinearly: the same expectation, with less noise.)"""
    intensity = _constant(node, "Blackbody Intensity", ctx, 0.0)
    if intensity <= 0.0:
        return _ZERO
    kelvin = alg.max0(_read(node, "Temperature", ctx, 1000.0))
    grid = _grid(ctx, node, "Temperature Attribute")
    if grid is not None:              # read as Cycles 5 reads it: one voxel's value
        kelvin = alg.mul(kelvin, alg.max0(grid_value(ctx.nodes, grid, "float", True)))
    if _varies(kelvin):
        kelvin = ctx.nodes.convert(alg.vector(kelvin), "float")
        color = blackbody_of(ctx.nodes, kelvin)
        t2 = alg.mul(kelvin, kelvin)
        power = alg.add(1.0 - intensity, alg.mul(alg.mul(t2, t2), intensity))
    else:
        k = float(np.asarray(kelvin).ravel()[0])
        color = np.asarray(blackbody_rgb(k))
        power = (1.0 - intensity) + intensity * k ** 4
    tint = alg.max0(_read(node, "Blackbody Tint", ctx, (1.0,) * 3, True))
    return alg.mul(alg.mul(tint, color), alg.mul(power, BLACKBODY_SIGMA))


def _principled(node, ctx, alg):
    density = alg.max0(_read(node, "Density", ctx, 1.0))
    grid = _grid(ctx, node, "Density Attribute")
    if grid is not None:              # a Volume object's density grid scales the Density
        density = alg.max0(alg.mul(density, grid_value(ctx.nodes, grid, "float")))
    color = alg.max0(_read(node, "Color", ctx, (0.5,) * 3, True))
    grid = _grid(ctx, node, "Color Attribute")
    if grid is not None:
        color = alg.mul(color, grid_value(ctx.nodes, grid, "color"))
    ss, gs = _scatter(alg, color, density, _constant(node, "Anisotropy", ctx, 0.0))
    absorb = _read(node, "Absorption Color", ctx, (0.0,) * 3, True)
    sa = alg.mul(alg.mul(alg.max0(alg.one_minus(color)),
                         alg.max0(alg.one_minus(alg.sqrt0(absorb)))), density)
    em = alg.max0(alg.mul(_read(node, "Emission Color", ctx, (1.0,) * 3, True),
                          _read(node, "Emission Strength", ctx, 0.0)))
    em = alg.add(em, _blackbody(node, ctx, alg))
    return _Coeffs(sa, ss, gs, em)


def _volume_scatter(node, ctx, alg):
    phase = getattr(node, "phase", "HENYEY_GREENSTEIN")
    if phase != "HENYEY_GREENSTEIN":
        ctx.issue(f"{node.name!r}: the {phase.replace('_', ' ').title()} phase function is "
                  f"rendered as Henyey-Greenstein")
    density = alg.max0(_read(node, "Density", ctx, 1.0))
    color = _read(node, "Color", ctx, (0.8,) * 3, True)
    ss, gs = _scatter(alg, color, density, _constant(node, "Anisotropy", ctx, 0.0))
    return _Coeffs(ss=ss, gs=gs)


def _absorption(node, ctx, alg):
    density = alg.max0(_read(node, "Density", ctx, 1.0))
    color = _read(node, "Color", ctx, (0.8,) * 3, True)
    return _Coeffs(sa=alg.mul(alg.max0(alg.one_minus(color)), density))


def _coefficients(node, ctx, alg):
    def v(name):
        return alg.max0(_read(node, name, ctx, (0.0,) * 3, True))
    ss = v("Scatter Coefficients")
    g = _constant(node, "Anisotropy", ctx, 0.0)
    return _Coeffs(v("Absorption Coefficients"), ss, float(alg.mean(ss).mean()) * g,
                   v("Emission Coefficients"))


def _emission(node, ctx, alg):
    color = _read(node, "Color", ctx, (1.0,) * 3, True)
    return _Coeffs(em=alg.max0(alg.mul(color, _read(node, "Strength", ctx, 1.0))))


_NODES = {"ShaderNodeVolumePrincipled": _principled,
          "ShaderNodeVolumeScatter": _volume_scatter,
          "ShaderNodeVolumeAbsorption": _absorption,
          "ShaderNodeVolumeCoefficients": _coefficients,
          "ShaderNodeEmission": _emission}


def _coeffs(socket, ctx, alg, depth=0):
    found = _link(socket)
    if found is None or depth > 32:
        return _Coeffs()
    node = found[0]
    kind = node.bl_idname
    if kind in _NODES:
        return _NODES[kind](node, ctx, alg)
    if kind == "ShaderNodeAddShader":
        return _coeffs(node.inputs[0], ctx, alg, depth + 1).plus(
            _coeffs(node.inputs[1], ctx, alg, depth + 1), alg)
    if kind == "ShaderNodeMixShader":
        f = alg.clamp01(_read(node, "Fac", ctx, 0.5))
        return _coeffs(node.inputs[1], ctx, alg, depth + 1).scaled(alg.one_minus(f), alg).plus(
            _coeffs(node.inputs[2], ctx, alg, depth + 1).scaled(f, alg), alg)
    ctx.issue(f"its volume uses the {node.bl_label!r} node, which DRT does not render in "
              f"volumes; that part is left out")
    return _Coeffs()


def is_heterogeneous(material) -> bool:
    """Whether an engine Material's volume varies in space (its program computes it)."""
    shader = getattr(material, "shader", None)
    return shader is not None and any(k in shader.outputs for k in VOLUME_OUTPUTS)


def volume_sampling(ctx) -> str:
    """The material's or world's Settings > Volume > Sampling Method (Cycles' defaults:
    Multiple Importance for materials, Equiangular for the world)."""
    owner = getattr(ctx, "mat", None) or getattr(ctx, "world", None)
    default = "EQUIANGULAR" if getattr(ctx, "mat", None) is None else "MULTIPLE_IMPORTANCE"
    method = getattr(getattr(owner, "cycles", None), "volume_sampling", default)
    return method if method in ("DISTANCE", "EQUIANGULAR", "MULTIPLE_IMPORTANCE") else default


def export_volume(socket, ctx) -> "engine.Volume | None":
    """The Volume behind a Volume socket (None: nothing linked or empty). When it varies
    in space (a material's, ctx.volume_programs), its coefficients are also left in
    ctx.volume_outputs ({VOLUME_OUTPUTS name: program Value}) for the material's
    program, and the Volume holds their averages."""
    if socket is None or _link(socket) is None:
        return None
    alg = _Algebra(ctx.nodes)
    return _volume_of(_coeffs(socket, ctx, alg), ctx, alg)


def default_volume(ctx) -> "engine.Volume | None":
    """Cycles' default volume shader, which fills a Volume object that has no material:
    a Principled Volume at its defaults (Density 1 times the object's density grid,
    Color 0.5; its Blackbody Intensity is 0). ctx as export_volume's."""
    alg = _Algebra(ctx.nodes)
    density = 1.0
    grid = (getattr(ctx, "volume_grids", None) or {}).get("density")
    if grid is not None:
        density = alg.max0(grid_value(ctx.nodes, grid, "float"))
    half = np.full(3, 0.5)
    return _volume_of(_Coeffs(alg.mul(half, density), alg.mul(half, density)), ctx, alg)


def _volume_of(c, ctx, alg):
    scale = getattr(ctx, "volume_density_scale", 1.0)
    if scale != 1.0:              # a Volume object's Object-space density (Cycles)
        c = c.scaled(scale, alg)
    sa, ss, em = alg.mean(c.sa), alg.mean(c.ss), alg.mean(c.em)
    ss_mean = float(ss.mean())
    g = c.gs / ss_mean if ss_mean > 0 else 0.0
    v = engine.Volume(tuple(np.maximum(sa, 0.0)), tuple(np.maximum(ss, 0.0)),
                      min(max(g, -1.0), 1.0), tuple(np.maximum(em, 0.0)),
                      volume_sampling(ctx))
    if c.varies():
        ctx.volume_outputs = {name: alg.vector(x) for name, x in
                              zip(VOLUME_OUTPUTS, (c.sa, c.ss, c.em))}
        return v
    return None if v.is_empty() else v


class _VolumeCtx(_WorldCtx):
    """The world's context with what the node readers need of a material's."""

    def __init__(self, world, reporter):
        from .nodes import NodeCompiler
        super().__init__(world, reporter)
        self.world = world
        self.normal = None
        self.nodes = NodeCompiler(self)


def world_volume(world, reporter) -> "engine.Volume | None":
    """The volume of the world's active World Output (None without one), filling the
    space outside every mesh; what is approximated is reported."""
    tree = getattr(world, "node_tree", None)
    out = world_output(tree) if tree is not None else None
    if out is None:
        return None
    ctx = _VolumeCtx(world, reporter)
    v = export_volume(out.inputs.get("Volume"), ctx)
    ctx.report(reporter)
    return v


def suns_blocked_message(volume, lights) -> str:
    """What to tell the artist when a volume on the World Output, which fills all space,
    hides the sun lamps: their light never arrives through it (their shadow rays are
    endless), as in Cycles; "" when it does not (no such volume, one that only emits, or
    no sun)."""
    if volume is None or not (any(v > 0 for v in volume.absorption)
                              or any(v > 0 for v in volume.scattering)):
        return ""
    suns = [light.name for light in lights if isinstance(light, engine.SunLight)]
    if not suns:
        return ""
    return (f"the world's volume fills all space, so sun lamp(s) {', '.join(suns)} and "
            "the world's light give no light through it, as in Cycles; to light fog "
            "with a sun, put the fog in a volume object (a large cube)")
