"""Blender's Principled BSDF as a mixture of lobes, evaluated for a batch of points.

Composition (Blender 4.x manual, "Principled BSDF", and Cycles' layering; weights per
point, every lobe in the local shading frame):

  metal         weight  m                   GGX reflection, Schlick Fresnel, F0 = base colour
                                            (clamped to [0, 1])
  transmission  weight  (1 - m) t           dielectric interface with the material IOR:
                                            smooth (delta) if GGX alpha <= ~3e-4, else
                                            rough GGX (Walter et al. 2007); reflection is
                                            untinted, refraction tinted by sqrt(base colour)
                                            per crossing (Cycles' choice: a round trip
                                            through a closed object gives the base colour)
  specular      weight  (1 - m)(1 - t)      GGX reflection with exact dielectric Fresnel of
                                            an IOR adjusted by `specular_ior_level`:
                                            F0' = F0(ior) * 2 level (0.5 = plain IOR, 0 =
                                            no specular, 1 = twice F0), IOR' = IOR(F0')
  diffuse       weight  (1 - m)(1 - t)      Lambert with the base colour, under the specular
                        (1 - E_spec(wo))    layer: it gets only the energy the layer does not
                                            reflect, E_spec(wo) being that layer's albedo as
                                            Cycles estimates it (its albedo scaling, see
                                            `_layer_albedo`), so diffuse + specular <= 1 for
                                            base colour <= 1.

with m = metallic, t = transmission, GGX alpha = roughness^2 (clamped, see
`microfacet.ALPHA_MIN`). The weights sum to 1, and each part conserves energy, so the
whole does. Cycles' E_spec for GGX is the Fresnel reflectance averaged over the visible
normals, which ignores the energy the single-scattering lobe loses to masking, so a
rough single-scattering plastic reflects a little less than 1 in a white furnace, as in
Cycles; with Multiscatter GGX it is that times the compensated lobe's weight, and the
furnace is white again.

Distribution per point: single-scattering GGX (Blender's "GGX"), the same with Cycles'
multiple-scattering energy compensation (`multiscatter`, Blender's default "Multiscatter
GGX", multiscatter.py: the metal, specular and rough glass lobes scaled per wo by
1 + F_ms (1 - E(wo)) / E(wo), so that a white metal or glass keeps all the energy), or
the lecture's Blinn-Phong in the reflection lobes (`blinn_phong`, never compensated; its
diffuse gets 1 - DRT's own single-scattering albedo of a GGX layer, layer_albedo.py).

Not modelled (Cycles has them): subsurface, sheen, coat, specular tint/F82 tint (with
Blender's default white tint, Cycles' F82-tint metal reduces to Schlick), anisotropy,
thin film.

Sampling: a lobe is chosen per point with probability proportional to an estimate of its
albedo at wo; the mixture pdf is sum_i q_i pdf_i over the allowed lobes (the delta part
of a smooth glass has no density and reports pdf = inf, delta = True). `allowed` masks
(n, 3) over DIFFUSE/GLOSSY/TRANSMISSION restrict sampling and the sampling pdf to the lobe
kinds whose bounce budget is not exhausted (Cycles' diffuse/glossy/transmission limits;
glass reflection counts as GLOSSY, refraction as TRANSMISSION), while `eval_f` always
returns the whole BSDF: next-event estimation still sees every lobe.

Lobes whose weight is zero at every point of a batch are never evaluated or sampled
(`active`), so a batch of plain diffuse materials costs what Lambert alone costs.

Sides: the integrator flips the shading normal towards the incoming ray, so wo_z > 0.
Whether the ray arrives from inside the object (a back face) matters only to the glass
lobe: pass `front_facing` to `from_materials` (the relative IOR becomes 1/ior there).
Without it every hit is taken as a front face.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import dielectric, fresnel, lambert, reflection
from . import microfacet as mf
from . import multiscatter as ms
from .layer_albedo import specular_albedo
from .lobes import DIFFUSE, GLOSSY, TRANSMISSION
from .material_table import MaterialTable  # noqa: F401  (re-exported: engine.render, tests)
from ..warp import cosine_hemisphere


@dataclass
class BSDFSample:
    wi: np.ndarray        # (n, 3) local direction
    weight: np.ndarray    # (n, 3) f * |cos| / pdf (zero where sampling failed)
    pdf: np.ndarray       # (n,) mixture pdf over the allowed lobes (inf for delta lobes)
    kind: np.ndarray      # (n,) lobe kind (DIFFUSE, GLOSSY, TRANSMISSION)
    delta: np.ndarray     # (n,) bool: a perfectly specular choice (no MIS possible)
    valid: np.ndarray     # (n,) bool


# Lobe indices of the mixture
L_DIFFUSE, L_SPECULAR, L_METAL, L_GLASS = 0, 1, 2, 3
LOBE_NAMES = ("diffuse", "specular", "metal", "glass")
# Lower bound of a present lobe's selection estimate, relative to its weight, so a lobe
# that reflects little at this wo (black metal at normal incidence) can still be sampled.
MIN_SELECTION = 0.02


# --- the mixture -----------------------------------------------------------------------

def _sub(a, rows):
    return a if rows is None else a[rows]


def _flag(a, rows):
    """A flag for all rows (a bool) or one per row (an array), on the rows `rows`."""
    return a if np.ndim(a) == 0 else a[rows]


class PrincipledBSDF:
    """Diffuse, dielectric specular, metal and glass lobes with Blender's weights."""

    def __init__(self, base_color, metallic, transmission, roughness=None, ior=None,
                 specular_ior_level=None, front_facing=None, blinn_phong=None,
                 multiscatter=None, filter_alpha=None):
        base_color = np.asarray(base_color, dtype=np.float64).reshape(-1, 3)
        n = self.n = len(base_color)

        def param(v, default):
            if v is None:
                return np.full(n, default, dtype=np.float64)
            return np.broadcast_to(np.asarray(v, dtype=np.float64), (n,)).copy()

        m = np.clip(param(metallic, 0.0), 0.0, 1.0)
        t = np.clip(param(transmission, 0.0), 0.0, 1.0)
        rough = np.clip(param(roughness, 0.5), 0.0, 1.0)
        ior = np.maximum(param(ior, 1.5), 1e-5)
        level = np.maximum(param(specular_ior_level, 0.5), 0.0)
        front = (np.ones(n, bool) if front_facing is None
                 else np.broadcast_to(np.asarray(front_facing, bool), (n,)))

        # Refraction also on the pairs the sampler never produces, as Cycles evaluates it
        # (engine/bsdf/dielectric.py's note); False (for all, or per row: an (n,) bool
        # array): Walter's BTDF and the sampler's own density (the chi-square tests, next-
        # event estimation towards a uniform world)
        self.as_cycles = True
        self.base = np.maximum(base_color, 0.0)         # Cycles: diffuse is not clamped
        self.base_clamped = np.minimum(self.base, 1.0)  # ... metal F0 and glass tint are
        # GGX alpha of the material, from which the energy compensation and the layering
        # are computed, and of the lobes, which Filter Glossy may widen afterwards as
        # Cycles' closure blur does (`filter_alpha`: a per-point lower bound, 0 = none)
        self.material_alpha = mf.clamp_alpha(rough * rough)
        self.alpha = (self.material_alpha if filter_alpha is None else
                      mf.clamp_alpha(np.maximum(self.material_alpha, param(filter_alpha, 0.0))))
        # Reflection lobes with the lecture's Blinn-Phong distribution instead of GGX, at
        # the exponent matching alpha (Walter et al. 2007: n = 2 / alpha^2 - 2).
        self.blinn = (np.zeros(n, bool) if blinn_phong is None
                      else np.broadcast_to(np.asarray(blinn_phong, bool), (n,)).copy())
        self.any_blinn = bool(self.blinn.any())
        self.exponent = np.maximum(2.0 / (self.alpha * self.alpha) - 2.0, 0.0)
        # Cycles' "Multiscatter GGX": energy compensation of the GGX lobes (not of
        # Blinn-Phong ones), see multiscatter.py
        self.multiscatter = (np.zeros(n, bool) if multiscatter is None else
                             np.broadcast_to(np.asarray(multiscatter, bool), (n,)) & ~self.blinn)
        self.any_multiscatter = bool(self.multiscatter.any())
        base_w = (1.0 - m) * (1.0 - t)
        # specular layer: F0 scaled by 2 * level, IOR recomputed from it
        f0 = fresnel.f0_from_ior(ior) * 2.0 * level
        eta_s = fresnel.ior_from_f0(f0)
        eta_s = np.where(ior < 1.0, 1.0 / eta_s, eta_s)
        self.eta_spec = np.where(level == 0.5, ior, eta_s)
        spec_on = (f0 > 0) & (np.abs(self.eta_spec - 1.0) > 1e-7)
        self.eta_glass = np.where(front, ior, 1.0 / ior)
        self.glass_smooth = dielectric.is_smooth(self.alpha, self.eta_glass)
        self.tint_t = np.sqrt(self.base_clamped)
        self.diffuse_color = self.base * base_w[:, None]
        self.weight = np.stack([
            np.where(self.diffuse_color.max(1) > 0, base_w, 0.0),   # diffuse (scalar part)
            np.where(spec_on, base_w, 0.0),                         # specular
            m,                                                      # metal
            (1.0 - m) * t,                                          # glass
        ], axis=1)
        on = self.weight > 0
        self.active = on.any(0)                  # lobes present anywhere in the batch
        self._all_on = on.all(0)
        self._rows_on = [np.nonzero(on[:, k])[0] for k in range(4)]
        self._state_key = None
        self._state = None
        # the common case of a batch of plain diffuse surfaces takes Lambert's own path
        self.diffuse_only = bool(self.active[L_DIFFUSE] and not self.active[1:].any())

    @classmethod
    def from_materials(cls, table: "MaterialTable", index: np.ndarray,
                       front_facing=None, uv=None, filter_alpha=None,
                       hits=None) -> "PrincipledBSDF":
        """The BSDFs of hits on materials `index` (n,); uv (n, 2) are the hits' texture
        coordinates (`SurfaceHit.uv`), used where a material's base colour, metallic or
        roughness is textured; hits: the rows its shader programs read (None: from uv). Lobe colours that are not Principled's own (a Glossy BSDF's
        colour as the metal F0, a Glass BSDF's colour as the refraction tint) replace the
        ones derived from the base colour; the lobe maths is unchanged. filter_alpha (n,):
        Filter Glossy's lower bound on the lobes' GGX alpha at each hit (None: none)."""
        index = np.asarray(index, dtype=np.int64)
        base = table.base_color_at(index, uv, hits)
        bsdf = cls(base, table.metallic_at(index, uv, hits), table.transmission[index],
                   table.roughness_at(index, uv, hits), table.ior[index],
                   table.specular_ior_level[index], front_facing,
                   table.blinn_phong[index], table.multiscatter[index], filter_alpha)
        if table.has_metal_color.any():
            own = table.has_metal_color[index]
            if own.any():
                bsdf.base_clamped = np.where(own[:, None],
                                             np.clip(table.metal_color[index], 0.0, 1.0),
                                             bsdf.base_clamped)
        if table.has_glass_color.any():
            own = table.has_glass_color[index]
            if own.any():
                bsdf.tint_t = np.where(own[:, None], np.clip(table.glass_color[index], 0.0, 1.0),
                                       bsdf.tint_t)
        return bsdf

    @classmethod
    def lambertian(cls, base_color) -> "PrincipledBSDF":
        """A plain Lambertian BSDF (no specular layer): only the diffuse lobe is active,
        and `diffuse_only` is set, so every call takes Lambert's own code path."""
        n = len(base_color)
        return cls(base_color, np.zeros(n), np.zeros(n), specular_ior_level=np.zeros(n))

    # -- per-wo quantities ---------------------------------------------------------------
    def _wo_state(self, wo):
        """Albedo-dependent weights at wo: the diffuse colour under the specular layer,
        the lobe selection estimates (n, 5): diffuse, specular, metal, glass reflection,
        glass refraction, and the multiple-scattering factors (n, 8) (None without
        multiscatter rows): specular, metal (3), glass (3), and the GGX albedo E(wo) they
        were computed from. Cached for the last wo array seen (the integrator evaluates,
        computes pdfs and samples with one wo)."""
        if self._state_key is wo:
            return self._state
        n = self.n
        cos_o = np.clip(wo[:, 2], 0.0, 1.0)
        comp = self._compensation(wo, cos_o) if self.any_multiscatter else None
        est = np.zeros((n, 5))
        e_layer = np.zeros(n)         # the specular layer's albedo estimate
        if self.active[L_SPECULAR]:
            r = self._rows_on[L_SPECULAR]
            e_layer[r] = self._layer_albedo(r, cos_o, comp)
            est[r, 1] = self.weight[r, L_SPECULAR] * e_layer[r]
        diffuse = self.diffuse_color * (1.0 - np.minimum(e_layer, 1.0))[:, None]
        if self.active[L_DIFFUSE]:
            est[:, 0] = diffuse.max(1)
        if self.active[L_METAL]:
            r = self._rows_on[L_METAL]
            F = fresnel.schlick(self.base_clamped[r], cos_o[r])
            if comp is not None:
                F = F * comp[r, 1:4]
            est[r, 2] = self.weight[r, L_METAL] * F.max(1)
        if self.active[L_GLASS]:
            r = self._rows_on[L_GLASS]
            eta = self.eta_glass[r]
            F = fresnel.dielectric(wo[r, 2], eta)
            eta_rel = np.where(wo[r, 2] < 0, 1.0 / eta, eta)
            est[r, 3] = self.weight[r, L_GLASS] * F
            est[r, 4] = (self.weight[r, L_GLASS] * (1.0 - F) * self.tint_t[r].max(1)
                         / (eta_rel * eta_rel))
            if comp is not None:
                c = comp[r, 4:7].max(1)
                est[r, 3] = est[r, 3] * c
                est[r, 4] = est[r, 4] * c
        # floors so that every present lobe can be sampled
        floor = MIN_SELECTION * self.weight
        est[:, :3] = np.where(self.weight[:, :3] > 0, np.maximum(est[:, :3], floor[:, :3]), 0.0)
        est[:, 3] = np.where(self.weight[:, 3] > 0, np.maximum(est[:, 3], 0.5 * floor[:, 3]), 0.0)
        est[:, 4] = np.where(self.weight[:, 3] > 0, np.maximum(est[:, 4], 0.5 * floor[:, 3]), 0.0)
        self._state_key, self._state = wo, (diffuse, est, comp)
        return self._state

    def _layer_albedo(self, r, cos_o, comp):
        """The specular layer's albedo at wo as the diffuse below sees it, rows r: Cycles'
        estimate per distribution (multiscatter.py), `layer_reflectance` for GGX, that
        times E(wo) for Multiscatter GGX (with the compensation factor: the weight the
        compensation leaves on the closure), but never below the layer's actual
        single-scattering albedo (layer_albedo.py; times the factor), so the layering
        creates no energy where the estimate falls short (IOR < 1 near the critical
        angle). Blinn-Phong, which Cycles does not have: that actual albedo."""
        a = self.material_alpha[r]
        exact = specular_albedo(cos_o[r], a, self.eta_spec[r])
        e = ms.layer_reflectance(cos_o[r], a, self.eta_spec[r])
        if comp is not None:
            e = e * comp[r, 7]
        e = np.maximum(e, exact)
        if comp is not None:
            e = e * comp[r, 0]
        if self.any_blinn:
            b = np.nonzero(self.blinn[r])[0]
            e[b] = exact[b]
        return e

    def _compensation(self, wo, cos_o):
        """Multiple-scattering factors (n, 8) at wo (multiscatter.py): specular layer,
        metal (per channel), rough glass (per channel), and GGX's E(wo) (for the layer
        albedo); 1 elsewhere."""
        comp = np.ones((self.n, 8))
        on = self.weight > 0
        r = np.nonzero(self.multiscatter & (on[:, L_SPECULAR] | on[:, L_METAL]))[0]
        if len(r):
            E = ms.ggx_albedo(cos_o[r], self.material_alpha[r])
            E_avg = ms.ggx_albedo_avg(self.material_alpha[r])
            comp[r, 7] = E
            spec = on[r, L_SPECULAR]
            comp[r[spec], 0] = ms.compensation(E[spec], E_avg[spec],
                                               ms.dielectric_fresnel_avg(self.eta_spec[r[spec]]))
            metal = on[r, L_METAL]
            comp[r[metal], 1:4] = ms.compensation(
                E[metal][:, None], E_avg[metal][:, None],
                ms.schlick_fresnel_avg(self.base_clamped[r[metal]]))
        r = np.nonzero(self.multiscatter & on[:, L_GLASS] & ~self.glass_smooth)[0]
        if len(r):
            eta = self.eta_glass[r]
            eta_rel = np.where(wo[r, 2] < 0, 1.0 / eta, eta)
            c = np.minimum(np.abs(wo[r, 2]), 1.0)
            E = ms.glass_albedo(c, self.material_alpha[r], eta_rel)
            E_avg = ms.glass_albedo_avg(self.material_alpha[r], eta_rel)
            comp[r, 4:7] = ms.compensation(E[:, None], E_avg[:, None], self.tint_t[r])
        return comp

    def _selection(self, est, allowed):
        """Lobe probabilities (n, 4) and the glass lobe's allow flags."""
        if allowed is None:
            allowed = np.ones((len(est), 3), bool)
        allowed = np.asarray(allowed, bool)
        a_g, a_t = allowed[:, GLOSSY], allowed[:, TRANSMISSION]
        w = np.stack([est[:, 0] * allowed[:, DIFFUSE], est[:, 1] * a_g, est[:, 2] * a_g,
                      est[:, 3] * a_g + est[:, 4] * a_t], axis=1)
        total = w.sum(1, keepdims=True)
        q = np.where(total > 0, w / np.where(total > 0, total, 1.0), 0.0)
        return q, a_g, a_t

    def _lobe_rows(self, lobe, idx):
        """Rows of lobe `lobe` within the subset idx: (global rows, local rows), None = all."""
        if idx is None:
            if self._all_on[lobe]:
                return None, None
            r = self._rows_on[lobe]
            return r, r
        loc = np.nonzero(self.weight[idx, lobe] > 0)[0]
        if len(loc) == len(idx):
            return idx, None
        return idx[loc], loc

    # -- the reflection distribution: GGX, or Blinn-Phong where asked ----------------------
    def _reflection(self, g):
        """(alpha, exponent, blinn or None) of rows g (None = all) for reflection.py."""
        return (_sub(self.alpha, g), _sub(self.exponent, g),
                _sub(self.blinn, g) if self.any_blinn else None)

    # -- evaluation ----------------------------------------------------------------------
    def _eval(self, idx, wo, wi, diffuse, comp, allowed=None):
        """f of rows idx; `allowed` (len(wo), 3) keeps only the lobe kinds a sampled
        path may continue by (DIFFUSE, GLOSSY, TRANSMISSION), None all of them."""
        f = np.zeros((len(wo), 3))
        if allowed is None:
            allowed = np.ones((len(wo), 3), bool)
        keep = allowed.astype(np.float64)
        if self.active[L_DIFFUSE]:
            g, loc = self._lobe_rows(L_DIFFUSE, idx)
            if g is None or len(g):
                val = lambert.eval_f(_sub(diffuse, g), _sub(wo, loc), _sub(wi, loc)) \
                    * _sub(keep[:, 0:1], loc)
                if loc is None:
                    f += val
                else:
                    f[loc] += val
        for lobe in (L_SPECULAR, L_METAL):
            if not self.active[lobe]:
                continue
            g, loc = self._lobe_rows(lobe, idx)
            if g is not None and not len(g):
                continue
            o, i = _sub(wo, loc), _sub(wi, loc)
            base, h = reflection.eval_base(o, i, *self._reflection(g))
            cos_oh = np.clip((o * h).sum(1), 0.0, 1.0)
            if lobe == L_SPECULAR:
                F = fresnel.dielectric(cos_oh, _sub(self.eta_spec, g))[:, None]
            else:
                F = fresnel.schlick(_sub(self.base_clamped, g), cos_oh)
            val = F * (base * _sub(self.weight[:, lobe], g))[:, None] \
                * _sub(keep[:, 1:2], loc)
            if comp is not None:
                val = val * (_sub(comp[:, 0:1], g) if lobe == L_SPECULAR
                             else _sub(comp[:, 1:4], g))
            if loc is None:
                f += val
            else:
                f[loc] += val
        if self.active[L_GLASS]:
            g, loc = self._lobe_rows(L_GLASS, idx)
            if g is None or len(g):
                rough = ~_sub(self.glass_smooth, g)
                if rough.any():
                    rr = np.nonzero(rough)[0]
                    gr = rr if g is None else g[rr]
                    lr = rr if loc is None else loc[rr]
                    f_r, f_t = dielectric.rough_eval(wo[lr], wi[lr], self.eta_glass[gr],
                                                     self.alpha[gr],
                                                     _flag(self.as_cycles, gr))
                    val = (f_r[:, None] * keep[lr, 1:2]
                           + f_t[:, None] * self.tint_t[gr] * keep[lr, 2:3]) \
                        * self.weight[gr, L_GLASS][:, None]
                    if comp is not None:
                        val = val * comp[gr, 4:7]
                    f[lr] += val
        return f

    def eval_f(self, wo, wi, allowed=None):
        """The whole BSDF f(wo, wi) (n, 3) in 1/sr (delta parts excluded), or only the
        lobe kinds `allowed` (n, 3) keeps (what `sample`'s weight estimates)."""
        if self.diffuse_only:
            f = lambert.eval_f(self.diffuse_color, wo, wi)
            return f if allowed is None else f * allowed[:, 0:1]
        diffuse, _, comp = self._wo_state(wo)
        return self._eval(None, wo, wi, diffuse, comp, allowed)

    def _pdf(self, idx, wo, wi, q, a_g, a_t):
        """Mixture pdf on the subset idx; q, a_g, a_t already restricted to it."""
        p = np.zeros(len(wo))
        if self.active[L_DIFFUSE]:
            p += q[:, L_DIFFUSE] * lambert.pdf(wo, wi)
        if self.active[L_SPECULAR] or self.active[L_METAL]:
            q_refl = q[:, L_SPECULAR] + q[:, L_METAL]
            r = np.nonzero(q_refl > 0)[0]
            if len(r):
                g = r if idx is None else idx[r]
                p[r] += q_refl[r] * reflection.pdf(wo[r], wi[r], *self._reflection(g))
        if self.active[L_GLASS]:
            gl = q[:, L_GLASS] > 0
            gl &= ~_sub(self.glass_smooth, idx)
            r = np.nonzero(gl)[0]
            if len(r):
                g = r if idx is None else idx[r]
                p[r] += q[r, L_GLASS] * dielectric.rough_pdf(
                    wo[r], wi[r], self.eta_glass[g], self.alpha[g], a_g[r], a_t[r],
                    _flag(self.as_cycles, g))
        return p

    def pdf(self, wo, wi, allowed=None):
        """Mixture pdf (n,) in 1/sr of `sample` with the same `allowed` mask."""
        if self.diffuse_only:
            return np.where(self._diffuse_allowed(allowed), lambert.pdf(wo, wi), 0.0)
        _, est, _ = self._wo_state(wo)
        q, a_g, a_t = self._selection(est, allowed)
        return self._pdf(None, wo, wi, q, a_g, a_t)

    # -- sampling ------------------------------------------------------------------------
    def _diffuse_allowed(self, allowed):
        on = self.weight[:, L_DIFFUSE] > 0
        return on if allowed is None else on & np.asarray(allowed, bool)[:, DIFFUSE]

    def _sample_diffuse_only(self, wo, u_dir, allowed):
        wi = cosine_hemisphere(u_dir)
        pdf = np.where(self._diffuse_allowed(allowed), lambert.pdf(wo, wi), 0.0)
        ok = pdf > 0
        # f |cos| / pdf of a Lambertian lobe is its albedo
        weight = np.where(ok[:, None], self.diffuse_color, 0.0)
        return BSDFSample(wi, weight, pdf, np.full(self.n, DIFFUSE, dtype=np.int64),
                          np.zeros(self.n, bool), ok)

    def sample(self, wo, u_lobe, u_dir, allowed=None) -> BSDFSample:
        """Choose a lobe with u_lobe (n,), a direction with u_dir (n, 2) (the rest of
        u_lobe, rescaled, picks a glass reflection or refraction)."""
        if self.diffuse_only:
            return self._sample_diffuse_only(wo, u_dir, allowed)
        n = self.n
        diffuse, est, comp = self._wo_state(wo)
        q, a_g, a_t = self._selection(est, allowed)
        cdf = np.cumsum(q, axis=1)
        total = cdf[:, -1]
        lobe = (u_lobe[:, None] >= cdf[:, :3]).sum(1)
        lo = np.take_along_axis(np.concatenate([np.zeros((n, 1)), cdf], 1), lobe[:, None], 1)[:, 0]
        q_sel = np.take_along_axis(q, np.minimum(lobe, 3)[:, None], 1)[:, 0]
        u_re = np.clip((u_lobe - lo) / np.where(q_sel > 0, q_sel, 1.0), 0.0, 1.0 - 2.0 ** -53)

        wi = np.zeros((n, 3))
        wi[:, 2] = 1.0
        kind = np.full(n, DIFFUSE, dtype=np.int64)
        delta = np.zeros(n, bool)
        ok = (total > 0) & (q_sel > 0)
        weight = np.zeros((n, 3))
        pdf = np.zeros(n)

        r = np.nonzero(ok & (lobe == L_DIFFUSE))[0]
        if len(r):
            wi[r] = cosine_hemisphere(u_dir[r])
        r = np.nonzero(ok & ((lobe == L_SPECULAR) | (lobe == L_METAL)))[0]
        if len(r):
            w, v = reflection.sample(wo[r], u_dir[r], *self._reflection(r))
            wi[r] = w
            kind[r] = GLOSSY
            ok[r] &= v
        r = np.nonzero(ok & (lobe == L_GLASS))[0]
        if len(r):
            smooth = self.glass_smooth[r]
            rs, rr = r[smooth], r[~smooth]
            if len(rs):
                w, ws, refr, v = dielectric.smooth_sample(
                    wo[rs], self.eta_glass[rs], u_re[rs], a_g[rs], a_t[rs])
                wi[rs] = w
                kind[rs] = np.where(refr, TRANSMISSION, GLOSSY)
                ok[rs] &= v
                delta[rs] = True
                tint = np.where(refr[:, None], self.tint_t[rs], 1.0)
                weight[rs] = tint * (ws * self.weight[rs, L_GLASS]
                                     / np.where(v, q_sel[rs], 1.0))[:, None]
                pdf[rs] = np.inf
            if len(rr):
                w, _, refr, v, _ = dielectric.rough_sample(
                    wo[rr], self.eta_glass[rr], self.alpha[rr], u_re[rr], u_dir[rr],
                    a_g[rr], a_t[rr])
                wi[rr] = w
                kind[rr] = np.where(refr, TRANSMISSION, GLOSSY)
                ok[rr] &= v

        # non-delta choices: one-sample mixture estimator f |cos| / sum_j q_j pdf_j
        r = np.nonzero(ok & ~delta)[0]
        if len(r):
            # the allowed lobes only: a lobe past its bounce limit adds nothing
            f = self._eval(r, wo[r], wi[r], diffuse, comp,
                           None if allowed is None else allowed[r])
            p = self._pdf(r, wo[r], wi[r], q[r], a_g[r], a_t[r])
            good = (p > 0) & np.isfinite(p)
            weight[r] = np.where(good[:, None],
                                 f * (np.abs(wi[r, 2]) / np.where(good, p, 1.0))[:, None], 0.0)
            pdf[r] = np.where(good, p, 0.0)
            ok[r] &= good
        weight[~ok] = 0.0
        pdf[~ok] = 0.0
        delta &= ok
        return BSDFSample(wi, weight, pdf, kind, delta, ok)
