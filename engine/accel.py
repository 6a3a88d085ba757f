"""Ray queries against the scene's triangles through Intel Embree (`embreex`).

embreex traces one ray at a time inside C with the GIL released, at a fixed tnear of 0
and time 0. So ray origins are offset by the caller (`engine.surface.offset_origin`), and
batches are split over threads here, which scales with cores because the GIL is free
while Embree runs.

Precision: Embree takes float32. Triangles are uploaded once in float32; ray origins and
directions are rounded per query. Hit points are NOT taken from the float32 distance but
rebuilt in float64 from the hit's barycentrics (`engine.surface`), so their error is that
of the float32 triangle, not of the ray distance.
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .scene import TriangleMesh

MISS = -1
_BIG = np.float32(1e30)
_MIN_SPLIT = 4096      # below this many rays, one thread is faster than two


def _embree():
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh as EmbreeMesh
    return rtcore_scene, EmbreeMesh


@dataclass
class Hits:
    t: np.ndarray          # (n,) float64, inf where missed
    prim: np.ndarray       # (n,) int64 global triangle id, -1 where missed
    u: np.ndarray          # (n,) float64 barycentric weight of vertex 1
    v: np.ndarray          # (n,) float64 barycentric weight of vertex 2

    @property
    def hit(self) -> np.ndarray:
        return self.prim >= 0


class Accelerator:
    """All static triangles of a scene in one Embree scene."""

    def __init__(self, meshes: list[TriangleMesh], threads: int = 0):
        positions, triangles, offsets = [], [], [0]
        base = 0
        for m in meshes:
            if not np.all(np.isfinite(m.positions)):
                raise ValueError(f"mesh {m.name!r} has non-finite (NaN or Inf) vertex positions")
            positions.append(m.positions)
            triangles.append(m.triangles.astype(np.int64) + base)
            base += len(m.positions)
            offsets.append(offsets[-1] + len(m.triangles))
        self.positions = np.concatenate(positions) if positions else np.zeros((0, 3))
        self.triangles = np.concatenate(triangles) if triangles else np.zeros((0, 3), np.int64)
        self.mesh_offsets = np.asarray(offsets, dtype=np.int64)
        self.threads = threads or min(os.cpu_count() or 1, 8)
        self._scene = None
        self._pool = ThreadPoolExecutor(self.threads) if self.threads > 1 else None
        if len(self.triangles):
            rtcore_scene, EmbreeMesh = _embree()
            self._scene = rtcore_scene.EmbreeScene()
            EmbreeMesh(self._scene, self.positions.astype(np.float32),
                       self.triangles.astype(np.int32))

    def close(self):
        if self._pool is not None:
            self._pool.shutdown(wait=False)
            self._pool = None

    def _run(self, origins, dirs, tmax, query, output):
        o = np.ascontiguousarray(origins, dtype=np.float32)
        d = np.ascontiguousarray(dirs, dtype=np.float32)
        dist = np.ascontiguousarray(np.minimum(tmax, _BIG), dtype=np.float32)
        n = len(o)
        if self._pool is None or n < _MIN_SPLIT:
            return [self._scene.run(o, d, dists=dist, query=query, output=output)]
        bounds = np.linspace(0, n, self.threads + 1).astype(int)
        futures = [self._pool.submit(self._scene.run, o[a:b], d[a:b], dist[a:b], query, output)
                   for a, b in zip(bounds[:-1], bounds[1:]) if b > a]
        return [f.result() for f in futures]

    def intersect(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray) -> Hits:
        n = len(origins)
        if self._scene is None or n == 0:
            return Hits(np.full(n, np.inf), np.full(n, MISS, np.int64), np.zeros(n), np.zeros(n))
        parts = self._run(origins, dirs, tmax, "INTERSECT", 1)
        prim = np.concatenate([p["primID"] for p in parts]).astype(np.int64)
        t = np.concatenate([p["tfar"] for p in parts]).astype(np.float64)
        u = np.concatenate([p["u"] for p in parts]).astype(np.float64)
        v = np.concatenate([p["v"] for p in parts]).astype(np.float64)
        missed = prim < 0
        t[missed] = np.inf
        return Hits(t, prim, u, v)

    def occluded(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray) -> np.ndarray:
        """True where something lies on the segment [0, tmax) of each ray."""
        n = len(origins)
        if self._scene is None or n == 0:
            return np.zeros(n, dtype=bool)
        parts = self._run(origins, dirs, tmax, "OCCLUDED", None)
        return np.concatenate(parts) != MISS
