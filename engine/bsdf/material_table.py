"""Scene materials as arrays (`MaterialTable`), indexed by a hit's material id: the
Principled parameters of engine/scene/material.py's `Material`s, with their textures."""
from __future__ import annotations

import numpy as np

# The microfacet models of `Material.glossy_model`
GLOSSY_MODELS = ("GGX", "MULTI_GGX", "BLINN_PHONG", "BECKMANN")
# The Fresnel term of the metal lobe (`Material.metal_fresnel`)
METAL_FRESNELS = ("SCHLICK", "CONSTANT")
# How a node's anisotropy maps to two alphas (`Material.anisotropy_kind`; params.ANISO_*)
ANISOTROPY_KINDS = ("NONE", "PRINCIPLED", "GLOSSY")
# Cycles' subsurface methods (`Material.subsurface_method`), in the order of their codes
SUBSURFACE_METHODS = ("RANDOM_WALK", "RANDOM_WALK_SKIN", "BURLEY")


def flatten_mixes(materials):
    """(materials with the shaders of every Mix Shader appended after the scene's, their
    indices (n, 2): the two shaders mixed per hit by material i, -1 for none)."""
    out = list(materials)
    children = []
    i = 0
    while i < len(out):
        mix = getattr(out[i], "mix", None)
        if mix is not None:
            children.append((len(out), len(out) + 1))
            out.extend(mix)
        else:
            children.append((-1, -1))
        i += 1
    return out, np.array(children, np.int64).reshape(-1, 2)


def _choices(materials, attr, default, allowed) -> list[str]:
    """Each material's `attr` (default when missing), which must be one of `allowed`."""
    values = [getattr(m, attr, default) for m in materials]
    for m, v in zip(materials, values):
        if v not in allowed:
            raise ValueError(f"material {m.name!r}: {attr} must be one of "
                             f"{', '.join(map(repr, allowed))}, not {v!r}")
    return values


class MaterialTable:
    """Scene materials as arrays, indexed by a hit's material id.

    The plain arrays (base_color, metallic, ...) hold each material's constant value (for
    a textured parameter: the texture's average, a summary for estimates such as the
    albedo AOV). What a hit sees comes from `lookup(name, index, uv)`, which evaluates the
    parameter's texture (engine.textures) at the hit's UV where the material has one.

    `emission` is the constant emission a hit reads: zero for materials whose emission
    varies over the surface (a texture or a program says it per hit). Light sampling
    (engine.mesh_lights) reads `emission_estimate`, which holds those materials'
    average instead, and `emission_shaded`, which names them: their light samples
    evaluate the material where they land (engine.kernels.shaded_emitter).
    """

    PARAMS = ("base_color", "metallic", "roughness", "emission", "alpha")

    def __init__(self, materials):
        materials = list(materials)
        self.n_scene_materials = len(materials)     # the mixed shaders' materials follow
        materials, self.mix_children = flatten_mixes(materials)
        self.base_color = np.array([m.base_color[:3] for m in materials], dtype=np.float64)
        self.metallic = np.array([m.metallic for m in materials], dtype=np.float64)
        self.roughness = np.array([m.roughness for m in materials], dtype=np.float64)
        self.ior = np.array([m.ior for m in materials], dtype=np.float64)
        self.transmission = np.array([m.transmission for m in materials], dtype=np.float64)
        self.specular_ior_level = np.array([m.specular_ior_level for m in materials], np.float64)
        self.alpha = np.array([getattr(m, "alpha", 1.0) for m in materials], dtype=np.float64)
        models = _choices(materials, "glossy_model", "GGX", GLOSSY_MODELS)
        self.blinn_phong = np.array([model == "BLINN_PHONG" for model in models], bool)
        self.multiscatter = np.array([model == "MULTI_GGX" for model in models], bool)
        self.beckmann = np.array([model == "BECKMANN" for model in models], bool)
        fresnels = _choices(materials, "metal_fresnel", "SCHLICK", METAL_FRESNELS)
        self.metal_constant = np.array([f == "CONSTANT" for f in fresnels], bool)
        self.diffuse_roughness = np.clip(np.nan_to_num(np.array(
            [float(getattr(m, "diffuse_roughness", 0.0)) for m in materials], np.float64)),
            0.0, 1.0)
        # Specular Tint: >= 0 (Cycles clamps the metal's F82 tint to 1, and the tinted
        # F0 of the specular layer to 1, kernels/bsdf/specular_tint.py)
        self.specular_tint = np.maximum(np.array(
            [tuple(getattr(m, "specular_tint", (1.0, 1.0, 1.0)))[:3] for m in materials],
            np.float64).reshape(-1, 3), 0.0)
        # Lobe colours: the metal F0 and the glass tint per crossing, when they are not
        # Principled's own (base colour, sqrt(base colour)).
        metal = [getattr(m, "metal_color", None) for m in materials]
        glass = [getattr(m, "glass_color", None) for m in materials]
        self.has_metal_color = np.array([c is not None for c in metal], bool)
        self.has_glass_color = np.array([c is not None for c in glass], bool)
        self.metal_color = np.array([(c if c is not None else b)[:3] for c, b in
                                     zip(metal, self.base_color)], np.float64).reshape(-1, 3)
        self.glass_color = np.array([(c if c is not None else (1.0, 1.0, 1.0))[:3]
                                     for c in glass], np.float64).reshape(-1, 3)
        self.glass_reflection_tint = np.maximum(np.array(
            [tuple(getattr(m, "glass_reflection_tint", (1.0, 1.0, 1.0)))[:3]
             for m in materials], np.float64).reshape(-1, 3), 0.0)
        _require_finite(materials, "glass_reflection_tint", self.glass_reflection_tint)
        self._layer_params(materials)
        self._subsurface_params(materials)
        kinds = _choices(materials, "anisotropy_kind", "NONE", ANISOTROPY_KINDS)
        self.anisotropy_kind = np.array([ANISOTROPY_KINDS.index(k) for k in kinds], np.float64)
        for name in ("anisotropy", "anisotropic_rotation"):
            setattr(self, name, np.nan_to_num(np.array(
                [float(getattr(m, name, 0.0)) for m in materials], np.float64)))
        # Thin Film (engine/kernels/bsdf/thin_film.py): thickness in nm, IOR
        self.thin_film_thickness = np.nan_to_num(np.maximum(np.array(
            [float(getattr(m, "thin_film_thickness", 0.0)) for m in materials], np.float64),
            0.0))
        self.thin_film_ior = np.nan_to_num(np.maximum(np.array(
            [float(getattr(m, "thin_film_ior", 1.33)) for m in materials], np.float64),
            1e-5), nan=1.33)
        self.transparent_color = np.array(
            [tuple(getattr(m, "transparent_color", (1.0, 1.0, 1.0)))[:3] for m in materials],
            np.float64).reshape(-1, 3)
        # Textures: one input per (parameter, material), each distinct Texture indexed once.
        self.textures = []
        self.texture_index = {}            # id(Texture) -> index into self.textures
        self._inputs = {}
        for name in self.PARAMS:
            inputs = [getattr(m, name + "_texture", None) for m in materials]
            if any(t is not None for t in inputs):
                self._inputs[name] = inputs
                for t in inputs:
                    if t is not None and id(t.texture) not in self.texture_index:
                        self.texture_index[id(t.texture)] = len(self.textures)
                        self.textures.append(t.texture)
        # Shader programs (engine.nodes): their images join the texture list; a program
        # output makes its parameter per-hit for that material.
        self.programs = [getattr(m, "shader", None) for m in materials]
        for p in self.programs:
            for t in (p.images if p is not None else ()):
                if id(t) not in self.texture_index:
                    self.texture_index[id(t)] = len(self.textures)
                    self.textures.append(t)
        self.programmed = {name: np.array([p is not None and name in p.outputs
                                           for p in self.programs], bool)
                           for name in self.PARAMS}
        self.programmed = {k: v for k, v in self.programmed.items() if v.any()}
        self._shading = None
        self.textured = {name: np.array([t is not None for t in inputs], bool)
                         for name, inputs in self._inputs.items()}
        for name, flags in self.programmed.items():
            self.textured[name] = self.textured.get(name, np.zeros(len(materials), bool)) | flags
        emission = np.array([m.emission[:3] for m in materials], dtype=np.float64)
        for name, arr in (("base_color", self.base_color), ("metallic", self.metallic),
                          ("roughness", self.roughness), ("ior", self.ior),
                          ("transmission", self.transmission),
                          ("specular_ior_level", self.specular_ior_level),
                          ("emission", emission), ("alpha", self.alpha),
                          ("metal_color", self.metal_color), ("glass_color", self.glass_color),
                          ("transparent_color", self.transparent_color)):
            _require_finite(materials, name, arr)
        self.emission_textured = self.textured.get("emission", np.zeros(len(materials), bool))
        self.emission = np.where(self.emission_textured[:, None], 0.0, emission)
        self.emission_shaded = self.emission_textured & (emission.max(axis=1) > 0.0)
        self.emission_estimate = np.where(self.emission_shaded[:, None],
                                          np.maximum(emission, 0.0), self.emission)
        self.any_emission = bool((self.emission > 0).any() or self.emission_textured.any())
        alpha_tex = self.textured.get("alpha", np.zeros(len(materials), bool))
        # Materials that may let rays through (stochastic transparency in the integrators)
        self.maybe_transparent = (self.alpha < 1.0) | alpha_tex
        # a Mix Shader per hit lets shadow rays through where a shader it mixes does
        # (kernels/transparency.py); its shaders follow it in the list
        for i in range(len(materials) - 1, -1, -1):
            c0, c1 = self.mix_children[i]
            if c0 >= 0:
                self.maybe_transparent[i] |= self.maybe_transparent[c0] | \
                    self.maybe_transparent[c1]
        self.any_transparent = bool(self.maybe_transparent.any())
        # Which lobes any material can produce (a scene of plain diffuse materials never
        # touches the microfacet code).
        self.any_glossy = bool(((self.specular_ior_level > 0) | (self.metallic > 0)
                                | (self.transmission > 0) | (self.coat_weight > 0)).any()
                               or "metallic" in self.textured)

    def _layer_params(self, materials):
        """The lobes beyond Principled's base (engine/kernels/bsdf/layers.py): coat,
        sheen, translucency and refraction without reflection, and `layered`, whether a
        material uses any of them (the others never run their code)."""
        def scalar(name, default):
            return np.array([float(getattr(m, name, default)) for m in materials], np.float64)

        def colour(name, default):
            return np.array([tuple(getattr(m, name, default))[:3] for m in materials],
                            np.float64).reshape(-1, 3)
        self.coat_weight = np.maximum(scalar("coat_weight", 0.0), 0.0)
        self.coat_roughness = scalar("coat_roughness", 0.03)
        self.coat_ior = scalar("coat_ior", 1.5)
        self.coat_tint = colour("coat_tint", (1.0, 1.0, 1.0))
        self.sheen_weight = np.maximum(scalar("sheen_weight", 0.0), 0.0)
        self.sheen_roughness = scalar("sheen_roughness", 0.5)
        self.sheen_tint = colour("sheen_tint", (1.0, 1.0, 1.0))
        self.translucent_color = np.maximum(colour("translucent_color", (0.0, 0.0, 0.0)), 0.0)
        # a Hair BSDF node's two components (engine/kernels/bsdf/hair.py)
        for part in ("reflection", "transmission"):
            name = "hair_" + part
            setattr(self, name, np.maximum(colour(name, (0.0, 0.0, 0.0)), 0.0))
            setattr(self, name + "_offset", scalar(name + "_offset", 0.0))
            setattr(self, name + "_roughness", np.array(
                [tuple(getattr(m, name + "_roughness", (0.1, 1.0)))[:2] for m in materials],
                np.float64).reshape(-1, 2))
        self._chiang_params(materials)
        self.hair = ((self.hair_reflection.max(1) > 0.0) | (self.hair_transmission.max(1) > 0.0)
                     | (self.chiang_weight.max(1) > 0.0))
        self.refraction_only = np.array([bool(getattr(m, "refraction_only", False))
                                         for m in materials], bool)
        self.sheen_layered = np.array([bool(getattr(m, "sheen_layered", True))
                                       for m in materials], bool)
        self.bump_correction = np.array([bool(getattr(m, "bump_correction", True))
                                         for m in materials], bool)
        self.sets_normal = np.array([bool(getattr(m, "sets_normal", False))
                                     for m in materials], bool)
        # the share of hits that are a Holdout (1 for a Holdout shader alone)
        self.holdout_weight = np.array(
            [1.0 if getattr(m, "holdout", False)
             else float(np.clip(getattr(m, "holdout_weight", 0.0), 0.0, 1.0))
             for m in materials], np.float64)
        # a Translucent BSDF's colour per hit (its program's translucent_color), which may
        # average to black (a ramp of the Object Info's Random, say)
        translucent_per_hit = np.array(
            ["translucent_color" in getattr(getattr(m, "shader", None), "outputs", {})
             for m in materials], bool)
        self.layered = ((self.coat_weight > 1e-5) | (self.sheen_weight > 1e-5)
                        | (self.translucent_color.max(1) > 0.0) | translucent_per_hit
                        | self.refraction_only | self.hair)
        # the emission the coat and sheen dim (engine.kernels.bsdf.layered_emission)
        under = np.array([bool(getattr(m, "emission_under_layers", True))
                          for m in materials], bool)
        emits = np.array([m.is_emissive() if hasattr(m, "is_emissive")
                          else max(m.emission[:3]) > 0.0 for m in materials], bool)
        self.emission_dimmed = under & emits & (
            (self.coat_weight > 1e-5) | ((self.sheen_weight > 1e-5) & self.sheen_layered))
        for name in ("coat_weight", "coat_roughness", "coat_ior", "coat_tint", "sheen_weight",
                     "sheen_roughness", "sheen_tint", "translucent_color", "hair_reflection",
                     "hair_reflection_offset", "hair_reflection_roughness",
                     "hair_transmission", "hair_transmission_offset",
                     "hair_transmission_roughness"):
            _require_finite(materials, name, getattr(self, name))

    def _chiang_params(self, materials):
        """A Principled Hair BSDF's inputs (engine.principled_hair; hair_chiang.py)."""
        from ..principled_hair import PARAMETRIZATIONS, PrincipledHair
        hair = [getattr(m, "principled_hair", None) for m in materials]
        plain = PrincipledHair(weight=(0.0, 0.0, 0.0))
        hair = [plain if h is None else h for h in hair]
        self.chiang_weight = np.maximum(np.array([h.weight for h in hair],
                                                 np.float64).reshape(-1, 3), 0.0)
        self.chiang_mode = np.array([PARAMETRIZATIONS.index(h.parametrization)
                                     for h in hair], np.float64)
        self.chiang_colour = np.array([h.mode_colour() for h in hair],
                                      np.float64).reshape(-1, 3)
        self.chiang_melanin = np.array([(h.melanin, h.melanin_redness) for h in hair],
                                       np.float64).reshape(-1, 2)
        self.chiang_roughness = np.array([(h.roughness, h.radial_roughness, h.coat)
                                          for h in hair], np.float64).reshape(-1, 3)
        self.chiang_ior = np.array([h.ior for h in hair], np.float64)
        self.chiang_offset = np.array([h.offset for h in hair], np.float64)
        self.chiang_random = np.array([(h.random_color, h.random_roughness, h.random)
                                       for h in hair], np.float64).reshape(-1, 3)
        self.chiang_own_random = np.array([h.strand_random for h in hair], np.float64)
        for name in ("chiang_weight", "chiang_colour", "chiang_melanin", "chiang_roughness",
                     "chiang_ior", "chiang_offset", "chiang_random"):
            _require_finite(materials, name, getattr(self, name))

    def _subsurface_params(self, materials):
        """Subsurface scattering (engine/kernels/subsurface.py): weight, radius (mean free
        path per channel, scene units), anisotropy, the entry's IOR and GGX alpha (< 0:
        the hit's roughness^2) and the method (SUBSURFACE_METHODS)."""
        n = len(materials)
        self.subsurface_weight = np.clip(np.array(
            [float(getattr(m, "subsurface_weight", 0.0)) for m in materials], np.float64), 0, 1)
        self.subsurface_radius = np.maximum(np.array(
            [tuple(getattr(m, "subsurface_radius", (1.0, 0.2, 0.1)))[:3] for m in materials],
            np.float64).reshape(n, 3), 0.0)
        self.subsurface_anisotropy = np.array(
            [float(getattr(m, "subsurface_anisotropy", 0.0)) for m in materials], np.float64)
        self.subsurface_ior = np.array(
            [float(getattr(m, "subsurface_ior", 1.4)) for m in materials], np.float64)
        alpha = [getattr(m, "subsurface_alpha", None) for m in materials]
        self.subsurface_alpha = np.array([-1.0 if a is None else float(a) for a in alpha])
        methods = [getattr(m, "subsurface_method", "RANDOM_WALK") for m in materials]
        unknown = sorted(set(methods) - set(SUBSURFACE_METHODS))
        if unknown:
            raise ValueError(f"subsurface_method {unknown[0]!r} is none of "
                             f"{', '.join(SUBSURFACE_METHODS)}")
        # engine.kernels.bsdf.params' SSS_RANDOM_WALK, SSS_SKIN, SSS_BURLEY
        self.subsurface_method_code = np.array(
            [SUBSURFACE_METHODS.index(k) for k in methods], np.float64)
        for name in ("subsurface_weight", "subsurface_radius", "subsurface_anisotropy",
                     "subsurface_ior", "subsurface_alpha"):
            _require_finite(materials, name, getattr(self, name))
        # whether any material scatters below its surface (the path tracer then compiles
        # the random walk, engine.integrators.compiled_path)
        self.any_subsurface = bool((self.subsurface_weight > 0.0).any())

    @property
    def any_textures(self) -> bool:
        return bool(self.textures)

    @property
    def any_programs(self) -> bool:
        return any(p is not None for p in self.programs)

    def shading(self) -> tuple:
        """The packed textures and programs (engine.nodes.pack.pack_shading), once."""
        if self._shading is None:
            from ..nodes.pack import pack_shading
            self._shading = pack_shading(self)
        return self._shading

    def _constant(self, name):
        return self.emission if name == "emission" else getattr(self, name)

    def lookup(self, name, index, uv=None, hits=None) -> np.ndarray:
        """Parameter `name` (one of PARAMS) at hits of materials `index` (n,) with texture
        coordinates uv (n, 2) (None: the mesh has no UVs, read as (0, 0) like Cycles'
        missing UV attribute). hits: the (n, engine.nodes.context.N_HIT) rows shader
        programs read (None: built from uv alone, the rest neutral). Returns (n, 3) for
        colours, (n,) for scalars; a fresh array."""
        index = np.asarray(index, dtype=np.int64)
        if name in self.programmed and len(index):
            return self._programmed_lookup(name, index, uv, hits)
        return self._plain_lookup(name, index, uv)

    def _plain_lookup(self, name, index, uv) -> np.ndarray:
        """`lookup` from the plain values and textures (no programs)."""
        if name == "emission":
            out = np.where(self.emission_textured[index][:, None], 0.0, self.emission[index])
        else:
            out = self._constant(name)[index].copy()
        inputs = self._inputs.get(name)
        if inputs is None or len(index) == 0:
            return out
        rows = np.nonzero(self.textured[name][index])[0]
        if rows.size == 0:
            return out
        if uv is None:
            uv = np.zeros((len(index), 2))
        mats = index[rows]
        for k in np.unique(mats):
            r = rows[mats == k]
            out[r] = inputs[k].evaluate(uv[r])
        return out

    def _programmed_lookup(self, name, index, uv, hits):
        from ..nodes.context import hit_rows
        from ..nodes.interpreter import evaluate_materials
        from ..nodes.pack import OUTS
        from ..nodes.program import OUTPUTS
        rows = np.nonzero(self.programmed[name][index])[0]
        rest = np.nonzero(~self.programmed[name][index])[0]
        colour = name in ("base_color", "emission")
        out = np.zeros((len(index), 3)) if colour else np.zeros(len(index))
        if rest.size:
            out[rest] = self._plain_lookup(name, index[rest], None if uv is None else uv[rest])
        if hits is None:
            n = len(index)
            uv2 = np.zeros((n, 2)) if uv is None else uv
            hits = hit_rows(np.zeros((n, 3)), np.tile([0.0, 0.0, 1.0], (n, 1)), uv=uv2)
        T = self.shading()
        regs = evaluate_materials(T, index[rows], hits[rows])
        reg = T[OUTS][index[rows], OUTPUTS.index(name)]
        if colour:
            out[rows] = np.stack([regs[np.arange(len(rows)), reg + k] for k in range(3)], 1)
        else:
            out[rows] = regs[np.arange(len(rows)), reg]
        return out

    def shading_normal(self, index, hits, ns, ng) -> np.ndarray:
        """The shading normals (n, 3) of hits whose materials' programs set one (a Normal
        Map), else ns; as in the kernels (engine.nodes.shading.program_normal), made a
        valid specular reflector for the hit's view direction as Cycles does."""
        from ..nodes.context import H_I
        from ..nodes.interpreter import evaluate_materials
        from ..nodes.shading import normal_rows
        index = np.asarray(index, np.int64)
        has = np.array([p is not None and "normal" in p.outputs for p in self.programs],
                       bool)
        rows = np.nonzero(has[index])[0] if len(index) else np.zeros(0, np.int64)
        if rows.size == 0:
            return ns
        T = self.shading()
        regs = evaluate_materials(T, index[rows], hits[rows])
        out = ns.copy()
        out[rows] = normal_rows(T, index[rows], regs, np.ascontiguousarray(ns[rows]),
                                np.ascontiguousarray(ng[rows]),
                                np.ascontiguousarray(hits[rows, H_I:H_I + 3]),
                                self.bump_correction[index[rows]])
        return out

    def emission_at(self, index, uv=None, hits=None) -> np.ndarray:
        """Emitted radiance (n, 3) of the hits' materials, textures evaluated."""
        return self.lookup("emission", index, uv, hits)

    def alpha_at(self, index, uv=None, hits=None) -> np.ndarray:
        """Coverage (n,) in [0, 1]: 1 - the probability that a ray passes through."""
        return np.clip(self.lookup("alpha", index, uv, hits), 0.0, 1.0)

    def base_color_at(self, index, uv=None, hits=None) -> np.ndarray:
        return self.lookup("base_color", index, uv, hits)

    def metallic_at(self, index, uv=None, hits=None) -> np.ndarray:
        return self.lookup("metallic", index, uv, hits)

    def roughness_at(self, index, uv=None, hits=None) -> np.ndarray:
        return self.lookup("roughness", index, uv, hits)

    def metal_color_at(self, index, base_color) -> np.ndarray:
        """The metal lobe's F0 per hit: the explicit metal colour, else the base colour
        (`base_color`, the per-hit value from `base_color_at`)."""
        index = np.asarray(index, dtype=np.int64)
        return np.where(self.has_metal_color[index][:, None], self.metal_color[index],
                        base_color)


def _require_finite(materials, name, arr):
    """Raise naming the first material whose parameter `name` (arr: one row per
    material) is NaN or infinite."""
    if not np.all(np.isfinite(arr)):
        bad = [m.name for m, row in zip(materials, arr.reshape(len(materials), -1))
               if not np.all(np.isfinite(row))]
        raise ValueError(f"material {bad[0]!r} has a non-finite {name}")
