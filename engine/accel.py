"""Ray queries against the scene's triangles through Intel Embree (`embreex`).

embreex traces one ray at a time inside C with the GIL released, at a fixed tnear of 0
and time 0, with no instancing. So ray origins are offset by the caller
(`engine.surface.offset_origin`); batches can be split over threads; and motion is built
here from plain scenes:
- static geometry: one shared Embree scene in world space (the only one a scene without
  motion ever builds, so static scenes pay nothing for motion blur);
- each rigidly moving object: its own Embree scene in object space; every ray is moved
  into object space by the inverse of the object's transform at that ray's own time
  (the ray parameter t is unchanged by an affine map, so distances compare directly);
- each deforming object: one Embree scene per stratified time slice of the shutter,
  built from the vertex positions at the slice's middle; a ray is traced against the
  slice its time falls in (see `engine.motion.DeformMotion` for what that costs).
The nearest hit across all of them wins. Triangles get global ids in that order.

Precision: Embree takes float32. Triangles are uploaded once in float32; ray origins and
directions are rounded per query. Hit points are NOT taken from the float32 distance but
rebuilt in float64 from the hit's barycentrics (`engine.surface`).
"""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .motion import DeformMotion, RigidMotion, inverse3
from .scene import TriangleMesh

MISS = -1
_BIG = np.float32(1e30)
_MIN_SPLIT = 4096      # below this many rays, one thread is faster than two


def _embree_scene(positions: np.ndarray, triangles: np.ndarray):
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh as EmbreeMesh
    scene = rtcore_scene.EmbreeScene()
    EmbreeMesh(scene, np.ascontiguousarray(positions, dtype=np.float32),
               np.ascontiguousarray(triangles, dtype=np.int32))
    return scene


@dataclass
class Hits:
    t: np.ndarray          # (n,) float64, inf where missed
    prim: np.ndarray       # (n,) int64 global triangle id, -1 where missed
    u: np.ndarray          # (n,) float64 barycentric weight of vertex 1
    v: np.ndarray          # (n,) float64 barycentric weight of vertex 2

    @property
    def hit(self) -> np.ndarray:
        return self.prim >= 0


@dataclass
class MovingObject:
    mesh: TriangleMesh
    prim_offset: int
    scenes: list             # one Embree scene (rigid) or one per time slice (deform)
    slice_positions: list    # per slice world positions (deform only)

    @property
    def rigid(self) -> bool:
        return isinstance(self.mesh.motion, RigidMotion)


def _is_moving(mesh: TriangleMesh, time_enabled: bool) -> bool:
    if mesh.motion is None or not time_enabled:
        return False
    if isinstance(mesh.motion, RigidMotion):
        return not mesh.motion.is_static()
    return not np.all(mesh.motion.positions == mesh.motion.positions[0])


def _static_world_positions(mesh: TriangleMesh) -> np.ndarray:
    """World positions of a mesh traced as static (no motion, or motion blur off)."""
    if isinstance(mesh.motion, RigidMotion):
        m = mesh.motion.matrices[0] if mesh.motion.is_static() else mesh.motion.at(
            np.array([0.5]))[0]
        return mesh.positions @ m[:3, :3].T + m[:3, 3]
    if isinstance(mesh.motion, DeformMotion):
        return mesh.motion.positions_at(0.5)
    return mesh.positions


class Accelerator:
    """All triangles of a scene: static ones in one Embree scene, moving ones apart."""

    def __init__(self, meshes: list[TriangleMesh], threads: int = 0, time_enabled: bool = False):
        for m in meshes:
            if not np.all(np.isfinite(m.positions)):
                raise ValueError(f"mesh {m.name!r} has non-finite (NaN or Inf) vertex positions")
        static = [m for m in meshes if not _is_moving(m, time_enabled)]
        moving = [m for m in meshes if _is_moving(m, time_enabled)]
        self.ordered_meshes = static + moving          # the global triangle order
        positions, triangles, base = [], [], 0
        for m in static:
            positions.append(_static_world_positions(m))
            triangles.append(m.triangles.astype(np.int64) + base)
            base += len(m.positions)
        self.positions = np.concatenate(positions) if positions else np.zeros((0, 3))
        self.triangles = np.concatenate(triangles) if triangles else np.zeros((0, 3), np.int64)
        self.static_count = len(self.triangles)
        self.threads = threads or min(os.cpu_count() or 1, 8)
        self._pool = ThreadPoolExecutor(self.threads) if self.threads > 1 else None
        self._scene = _embree_scene(self.positions, self.triangles) if len(self.triangles) else None
        self.moving: list[MovingObject] = []
        offset = self.static_count
        for m in moving:
            if isinstance(m.motion, RigidMotion):
                obj = MovingObject(m, offset, [_embree_scene(m.positions, m.triangles)], [])
            else:
                slices = [m.motion.positions_at(t) for t in m.motion.slice_times()]
                obj = MovingObject(m, offset, [_embree_scene(p, m.triangles) for p in slices],
                                   slices)
            self.moving.append(obj)
            offset += len(m.triangles)
        self.total_triangles = offset
        # Rays traced per query kind (all threads), and an optional recorder: a list that
        # receives (query, origins, dirs, tmax) of every static-scene batch, so that a
        # benchmark can replay exactly the same rays through bare Embree.
        self.rays_traced = {"INTERSECT": 0, "OCCLUDED": 0}
        self.recorder = None
        self._count_lock = threading.Lock()
        self.scene_count = (self._scene is not None) + sum(len(o.scenes) for o in self.moving)

    def close(self):
        if self._pool is not None:
            self._pool.shutdown(wait=False)
            self._pool = None

    # -- raw queries -------------------------------------------------------------------
    def _run(self, scene, origins, dirs, tmax, query, output):
        o = np.ascontiguousarray(origins, dtype=np.float32)
        d = np.ascontiguousarray(dirs, dtype=np.float32)
        dist = np.ascontiguousarray(np.minimum(tmax, _BIG), dtype=np.float32)
        n = len(o)
        with self._count_lock:
            self.rays_traced[query] += n
            if self.recorder is not None and scene is self._scene:
                self.recorder.append((query, o, d, dist))
        if self._pool is None or n < _MIN_SPLIT:
            return [scene.run(o, d, dists=dist, query=query, output=output)]
        bounds = np.linspace(0, n, self.threads + 1).astype(int)
        futures = [self._pool.submit(scene.run, o[a:b], d[a:b], dist[a:b], query, output)
                   for a, b in zip(bounds[:-1], bounds[1:]) if b > a]
        return [f.result() for f in futures]

    def _intersect_scene(self, scene, origins, dirs, tmax):
        parts = self._run(scene, origins, dirs, tmax, "INTERSECT", 1)
        prim = np.concatenate([p["primID"] for p in parts]).astype(np.int64)
        t = np.concatenate([p["tfar"] for p in parts]).astype(np.float64)
        u = np.concatenate([p["u"] for p in parts]).astype(np.float64)
        v = np.concatenate([p["v"] for p in parts]).astype(np.float64)
        return t, prim, u, v

    # -- motion ------------------------------------------------------------------------
    @staticmethod
    def to_object_space(obj: MovingObject, origins, dirs, time):
        """Rays moved into a rigid object's space at each ray's own time."""
        m = obj.mesh.motion.at(time)
        inv = inverse3(m[:, :3, :3])
        o = np.einsum("nij,nj->ni", inv, origins - m[:, :3, 3])
        d = np.einsum("nij,nj->ni", inv, dirs)
        return o, d

    def _moving_groups(self, obj: MovingObject, time):
        """(scene, row indices) pairs: one for a rigid object, one per time slice else."""
        if obj.rigid:
            return [(obj.scenes[0], None)]
        sl = obj.mesh.motion.slice_of(time)
        return [(scene, np.nonzero(sl == s)[0]) for s, scene in enumerate(obj.scenes)]

    # -- public queries ----------------------------------------------------------------
    def intersect(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray,
                  time: np.ndarray | None = None) -> Hits:
        n = len(origins)
        t = np.full(n, np.inf)
        prim = np.full(n, MISS, np.int64)
        u, v = np.zeros(n), np.zeros(n)
        if n == 0:
            return Hits(t, prim, u, v)
        if self._scene is not None:
            t, prim, u, v = self._intersect_scene(self._scene, origins, dirs, tmax)
            t[prim < 0] = np.inf
        if self.moving:
            if time is None:
                raise ValueError("a scene with moving objects needs a time per ray")
            best = np.minimum(t, tmax)
            for obj in self.moving:
                for scene, rows in self._moving_groups(obj, time):
                    if rows is not None and rows.size == 0:
                        continue
                    sel = slice(None) if rows is None else rows
                    o, d = origins[sel], dirs[sel]
                    if obj.rigid:
                        o, d = self.to_object_space(obj, o, d, time[sel])
                    tt, pp, uu, vv = self._intersect_scene(scene, o, d, best[sel])
                    closer = (pp >= 0) & (tt < best[sel])
                    idx = np.arange(n)[sel][closer]
                    t[idx], prim[idx] = tt[closer], pp[closer] + obj.prim_offset
                    u[idx], v[idx] = uu[closer], vv[closer]
                    best[idx] = tt[closer]
        return Hits(t, prim, u, v)

    def occluded(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray,
                 time: np.ndarray | None = None) -> np.ndarray:
        """True where something lies on the segment [0, tmax) of each ray."""
        n = len(origins)
        blocked = np.zeros(n, dtype=bool)
        if n == 0:
            return blocked
        if self._scene is not None:
            blocked = np.concatenate(self._run(self._scene, origins, dirs, tmax,
                                               "OCCLUDED", None)) != MISS
        if self.moving:
            if time is None:
                raise ValueError("a scene with moving objects needs a time per ray")
            for obj in self.moving:
                for scene, rows in self._moving_groups(obj, time):
                    open_rows = np.nonzero(~blocked)[0] if rows is None else rows[~blocked[rows]]
                    if open_rows.size == 0:
                        continue
                    o, d = origins[open_rows], dirs[open_rows]
                    if obj.rigid:
                        o, d = self.to_object_space(obj, o, d, time[open_rows])
                    hit = np.concatenate(self._run(scene, o, d, tmax[open_rows], "OCCLUDED",
                                                   None)) != MISS
                    blocked[open_rows[hit]] = True
        return blocked
