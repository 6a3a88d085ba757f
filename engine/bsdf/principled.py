"""Blender's Principled BSDF as a mixture of lobes, evaluated for a batch of points.

Each point carries its own material parameters; a lobe is chosen per point with
probability proportional to an estimate of its albedo, and the mixture pdf is the
probability-weighted sum of the lobes' pdfs (used by multiple importance sampling).

`allowed` masks (n, 3) restrict sampling and the sampling pdf to the lobe kinds whose
bounce budget is not exhausted (Cycles' diffuse/glossy/transmission limits), while
`eval_f` always returns the whole BSDF: next-event estimation still sees every lobe.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import lambert
from .lobes import DIFFUSE, GLOSSY, TRANSMISSION


@dataclass
class BSDFSample:
    wi: np.ndarray        # (n, 3) local direction
    weight: np.ndarray    # (n, 3) f * |cos| / pdf (zero where sampling failed)
    pdf: np.ndarray       # (n,) mixture pdf over the allowed lobes (inf for delta lobes)
    kind: np.ndarray      # (n,) lobe kind (DIFFUSE, GLOSSY, TRANSMISSION)
    delta: np.ndarray     # (n,) bool: a perfectly specular choice (no MIS possible)
    valid: np.ndarray     # (n,) bool


class PrincipledBSDF:
    """The lobes DRT models so far: Lambertian diffuse from the base colour."""

    def __init__(self, base_color: np.ndarray, metallic: np.ndarray, transmission: np.ndarray):
        self.n = len(base_color)
        diffuse_w = (1.0 - np.clip(metallic, 0, 1)) * (1.0 - np.clip(transmission, 0, 1))
        self.diffuse_albedo = base_color * diffuse_w[:, None]
        # lobe weights for selection, one column per kind
        self.lobe_weight = np.zeros((self.n, 3))
        self.lobe_weight[:, DIFFUSE] = np.maximum(self.diffuse_albedo.max(axis=1), 0.0)

    @classmethod
    def from_materials(cls, table: "MaterialTable", index: np.ndarray) -> "PrincipledBSDF":
        return cls(table.base_color[index], table.metallic[index], table.transmission[index])

    def _selection(self, allowed):
        w = self.lobe_weight if allowed is None else self.lobe_weight * allowed
        total = w.sum(1, keepdims=True)
        return np.where(total > 0, w / np.where(total > 0, total, 1.0), 0.0)

    def eval_f(self, wo, wi):
        return lambert.eval_f(self.diffuse_albedo, wo, wi)

    def pdf(self, wo, wi, allowed=None):
        q = self._selection(allowed)
        return q[:, DIFFUSE] * lambert.pdf(wo, wi)

    def sample(self, wo, u_lobe, u_dir, allowed=None) -> BSDFSample:
        q = self._selection(allowed)
        kind = np.full(self.n, DIFFUSE, dtype=np.int64)
        wi = lambert.sample(wo, u_dir)
        pdf = self.pdf(wo, wi, allowed)
        f = self.eval_f(wo, wi)
        valid = (pdf > 0) & (q.sum(1) > 0) & (wo[:, 2] > 0)
        weight = np.where(valid[:, None], f * np.abs(wi[:, 2:3]) / np.where(valid, pdf, 1.0)[:, None], 0.0)
        return BSDFSample(wi, weight, pdf, kind, np.zeros(self.n, bool), valid)


class MaterialTable:
    """Scene materials as arrays, indexed by a hit's material id."""

    def __init__(self, materials):
        self.base_color = np.array([m.base_color[:3] for m in materials], dtype=np.float64)
        self.metallic = np.array([m.metallic for m in materials], dtype=np.float64)
        self.roughness = np.array([m.roughness for m in materials], dtype=np.float64)
        self.ior = np.array([m.ior for m in materials], dtype=np.float64)
        self.transmission = np.array([m.transmission for m in materials], dtype=np.float64)
        self.specular_ior_level = np.array([m.specular_ior_level for m in materials], np.float64)
        self.emission = np.array([m.emission[:3] for m in materials], dtype=np.float64)
        self.alpha = np.array([m.alpha for m in materials], dtype=np.float64)
        for name in ("base_color", "metallic", "roughness", "ior", "transmission", "emission"):
            if not np.all(np.isfinite(getattr(self, name))):
                bad = [m.name for m in materials
                       if not np.all(np.isfinite(np.asarray(getattr(m, name), dtype=float)))]
                raise ValueError(f"material {bad[0]!r} has a non-finite {name}")
        self.any_emission = bool((self.emission > 0).any())
