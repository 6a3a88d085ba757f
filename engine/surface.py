"""Surface interactions: what a ray hit, rebuilt in float64, and safe ray origins.

Hit points come from the triangle's float64 vertices and Embree's barycentrics, so their
error is a few float32 ulps of the vertex coordinates whatever the ray length. A new ray
leaving the surface starts at the hit point pushed along the geometric normal, to the
side it leaves from, by an amount proportional to the magnitude of the coordinates
involved: that bounds the float32 rounding Embree applies to origins and triangles, so
there is no self-intersection (acne) and, the offset being relative, no leaking through
thin geometry at any scene scale from 1e-3 to 1e4.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .accel import Accelerator, Hits

# Relative offset: 2**-17 ~ 7.6e-6 of the coordinate magnitude, i.e. 64 float32 ulps,
# comfortably above Embree's watertight-test error and the float32 rounding of vertices
# and origins, and small enough not to skip geometry thinner than 1e-5 of the scene size.
RELATIVE_OFFSET = 2.0 ** -17


@dataclass
class SurfaceHit:
    position: np.ndarray         # (n, 3) float64
    geometric_normal: np.ndarray  # (n, 3) unit, facing the incoming ray's side
    shading_normal: np.ndarray   # (n, 3) unit, same hemisphere as geometric_normal
    front_facing: np.ndarray     # (n,) bool: the ray hit the triangle's front side
    material: np.ndarray         # (n,) int64 index into Scene.materials
    scale: np.ndarray            # (n,) float64 magnitude used for ray offsets
    uv: np.ndarray | None = None


class SurfaceBuilder:
    """Precomputes per-triangle data of an Accelerator's triangles."""

    def __init__(self, accel: Accelerator, meshes):
        self.accel = accel
        tri = accel.triangles
        p = accel.positions
        if len(tri):
            self.v0, self.v1, self.v2 = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
            n = np.cross(self.v1 - self.v0, self.v2 - self.v0)
            length = np.linalg.norm(n, axis=1)
            ok = length > 0
            n[ok] /= length[ok, None]
            n[~ok] = (0.0, 0.0, 1.0)                     # never hit by Embree anyway
            self.normal = n
            self.tri_scale = np.max(np.abs(np.stack([self.v0, self.v1, self.v2], 1)), axis=(1, 2))
        self.material = np.concatenate([m.material_indices for m in meshes]).astype(np.int64) \
            if meshes else np.zeros(0, np.int64)
        has_normals = any(m.corner_normals is not None for m in meshes)
        self.corner_normals = None
        if has_normals:
            parts = []
            for m in meshes:
                if m.corner_normals is not None:
                    parts.append(np.asarray(m.corner_normals, np.float32).reshape(-1, 3, 3))
                else:
                    parts.append(None)
            fill = []
            offset = 0
            for m, part in zip(meshes, parts):
                if part is None:
                    t = len(m.triangles)
                    flat = self.normal[offset:offset + t].astype(np.float32)
                    part = np.repeat(flat[:, None, :], 3, axis=1)
                fill.append(part)
                offset += len(m.triangles)
            self.corner_normals = np.concatenate(fill)

    def build(self, hits: Hits, index: np.ndarray, ray_dirs: np.ndarray) -> SurfaceHit:
        """Interactions for the rays `index` (which must all have hit)."""
        prim = hits.prim[index]
        u = hits.u[index][:, None]
        v = hits.v[index][:, None]
        w = 1.0 - u - v
        pos = w * self.v0[prim] + u * self.v1[prim] + v * self.v2[prim]
        ng = self.normal[prim]
        d = ray_dirs[index]
        front = (ng * d).sum(1) < 0.0
        sign = np.where(front, 1.0, -1.0)[:, None]
        ng_f = ng * sign
        if self.corner_normals is not None:
            cn = self.corner_normals[prim].astype(np.float64)
            ns = w * cn[:, 0] + u * cn[:, 1] + v * cn[:, 2]
            length = np.linalg.norm(ns, axis=1, keepdims=True)
            ns = np.where(length > 1e-12, ns / np.maximum(length, 1e-300), ng)
            ns = ns * sign
            # A shading normal on the far side of the geometric one (possible with
            # strongly bent custom normals) is replaced by the geometric normal.
            bad = (ns * ng_f).sum(1) <= 0.0
            ns[bad] = ng_f[bad]
        else:
            ns = ng_f
        scale = np.maximum(np.max(np.abs(pos), axis=1), self.tri_scale[prim])
        return SurfaceHit(pos, ng_f, ns, front, self.material[prim], scale)


def offset_origin(position: np.ndarray, normal: np.ndarray, scale: np.ndarray,
                  direction: np.ndarray) -> np.ndarray:
    """Move origins off the surface to the side `direction` leaves towards."""
    side = np.where((normal * direction).sum(1) >= 0.0, 1.0, -1.0)[:, None]
    eps = (RELATIVE_OFFSET * np.maximum(scale, 1e-30))[:, None]
    return position + normal * (eps * side)
