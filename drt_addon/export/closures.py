"""Closures as the exporter reads a shader tree (Cycles' meaning, kernel/svm/closure.h)
and their reduction to one engine Material: `_Comp` is one BSDF closure as Principled
parameters, `_Closure` a weighted set of them with transparency and emission; `_reduce`
mixes a set into one Principled parameter set (see export/materials.py's docstring for
what is exact and what is approximated)."""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..engine_link import engine
from .closure_layers import (BLACK, HAIR_PARTS, LAYER_FIELDS, WHITE,  # noqa: F401
                             _Layers, _blend_layers)                   # (re-exported)
from .material_params import _is_tex, _lin, _mean, _plain, _same, _scale
from .nodes import anisotropy


@dataclass
class _Comp:
    """One BSDF closure as Principled parameters (Params; see the module docstring)."""
    base: object = (0.8, 0.8, 0.8)
    metallic: object = 0.0
    transmission: float = 0.0
    roughness: object = 0.5
    ior: float = 1.5
    spec: float = 0.5
    metal_color: object = None      # None: the base colour (Principled)
    metal_fresnel: str = "SCHLICK"  # 'CONSTANT': a Glossy BSDF's (Material.metal_fresnel)
    specular_tint: tuple = WHITE    # Principled's, the metal lobe's F82 tint
    glass_color: object = None      # None: sqrt(base colour) per crossing (Principled)
    glass_reflect: object = None    # the glass reflection's tint (a Glass BSDF's Color;
    #                                 None: white, Principled's)
    distribution: str = "MULTI_GGX"  # 'MULTI_GGX', 'GGX' or 'BECKMANN' (glossy_model)
    layers: object = None           # a _Layers: coat, sheen, translucency (None: none)
    refraction_only: bool = False   # the glass lobe does not reflect (Refraction BSDF)
    subsurface: object = None       # nodes/subsurface.Subsurface (None: none)
    diffuse_roughness: float = 0.0  # Oren-Nayar sigma of the diffuse lobe (0: Lambert)
    anisotropy: object = None       # nodes/anisotropy.Anisotropy of the metal and specular
    #                                 lobes (None: isotropic)
    thin_film: object = None        # (thickness nm, IOR) of a Thin Film on the specular,
    #                                 metal and glass lobes (None: none)

    def glossy_weight(self):
        """Mean weight of the lobes the distribution shapes (metal, glass, specular)."""
        m, g, b = self.weights()
        return m + g + (b if self.spec > 0 else 0.0)

    def weights(self):
        """Mean lobe weights (metal, glass, dielectric base) of this closure."""
        m = float(np.clip(_mean(self.metallic), 0.0, 1.0))
        t = float(np.clip(self.transmission, 0.0, 1.0))
        return m, (1.0 - m) * t, (1.0 - m) * (1.0 - t)


NULL_COMP = _Comp(base=BLACK, spec=0.0)     # absorbs: an Emission shader's "no BSDF"

@dataclass
class _Closure:
    comps: list = field(default_factory=list)      # [(weight, _Comp)]
    t_weight: float = 0.0                            # transparent closure weight
    t_color: tuple = BLACK                           # sum of weight x transparent colour
    emission: object = BLACK                         # expected emitted radiance (Param)
    alpha_texture: object = None                     # a lone Principled's textured Alpha
    mix: object = None     # (A, B, Fac Value): a Mix Shader whose Fac varies per hit; the
    #                        fields above are then its mixture at the Fac's average
    h_weight: float = 0.0                            # Holdout closure weight
    plain_emission: bool = False   # some of its emission is an Emission shader's, which
    #                                no coat or sheen dims (Material.emission_under_layers)

    def scaled(self, f, ctx):
        if self.alpha_texture is not None and f != 1.0:
            ctx.issue("a textured Alpha inside a Mix/Add Shader is replaced by its average")
            c = self._alpha_to_constant()
            return c.scaled(f, ctx)
        return _Closure([(w * f, c) for w, c in self.comps], self.t_weight * f,
                        _plain(np.asarray(self.t_color) * f), _scale(self.emission, f),
                        self.alpha_texture, h_weight=self.h_weight * f,
                        plain_emission=self.plain_emission)

    def _alpha_to_constant(self):
        a = float(np.clip(self.alpha_texture.mean(), 0.0, 1.0))
        return _Closure([(w * a, c) for w, c in self.comps], self.t_weight + (1.0 - a),
                        _plain(np.asarray(self.t_color) + (1.0 - a)), self.emission,
                        h_weight=self.h_weight * a, plain_emission=self.plain_emission)

    def is_emission_only(self):
        return (all(c is NULL_COMP for _, c in self.comps) and self.t_weight == 0
                and bool(self.comps))


def _sum(a: _Closure, b: _Closure, ctx) -> _Closure:
    for c in (a, b):
        if c.alpha_texture is not None:
            ctx.issue("a textured Alpha inside a Mix/Add Shader is replaced by its average")
    a = a._alpha_to_constant() if a.alpha_texture is not None else a
    b = b._alpha_to_constant() if b.alpha_texture is not None else b
    return _Closure(a.comps + b.comps, a.t_weight + b.t_weight,
                    _plain(np.asarray(a.t_color) + np.asarray(b.t_color)),
                    _lin([(1.0, a.emission), (1.0, b.emission)], ctx, "emission"),
                    h_weight=a.h_weight + b.h_weight,
                    plain_emission=a.plain_emission or b.plain_emission)


def _reduce(cl: _Closure, ctx, name) -> "engine.Material":
    """One Material from a closure set (see the module docstring)."""
    W = float(sum(w for w, _ in cl.comps))
    T = float(cl.t_weight)
    H = float(cl.h_weight)
    total = W + T + H
    if total <= 0.0:
        # Nothing but emission can come out (e.g. every weight mixed to zero).
        return engine.Material(name, BLACK, specular_ior_level=0.0,
                               emission=tuple(_mean(cl.emission)))
    # A Holdout's weight H (Cycles: a hole of H in the camera's alpha, no light): the
    # opaque part (alpha) holds it, and a hit there is a Holdout with probability
    # holdout_weight, else shades the BSDFs (their weights over W); so a hit is
    # transparent, a hole and shaded with probabilities T, H and W over the total.
    alpha = (W + H) / total
    holdout = H / (W + H) if W + H > 0.0 else 0.0
    t_color = _plain(np.asarray(cl.t_color) * (total / T)) if T > 0 else WHITE
    if W <= 0.0 and H > 0.0:
        if max(_mean(cl.emission)) > 0:
            ctx.issue("emission on a Holdout mixed with no BSDF is not rendered")
        return engine.Material(name, BLACK, specular_ior_level=0.0, alpha=alpha,
                               transparent_color=t_color, holdout_weight=1.0)
    if W <= 0.0:
        if max(_mean(cl.emission)) > 0:
            ctx.issue("emission on a fully transparent shader is not rendered")
        return engine.Material(name, BLACK, specular_ior_level=0.0, alpha=0.0,
                               transparent_color=t_color)
    comps = [(w / W, c) for w, c in cl.comps if w > 0]
    p = _blend(comps, ctx)
    if abs(total - 1.0) > 1e-9:
        # closures summed past 1 (Add Shader): the opaque part keeps its full weight
        for k in ("base", "metal_color", "glass_color"):
            if p[k] is not None:
                p[k] = _scale(p[k], total)
        if p["layers"] is not None:
            L = p["layers"] = replace(p["layers"])
            L.coat_weight, L.sheen_weight = L.coat_weight * total, L.sheen_weight * total
            L.translucent_color = _scale(L.translucent_color, total)
            for part in HAIR_PARTS:
                setattr(L, part, _scale(getattr(L, part), total))
            if L.principled_hair is not None:
                L.principled_hair = L.principled_hair.scaled(total)
    # emitted by the shaded part (probability W / total)
    emission = _scale(cl.emission, total / W)
    alpha_tex = cl.alpha_texture
    if alpha_tex is not None:
        alpha = 1.0
    m = engine.Material(name)
    _set(m, "base_color", p["base"])
    _set(m, "metallic", p["metallic"])
    _set(m, "roughness", p["roughness"])
    m.diffuse_roughness = p["diffuse_roughness"]
    if p["thin_film"] is not None:
        m.thin_film_thickness, m.thin_film_ior = p["thin_film"]
    _set(m, "emission", emission)
    m.emission_under_layers = not cl.plain_emission
    m.ior = float(p["ior"])
    m.transmission = float(p["transmission"])
    m.glossy_model = p["distribution"]
    m.specular_ior_level = float(p["spec"])
    if p["metal_color"] is not None:
        mc = p["metal_color"]
        if _is_tex(mc):
            ctx.issue("the metal colour is textured and differs from the base colour; "
                      "DRT uses its average")
            mc = mc.mean()
        m.metal_color = tuple(mc)
    if p["glass_color"] is not None:
        m.glass_color = tuple(_mean(p["glass_color"]))
    m.glass_reflection_tint = tuple(float(x) for x in p["glass_reflect"])
    m.refraction_only = bool(p["refraction_only"])
    sss = p["subsurface"]
    if sss is not None and sss.weight > 0:
        m.subsurface_weight = float(sss.weight)
        m.subsurface_radius = tuple(float(x) for x in sss.radius)
        m.subsurface_anisotropy = float(sss.anisotropy)
        m.subsurface_ior = float(sss.ior)
        m.subsurface_alpha = None if sss.alpha is None else float(sss.alpha)
        m.subsurface_method = sss.method
    m.metal_fresnel = p["metal_fresnel"]
    anisotropy.apply(m, p["anisotropy"], program_outputs(m))
    m.specular_tint = tuple(p["specular_tint"])
    if p["layers"] is not None:
        for k in LAYER_FIELDS:
            v = getattr(p["layers"], k)
            if _is_tex(v):               # per hit (a Translucent BSDF's colour)
                program_outputs(m)[k] = v.value
                v = tuple(float(x) for x in v.mean())
            setattr(m, k, tuple(float(x) for x in v) if isinstance(v, tuple) else v)
        for k, v in (p["layers"].principled_hair_programs or {}).items():
            program_outputs(m)[k] = v.value       # per hit (hair_chiang's colour, Melanin)
    m.alpha = float(alpha)
    m.transparent_color = tuple(t_color)
    m.holdout_weight = float(holdout)
    if alpha_tex is not None:
        # a per-hit Alpha is an output of the material's program (the tracer clips it
        # to [0, 1] per hit); its plain value is the clipped average
        _set(m, "alpha", alpha_tex)
        m.alpha = float(np.clip(m.alpha, 0.0, 1.0))
    return m


def program_outputs(m) -> dict:
    """The program outputs collected for engine Material m ({OUTPUTS name: Value})."""
    if not hasattr(m, "_program_outputs"):
        m._program_outputs = {}
    return m._program_outputs


def _set(m, attr, value):
    """Set a Material's parameter: a plain value, or a per-hit one (a NodeParam), which
    becomes an output of the material's program (`program_outputs`, collected by
    export_material) with its average as the plain value."""
    if _is_tex(value):
        program_outputs(m)[attr] = value.value
        mean = value.mean()
        setattr(m, attr, tuple(mean) if isinstance(mean, tuple) else float(mean))
    else:
        setattr(m, attr, tuple(value) if isinstance(value, tuple) else float(value))


def _blend_subsurface(lw, Wb, ctx):
    """The subsurface scattering of a mixture [(c, comp, metal, glass, base weights)]:
    its share of the mixed diffuse base is the closures' shares weighted by their base
    weights; its parameters those of the closure that scatters most (reported when they
    differ)."""
    parts = [(c * b * comp.subsurface.weight, comp.subsurface) for c, comp, _, _, b in lw
             if comp.subsurface is not None and c * b > 0]
    if not parts or Wb <= 0:
        return None
    main = max(parts, key=lambda x: x[0])[1]
    if len({(s.radius, s.anisotropy, s.ior, s.alpha, s.method) for _, s in parts}) > 1:
        ctx.issue("mixed shaders scatter below the surface with different parameters; DRT "
                  "uses those of the one that scatters most")
    return replace(main, weight=float(min(sum(w for w, _ in parts) / Wb, 1.0)))


def _blend(comps, ctx) -> dict:
    """Principled parameters of a convex combination [(c_i, _Comp)] of closures."""
    if len(comps) == 1:
        c = comps[0][1]
        return dict(base=c.base, metallic=c.metallic, transmission=c.transmission,
                    roughness=c.roughness, ior=c.ior, spec=c.spec,
                    metal_color=None if c.metal_color is None or _same(c.metal_color, c.base)
                    else c.metal_color,
                    glass_color=c.glass_color,
                    glass_reflect=c.glass_reflect if c.glass_reflect is not None else WHITE,
                    distribution=c.distribution, layers=c.layers, refraction_only=c.refraction_only,
                    metal_fresnel=c.metal_fresnel, specular_tint=c.specular_tint,
                    subsurface=c.subsurface, diffuse_roughness=c.diffuse_roughness,
                    anisotropy=c.anisotropy, thin_film=c.thin_film)
    lw = [(c, comp, *comp.weights()) for c, comp in comps]
    Wm = sum(c * m for c, _, m, _, _ in lw)
    Wg = sum(c * g for c, _, _, g, _ in lw)
    Wb = sum(c * b for c, _, _, _, b in lw)
    metallic = _lin([(c, comp.metallic) for c, comp in comps], ctx, "metallic")
    transmission = Wg / (1.0 - Wm) if Wm < 1.0 - 1e-12 else 0.0
    metal_cols = [(c * m, comp.metal_color if comp.metal_color is not None else comp.base)
                  for c, comp, m, _, _ in lw]
    metal_avg = _scale(_lin(metal_cols, ctx, "metal colour"), 1.0 / Wm) if Wm > 0 else None
    if Wb > 0:
        base = _scale(_lin([(c * b, comp.base) for c, comp, _, _, b in lw], ctx, "base colour"),
                      1.0 / Wb)
    elif Wm > 0:
        base = metal_avg
    else:
        base = _scale(_lin([(c * g, comp.base) for c, comp, _, g, _ in lw], ctx,
                           "base colour"), 1.0 / max(Wg, 1e-300))
    metal_color = None
    if Wm > 0 and not _same(metal_avg, base):
        metal_color = metal_avg
    glass_color = None
    if Wg > 0:
        principled = all(comp.glass_color is None and _same(comp.base, base)
                         for _, comp, _, g, _ in lw if g > 0)
        if not principled:
            tints = [(c * g, np.asarray(comp.glass_color) if comp.glass_color is not None
                      else np.sqrt(np.clip(np.asarray(_mean(comp.base)), 0.0, 1.0)))
                     for c, comp, _, g, _ in lw if g > 0]
            glass_color = _plain(sum(w * t for w, t in tints) / Wg)
    glass_reflect = WHITE
    if Wg > 0 and any(comp.glass_reflect is not None for _, comp, _, g, _ in lw if g > 0):
        glass_reflect = _plain(sum(c * g * np.asarray(comp.glass_reflect if comp.glass_reflect
                                                       is not None else WHITE, float)
                                   for c, comp, _, g, _ in lw if g > 0) / Wg)
    # the dielectric base lobe's specular layer: level weighted by the base lobes
    spec = (sum(c * b * comp.spec for c, comp, _, _, b in lw) / Wb) if Wb > 0 else 0.5
    # roughness and IOR: weighted by the lobes that use them
    rough_w = [(c * (m + g + (b if comp.spec > 0 else 0.0)), comp) for c, comp, m, g, b in lw]
    total_r = sum(w for w, _ in rough_w)
    if total_r > 0:
        roughness = _scale(_lin([(w, comp.roughness) for w, comp in rough_w], ctx,
                                "roughness"), 1.0 / total_r)
    else:
        roughness = 0.5
    ior_w = [(c * (g + (b if comp.spec > 0 else 0.0)), comp.ior) for c, comp, m, g, b in lw]
    total_i = sum(w for w, _ in ior_w)
    iors = {round(i, 6) for w, i in ior_w if w > 0}
    if len(iors) > 1:
        ctx.issue("closures with different IORs are mixed; DRT uses their weighted mean")
    ior = sum(w * i for w, i in ior_w) / total_i if total_i > 0 else 1.5
    if Wb > 0 and Wm > 0 and not _same(metal_avg, base):
        pass   # exact: the metal lobe keeps its own colour (Material.metal_color)
    # the microfacet distribution: the one of the closure with the most glossy weight
    glossy = [(c * comp.glossy_weight(), comp.distribution) for c, comp in comps]
    distribution = max(glossy, key=lambda x: x[0])[1]
    if len({d for w, d in glossy if w > 0}) > 1:
        ctx.issue(f"closures with different microfacet distributions are mixed; DRT uses "
                  f"{distribution} for all")
    # the metal lobe's Fresnel: that of the closure with the most metal weight
    metal_fresnel, specular_tint = max(
        ((c * m, (comp.metal_fresnel, comp.specular_tint)) for c, comp, m, _, _ in lw),
        key=lambda x: x[0])[1]
    if len({comp.metal_fresnel for c, comp, m, _, _ in lw if c * m > 0}) > 1:
        ctx.issue(f"a Glossy BSDF and a Principled metal are mixed; DRT gives both the "
                  f"{'Glossy' if metal_fresnel == 'CONSTANT' else 'Principled'} one's "
                  f"Fresnel")
    refr = {comp.refraction_only for _, comp, _, g, _ in lw if g > 0}
    if len(refr) > 1:
        ctx.issue("a Refraction BSDF is mixed with a glass; DRT renders both as glass")
    return dict(base=base, metallic=metallic, transmission=float(np.clip(transmission, 0, 1)),
                roughness=roughness, ior=ior, spec=spec, metal_color=metal_color,
                glass_color=glass_color, glass_reflect=glass_reflect,
                distribution=distribution,
                layers=_blend_layers(comps, ctx), refraction_only=refr == {True},
                metal_fresnel=metal_fresnel, specular_tint=specular_tint,
                subsurface=_blend_subsurface(lw, Wb, ctx),
                diffuse_roughness=_diffuse_roughness(lw, Wb, ctx),
                anisotropy=anisotropy.blend(comps, ctx), thin_film=_thin_film(lw, ctx))


def _thin_film(lw, ctx):
    """The Thin Film of the mixed closures' specular, metal and glass lobes: that of the
    closure with the most of their weight (reported if they differ)."""
    terms = [(c * (m + g + (b if comp.spec > 0 else 0.0)), comp.thin_film)
             for c, comp, m, g, b in lw]
    films = {f for w, f in terms if w > 0}
    if len(films) > 1:
        ctx.issue("mixed shaders have different thin films; DRT gives all the film of the "
                  "one that reflects most")
    return max(terms, key=lambda x: x[0])[1] if terms else None


def _diffuse_roughness(lw, Wb, ctx) -> float:
    """The mixed diffuse lobes' roughness, weighted by them (reported if they differ)."""
    terms = [(c * b, comp.diffuse_roughness) for c, comp, _, _, b in lw if c * b > 0]
    if len({round(r, 6) for _, r in terms}) > 1:
        ctx.issue("mixed diffuse lobes have different roughnesses; DRT uses their weighted "
                  "mean")
    return float(sum(w * r for w, r in terms) / Wb) if Wb > 0 else 0.0
