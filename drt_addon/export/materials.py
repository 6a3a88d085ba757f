"""Blender materials to DRT's Principled parameters, with Cycles' meaning of each node.

Where things are: this module drives the export of one material; the shader nodes are
read into closures by export/nodes/shader.py, reduced to one Principled parameter set by
export/closures.py, their linked inputs compiled into the material's program by
export/nodes/ (export/material_params.py combines plain and per-hit values).

The node tree behind the active Material Output's Surface socket is read as a weighted
set of closures, as Cycles builds it (intern/cycles/kernel/svm/closure.h), and reduced to
one `engine.Material`:

Principled BSDF
    Base Color, Metallic, Roughness (GGX alpha = roughness^2), IOR, Transmission Weight,
    Specular IOR Level and Emission Color x Emission Strength as they are. Alpha a: the
    BSDF gets weight a and a Transparent BSDF the rest (so emission is a x emission on
    average), rendered as stochastic transparency. Coat and sheen are the compiled
    BSDF's layers; Specular Tint (`Material.specular_tint`) is the metal lobe's F82
    tint and the specular layer's and the glass's F0 tint, as in Cycles. Subsurface
    Weight, Radius, Scale, IOR and Anisotropy are Cycles' random walk
    (export/nodes/subsurface.py). Anisotropy, thin film and diffuse roughness are not
    modelled: reported when used.
    The node's distribution is the material's `glossy_model`: 'MULTI_GGX' (Blender's
    default, Cycles' energy-compensated GGX) or 'GGX' (single scattering).
Subsurface Scattering
    Cycles' random walk of its Color, Radius x Scale, IOR, Roughness and Anisotropy
    (Random Walk and Random Walk (Skin)), or Christensen-Burley's profile of its Color and
    Radius x Scale by Cycles' disk sampling.
Diffuse BSDF
    Lambert with its colour (no specular layer). Roughness > 0 (Oren-Nayar) is reported.
Glossy BSDF
    Microfacet reflection of its colour with its roughness: DRT's metal lobe with
    reflectance = colour at every angle (`Material.metal_fresnel` 'CONSTANT': Cycles'
    Glossy has no Fresnel term), its multiple-scattering compensation coloured by the
    colour itself, as Cycles' is. Multiscatter GGX (the default), GGX and Beckmann are
    kept; Ashikhmin-Shirley is rendered as GGX (reported).
Glass BSDF
    DRT's glass lobe with the node's IOR, roughness and distribution (Multiscatter GGX,
    GGX or Beckmann); its colour tints each refraction
    (`Material.glass_color`), as Cycles' Glass does (Cycles also tints the reflection).
Refraction BSDF
    The glass lobe's refraction alone, without Fresnel (`Material.refraction_only`), with
    the node's distribution (Beckmann, its default, or GGX).
Emission
    Radiance = colour x strength (no 1/pi); alone it is an opaque black emitter, as in
    Cycles (an Emission shader has no BSDF).
Transparent BSDF
    A pass-through closure of its colour (`Material.alpha`, `transparent_color`).
Mix Shader
    Fac constant: closures are weighted by 1 - Fac and Fac and the mixture is reduced to
    one Principled parameter set: the lobe weights (metal, glass, dielectric base,
    transparent) mix exactly, each lobe's colour is the weighted mean of the colours of
    the closures that contribute to it (a Glossy's colour becomes the metal colour, a
    Diffuse's the base colour), roughness and IOR are means weighted by the lobes that use
    them; the distribution is that of the closure with the largest glossy weight
    (reported when they differ). Fac from a Fresnel or Layer Weight node (angle-dependent
    in Cycles): a Mix of a
    dielectric base with a Glossy BSDF becomes Principled's own Fresnel-weighted specular
    layer with that IOR (the classic "plastic" set-up, which is what that layer models);
    otherwise the factor is replaced by its average over the cosine-weighted hemisphere.
    Both approximations are reported.
Add Shader
    Emission + BSDF is exact (the emissions add, the BSDF stays). Two BSDFs are summed
    as a mix at 1/2 with their colours doubled (exact for the lobe colours, reported).
Linked inputs (any node graph, engine/nodes and export/nodes)
    The graph linked to an input is compiled into the material's shader program, which
    the engine runs at every hit (`engine.nodes`): Image, Checker and Gradient textures,
    the procedural textures with Blender's own noise (White Noise, Noise, Voronoi, Wave,
    Magic, Brick), the colour, converter, vector and input nodes, node groups and
    reroutes. A graph
    that does not depend on the hit is folded into a constant at export. Base Color,
    Metallic, Roughness, Emission Color and Strength and Alpha (and the Color of
    Diffuse, Glossy and Emission) vary per hit; other inputs (IOR, Transmission, the
    Mix Shader's Fac...) take the graph's average over the unit square of UV and
    generated coordinates when it varies (reported). A node no family translates is
    reported and its socket keeps its own value. Images: 8-bit sRGB images are decoded
    after interpolation like Cycles; float images and Non-Color data are read as they
    are; straight-alpha images have their colour premultiplied when the Alpha output is
    not used (Cycles associates alpha on load).
Displacement (the Material Output's socket)
    As Material > Settings > Displacement asks (export/nodes/displacement.py): Bump Only
    (Blender's default) bends the normal as a Bump of the displacement's height would
    bend it; Displacement Only moves the mesh's vertices (engine.displacement, at
    export); Displacement and Bump does both.

A node tree without a Material Output is black and opaque, as in Cycles (no closure).
Anything else falls back to a diffuse surface of the material's viewport colour. Every
approximation is reported once per material, in one warning naming the material.
"""
from __future__ import annotations

import dataclasses
from typing import Optional

from ..engine_link import engine
from .closures import _Comp, _reduce, program_outputs
from .emission_sampling import emission_sampling, surface_estimate
from .errors import Reporter
from .images import image_cache
from .nodes import NodeCompiler
from .nodes.displacement import displacement_normal, true_displacement
from .nodes.errors import Unsupported
from .nodes.aov_output import material_aovs
from .nodes.links import _all_nodes, _link, _output_node, tree_problems, uses_nodes
from .nodes.shader import _closure
from .volumes import default_volume, export_volume



class _Ctx:
    """Per-material state: the material, what could not be represented (reported once
    per material) and the export's image cache."""

    def __init__(self, mat, reporter):
        self.mat = mat
        self.name = mat.name
        self.issues = []
        self.cache = image_cache(reporter)
        self.nodes = NodeCompiler(self)
        self.normal = None          # the per-hit shading normal (a program Value), if any
        self.sets_normal = False    # ... set as the surface's own (the Displacement's bump)
        self.surface_normal = None  # the surface's own where a shader has a Normal of its own
        self.coat_normal = None     # a Principled's linked Coat Normal (a program Value)
        self.volume_programs = True     # a volume varying in space joins the program
        self.volume_outputs = {}        # ... as these outputs (export/volumes.py)

    def issue(self, text):
        if text not in self.issues:
            self.issues.append(text)

    def viewport_comp(self):
        m = self.mat
        return _Comp(base=tuple(m.diffuse_color[:3]), metallic=float(m.metallic),
                     roughness=float(m.roughness), spec=0.5)


# --------------------------------------------------------------------------- entry points
UV_READERS = {"ShaderNodeTexImage", "ShaderNodeUVMap", "ShaderNodeTexCoord"}


def material_uv_maps(mat) -> Optional[set]:
    """The UV maps a material's nodes may read ('' = the mesh's default map), or None
    when no node reads UVs (its meshes then need no UVs)."""
    if mat is None or not uses_nodes(mat):
        return None
    nodes = list(_all_nodes(mat.node_tree))
    if not any(n.bl_idname in UV_READERS for n in nodes):
        return None
    names = {n.uv_map for n in nodes if n.bl_idname == "ShaderNodeUVMap" and n.uv_map}
    return names or {""}


def _material(cl, ctx, name) -> "engine.Material":
    """The Material of closure set cl; a Mix Shader with a per-hit Fac (cl.mix) becomes a
    Material shading each hit by one of its two sides (Material.mix), picked with the
    Fac's probability; anywhere else in the tree it mixes by the Fac's average."""
    m = _reduce(cl, ctx, name)
    # Settings > Bump Map Correction: how a bent normal is lit (engine.Material)
    m.bump_correction = bool(getattr(getattr(ctx.mat, "cycles", None),
                                     "use_bump_map_correction", True))
    if cl.mix is not None:
        a, b, fac = cl.mix
        program_outputs(m)["mix"] = fac
        m.mix = (_material(a, ctx, name + " [1]"), _material(b, ctx, name + " [2]"))
    return m


def _bump_pass(mat, out, ctx):
    """The Displacement socket's bump (export/nodes/displacement.py), compiled before the
    surface's nodes as Cycles' bump pass runs before them: its bent normal (None: no
    bump) is the surface's own normal (Cycles' Set Normal, sd->N) for every node after
    it (NodeCompiler.set_normal)."""
    disp = out.inputs.get("Displacement")
    if disp is None or _link(disp) is None:
        return None
    try:
        bent = displacement_normal(mat, disp, ctx)
    except Unsupported as e:
        ctx.issue(f"its displacement is not rendered ({e})")
        return None
    if bent is not None:
        ctx.nodes.set_normal(bent)
    return bent


def _displace(bent, ctx):
    """The bump's normal `bent` as the material's shading normal, or where a shader has a
    Normal of its own (which its lobes keep), as the surface normal alone (bent lobes are
    shadowed against it, lights picked for it)."""
    if bent is None:
        return
    if ctx.normal is not None:
        ctx.surface_normal, ctx.sets_normal = bent, True
        return
    ctx.normal, ctx.sets_normal = bent, True      # Cycles' Set Normal


def _attach_programs(m, ctx, program):
    """Give m (and the sides of its mixes) the material's program with its own outputs
    (all share the program's instructions and registers; the normal is everyone's)."""
    outputs = dict(program_outputs(m))
    if ctx.normal is not None:
        outputs["normal"] = ctx.normal
        m.sets_normal = ctx.sets_normal
    if ctx.surface_normal is not None:
        outputs["surface_normal"] = ctx.surface_normal
    if ctx.coat_normal is not None:
        outputs["coat_normal"] = ctx.coat_normal
    if outputs:
        m.shader = dataclasses.replace(program, outputs=outputs)
    for side in (m.mix or ()):
        _attach_programs(side, ctx, program)


def export_material(mat, reporter: Reporter, grids=None,
                    density_scale: float = 1.0) -> "engine.Material":
    """`mat` (None: an empty slot) as an engine Material, with Cycles' meaning; what is
    approximated is reported once, in one warning naming the material. On a Volume
    object, `grids` ({name: engine.volume_grid.VoxelGrid}) are what its Attribute nodes
    read and `density_scale` its Object-space density (export.volume_objects)."""
    if mat is None:      # Cycles' default surface: a Principled BSDF at its defaults
        return engine.Material("none", glossy_model="MULTI_GGX")
    name = mat.name
    ctx = _Ctx(mat, reporter)
    ctx.volume_grids = grids or {}
    ctx.volume_density_scale = float(density_scale)
    fallback = engine.Material(name, tuple(mat.diffuse_color[:3]), metallic=float(mat.metallic),
                               roughness=float(mat.roughness), specular_ior_level=0.5,
                               glossy_model="MULTI_GGX")
    if not uses_nodes(mat):
        return fallback
    try:
        result = _from_nodes(mat, ctx)
    except Exception as e:     # a node set-up the exporter does not know: the rest renders
        ctx.issues = [f"DRT could not read its nodes ({type(e).__name__}: {e}); it renders "
                      "with its viewport colour"]
        result = fallback
    if result is not fallback:
        try:
            result.aovs = material_aovs(mat, ctx)      # its AOV Output nodes
        except Exception as e:
            ctx.issue(f"its AOV Output nodes are not written ({type(e).__name__}: {e})")
    if ctx.issues and reporter is not None:
        reporter.warn(f"DRT: material {name!r}: " + "; ".join(ctx.issues),
                      key=(name, "material"))
    result.pass_index = int(getattr(mat, "pass_index", 0))     # the Material Index pass
    result.emission_sampling = emission_sampling(mat)    # Material > Settings
    _estimate_varying_emission(result, mat)
    return result


def _estimate_varying_emission(result, mat):
    """An emission that varies per hit keeps its average as its plain value, which light
    sampling weighs its triangles by (engine.kernels.shaded_emitter). Where that average
    is black though the program emits (a Layer Weight's Facing, which the average cannot
    see, having no view), it takes Cycles' own estimate of the tree instead (a linked
    input counts 1), as Cycles' light tree weighs such a mesh."""
    outputs = getattr(getattr(result, "shader", None), "outputs", None) or {}
    if "emission" not in outputs or max(result.emission[:3]) > 0.0:
        return
    try:
        estimate, _ = surface_estimate(mat)
    except Exception:            # a tree the estimate cannot walk
        estimate = [1.0, 1.0, 1.0]
    result.emission = tuple(max(float(x), 0.0) for x in estimate[:3])


class _DefaultVolume:
    """What a Volume object without a material renders with (Cycles' default volume)."""
    name = "DRT default volume"
    diffuse_color = (0.8, 0.8, 0.8, 1.0)
    metallic, roughness = 0.0, 0.5
    cycles = None


def export_default_volume(reporter: Reporter, grids, density_scale: float
                          ) -> "engine.Material":
    """The material of a Volume object with no material: Cycles' default volume shader
    (export.volumes.default_volume) over its grids, with no surface."""
    ctx = _Ctx(_DefaultVolume(), reporter)
    ctx.volume_grids = grids or {}
    ctx.volume_density_scale = float(density_scale)
    result = engine.Material(_DefaultVolume.name, (0.0, 0.0, 0.0), specular_ior_level=0.0)
    result.volume = default_volume(ctx)
    _attach_programs(result, ctx, ctx.nodes.build())
    if ctx.volume_outputs:
        program = result.shader or ctx.nodes.build()
        result.shader = dataclasses.replace(
            program, outputs={**program.outputs, **ctx.volume_outputs})
    result.surface = False
    return result


def _is_holdout(socket) -> bool:
    found = _link(socket)
    return found is not None and found[0].bl_idname == "ShaderNodeHoldout"


def _from_nodes(mat, ctx) -> "engine.Material":
    """The material from its node tree (see the module docstring)."""
    name = mat.name
    for problem in tree_problems(mat.node_tree):
        ctx.issue(problem)
    out = _output_node(mat.node_tree)
    if out is None:
        # Cycles: a node tree without an output has no closure: black, opaque (as an
        # output whose Surface is unlinked), not the viewport colour
        result = engine.Material(name, (0.0, 0.0, 0.0), specular_ior_level=0.0)
    elif _is_holdout(out.inputs["Surface"]):
        # Cycles' Holdout: a hole in the alpha for the camera, black to other rays
        result = engine.Material(name, (0.0, 0.0, 0.0), specular_ior_level=0.0,
                                 holdout=True)
    else:
        bent = _bump_pass(mat, out, ctx)
        result = _material(_closure(out.inputs["Surface"], ctx), ctx, name)
        _displace(bent, ctx)
        disp = out.inputs.get("Displacement")
        if disp is not None and _link(disp) is not None:
            try:
                result.displacement = true_displacement(mat, disp, ctx)
            except Unsupported as e:
                ctx.issue(f"its displacement does not move the surface ({e})")
        # a volume inside its meshes (its program outputs, when it varies in space, join
        # the surface's); with no surface shader, the surface is its boundary
        result.volume = export_volume(out.inputs.get("Volume"), ctx)
        _attach_programs(result, ctx, ctx.nodes.build())
        if ctx.volume_outputs:
            program = result.shader or ctx.nodes.build()
            result.shader = dataclasses.replace(
                program, outputs={**program.outputs, **ctx.volume_outputs})
        result.surface = result.volume is None or _link(out.inputs["Surface"]) is not None
        if result.volume is None and _link(out.inputs["Surface"]) is None:
            ctx.issue("no shader reaches its Material Output's Surface; it renders black, "
                      "as in Cycles")
    return result
