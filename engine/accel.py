"""Ray queries against the scene's triangles through Intel Embree's own C API
(`engine.embree`: scenes on shared NumPy buffers, queries in compiled kernels).

Batches of rays are traced by one compiled call each (`engine.embree.rays`), at tnear 0:
a ray that leaves a surface starts on it and names the primitive it leaves (`skip`),
which Embree's filter passes (engine.embree.self_hits); batches are split over threads
(every kernel releases the GIL). Everything is one Embree scene, in world
space relative to `center`:
- static triangles: one geometry (the only one a scene without motion or instances
  builds, so static scenes pay nothing for motion blur);
- each instanced mesh (engine.instancing): one Embree scene in object space, placed by
  one Embree instance array (one shared float32 buffer of the places' transforms);
- each rigidly moving object: its own Embree scene in object space, placed by an Embree
  instance with one quaternion decomposition per motion step, which Embree interpolates
  at each ray's time as engine.motion.RigidMotion.at does (translation and scale
  linearly, rotation spherically);
- each deforming object: a triangle geometry with one vertex buffer per motion step,
  which Embree interpolates linearly at each ray's time;
- hair (engine.curves): one round Catmull-Rom curve geometry of every strand, its
  segments' global ids right after the static triangles'.
Embree builds its motion hierarchies over the moving geometry itself (Cycles likewise
hands motion to Embree). Motion steps are evenly spaced over the shutter, as Embree
takes them (`evenly_spaced()` resamples others).

Primitives get global ids in the order static, hair, instanced, moving; a hit's Embree ids
(geometry, instance, element) map to its global triangle id and to `Hits.inst`, the
place's row in the object table (engine.surface; -1 for a triangle that is not an
instanced mesh's). Memory grows with the places, not with places x triangles.

All Embree scenes share one Embree device: one device per scene crashes Embree past
about a thousand scenes.

Precision: Embree takes float32. Triangles are converted once to float32 (one NumPy
operation into the buffer Embree shares); ray origins and directions are rounded per
ray. The static scene is uploaded relative to `center`, its median vertex, and every
ray's origin is moved by the same amount (in float64) before rounding: a scene far from
the world origin then keeps the float32 precision it would have at the origin
(tests/test_extremes_scale.py: the Cornell box moved by 1e6 renders as at the origin;
before, a box 1e5 from the origin lost 14% of its pixels to the z-test). Hit points are
NOT taken from the float32 distance but rebuilt in float64 from the hit's barycentrics
(`engine.surface`).
"""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .curves import pack_curves
from .embree.library import GEOMETRY_ROUND_CATMULL_ROM_CURVE
from .embree.rays import intersect_batch, occluded_batch, target
from .embree.scene import Scene as EmbreeScene
from .instancing import is_instanced
from .kernels.motion import pack_motion
from .motion import DeformMotion, RigidMotion
from .scene import TriangleMesh

MISS = -1
_NO_F64 = np.zeros(0)
_NO_SKIP = np.zeros((0, 2), np.int64)
_NO_SKIP_SHADOW = np.zeros((0, 4), np.int64)
_MIN_SPLIT = 4096      # below this many rays, one thread is faster than two


def _embree_scene(positions: np.ndarray, triangles: np.ndarray, offset=None) -> EmbreeScene:
    """One committed Embree scene of one triangle mesh (shared buffers, engine.embree)."""
    scene = EmbreeScene()
    scene.add_triangles(positions, triangles, offset)
    return scene.commit()


class HitArrays(NamedTuple):
    """The hits of a batch as the vertex kernels take them (engine.kernels.path_vertex)."""
    t: np.ndarray
    prim: np.ndarray
    inst: np.ndarray
    u: np.ndarray
    v: np.ndarray


@dataclass
class Hits:
    t: np.ndarray          # (n,) float64, inf where missed
    prim: np.ndarray       # (n,) int64 global triangle id, -1 where missed
    u: np.ndarray          # (n,) float64 barycentric weight of vertex 1
    v: np.ndarray          # (n,) float64 barycentric weight of vertex 2
    inst: np.ndarray = None  # (n,) int64 the instance's object row, -1: none

    def __post_init__(self):
        if self.inst is None:
            self.inst = np.full(len(self.prim), -1, np.int64)

    def arrays(self) -> HitArrays:
        """The hits as the kernels take them (one Numba type: int64 ids, float64 rest)."""
        return HitArrays(np.ascontiguousarray(self.t, np.float64),
                         np.ascontiguousarray(self.prim, np.int64),
                         np.ascontiguousarray(self.inst, np.int64),
                         np.ascontiguousarray(self.u, np.float64),
                         np.ascontiguousarray(self.v, np.float64))

    @property
    def hit(self) -> np.ndarray:
        return self.prim >= 0


def _skips(skip, n: int, columns: int) -> np.ndarray:
    """skip as (n, columns) int64 rows, -1 in the columns it lacks."""
    skip = np.asarray(skip, np.int64)
    if skip.shape == (n, columns):
        return np.ascontiguousarray(skip)
    out = np.full((n, columns), -1, np.int64)
    out[:, :skip.shape[1]] = skip
    return out


@dataclass
class MovingObject:
    mesh: TriangleMesh
    prim_offset: int
    motion: object           # the mesh's motion on evenly spaced steps (Embree's)
    scene: EmbreeScene = None  # a rigid object's own scene, in object space

    @property
    def rigid(self) -> bool:
        return isinstance(self.motion, RigidMotion)


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


def _places_center(instanced: list, moving: list) -> np.ndarray:
    """Without static triangles: the median of the instances' places and the moving
    objects' positions at their middle step (the origin when there are none)."""
    places = [m.instances.matrices[:, :3, 3] for m in instanced]
    for m in moving:
        k = len(m.motion.times) // 2
        places.append(m.motion.matrices[k:k + 1, :3, 3] if isinstance(m.motion, RigidMotion)
                      else m.motion.positions[k])
    return np.median(np.concatenate(places), axis=0) if places else np.zeros(3)


def _joined(parts: list, empty_shape, dtype) -> np.ndarray:
    """The arrays one after the other (one array: itself, not a copy)."""
    if len(parts) == 1:
        return np.ascontiguousarray(parts[0], dtype=dtype)
    return np.concatenate(parts).astype(dtype, copy=False) if parts else \
        np.zeros(empty_shape, dtype)


@dataclass
class Prototype:
    """An instanced mesh: its triangles' first global id, its Embree scene (object
    space), and the object-table row of its first place (the others follow)."""
    mesh: TriangleMesh
    prim_offset: int
    scene: EmbreeScene
    first_row: int


class Accelerator:
    """All triangles of a scene in one Embree scene: static ones, instanced meshes'
    places and moving objects (see the module docstring)."""

    def __init__(self, meshes: list[TriangleMesh], threads: int = 0, time_enabled: bool = False,
                 curves: list = ()):
        for m in meshes:
            if not np.all(np.isfinite(m.positions)):
                raise ValueError(f"mesh {m.name!r} has non-finite (NaN or Inf) vertex positions")
        static = [m for m in meshes if not _is_moving(m, time_enabled) and not is_instanced(m)]
        instanced = [m for m in meshes if is_instanced(m)]
        moving = [m for m in meshes if _is_moving(m, time_enabled) and not is_instanced(m)]
        # hair (engine.curves): its segments' ids follow the static triangles'
        self.curves = [c for c in curves if c.segment_count]
        # the global primitive order
        self.ordered_meshes = static + self.curves + instanced + moving
        self.static_meshes = len(static)
        # Every static vertex in world space, and every static triangle's corners as
        # int32 rows of them (Embree's index format); a single static mesh's own arrays
        # are used as they are, not copied (the tracer never writes them).
        positions = [_static_world_positions(m) for m in static]
        n_vertices = sum(len(p) for p in positions)
        index = np.int32 if n_vertices < 2**31 else np.int64
        bases = np.cumsum([0] + [len(p) for p in positions[:-1]])
        triangles = [m.triangles.astype(index, copy=False) + index(b) if b else
                     m.triangles.astype(index, copy=False) for m, b in zip(static, bases)]
        self.positions = _joined(positions, (0, 3), np.float64)
        self.triangles = _joined(triangles, (0, 3), index)
        self.static_count = len(self.triangles)
        # the median vertex, not the middle of the bounds: a few far vertices (a mesh
        # with a vertex at 3.4e38, tests/test_degenerate_input.py) do not move it off
        # the bulk of the geometry
        self.center = np.median(self.positions, axis=0) if len(self.positions) else \
            np.median(np.concatenate([c.keys for c in self.curves]), axis=0) \
            if self.curves else _places_center(instanced, moving)
        self.threads = threads or min(os.cpu_count() or 1, 8)
        self._pool = ThreadPoolExecutor(self.threads) if self.threads > 1 else None
        # Embree builds the hierarchy when the scene is committed: here, as part of
        # building the accelerator (and before a cancel can come), not of the first sample
        self.prototypes: list[Prototype] = []
        self.instance_count = 0
        self.curve_start = self.static_count
        offset = self.static_count + sum(c.segment_count for c in self.curves)
        self.packed_curves = pack_curves(self.curves, self.curve_start)
        for m in instanced:
            self.prototypes.append(Prototype(m, offset, _embree_scene(m.positions, m.triangles),
                                             self.instance_count))
            offset += len(m.triangles)
            self.instance_count += len(m.instances)
        self.moving_start = offset
        self.moving: list[MovingObject] = []
        for m in moving:
            motion = m.motion.evenly_spaced()
            obj = MovingObject(m, offset, motion)
            if obj.rigid:
                obj.scene = _embree_scene(m.positions, m.triangles)
            self.moving.append(obj)
            offset += len(m.triangles)
        self.total_triangles = offset
        self._scene = self._top_scene() if offset else None
        # Rays traced per query kind (all threads), and an optional recorder: a list that
        # receives (query, origins, dirs, tmax, time) of every batch, so that a benchmark
        # can replay exactly the same rays through bare Embree.
        self.rays_traced = {"INTERSECT": 0, "OCCLUDED": 0}
        self.recorder = None
        self._count_lock = threading.Lock()
        self.scene_count = ((self._scene is not None) + len(self.prototypes)
                            + sum(o.scene is not None for o in self.moving))
        # Moving objects packed for the kernels that rebuild their hits
        # (engine.kernels.motion)
        self.motion = pack_motion(self)

    def _top_scene(self) -> EmbreeScene:
        """The scene every ray is traced against, relative to `center`: the static
        triangles (geometry 0, when there are any), the places of every instanced mesh
        (one instance array each), every rigidly moving object (a moving instance) and
        every deforming one (triangles with time steps). Fills the maps from an Embree
        geometry id to its first global triangle id and, for an instance array, to the
        object-table row of its first place (-1: not an instanced mesh)."""
        scene = EmbreeScene()
        ids = []
        curve_geom = -1
        if len(self.triangles):
            ids.append((scene.add_triangles(self.positions, self.triangles, self.center),
                        0, -1))
        if self.curves:
            C = self.packed_curves
            curve_geom = scene.add_curves(C.points, C.first, GEOMETRY_ROUND_CATMULL_ROM_CURVE,
                                          self.center, cull_back_faces=True)
            ids.append((curve_geom, self.curve_start, -1))
        for proto in self.prototypes:
            places = proto.mesh.instances.matrices[:, :3, :].copy()
            places[:, :, 3] -= self.center
            ids.append((scene.add_instance_array(proto.scene, places), proto.prim_offset,
                        proto.first_row))
        for obj in self.moving:
            if obj.rigid:
                gid = scene.add_moving_instance(obj.scene, obj.motion.embree_steps(self.center))
            else:
                gid = scene.add_triangles(list(obj.motion.positions), obj.mesh.triangles,
                                          self.center)
            ids.append((gid, obj.prim_offset, -1))
        n = max(g for g, _, _ in ids) + 1 if ids else 0
        self._geom_base = np.zeros(n, np.int64)
        self._geom_row = np.full(n, -1, np.int64)
        for g, base, row in ids:
            self._geom_base[g], self._geom_row[g] = base, row
        # whether a hit's ids need mapping (anything beside the static triangles)
        self._remaps = len(ids) > 1 or (len(ids) == 1 and ids[0][1:] != (0, -1))
        scene.commit()
        self.target = target(scene.handle, self.center, self._geom_base, self._geom_row,
                             curve_geom)
        return scene

    def kernel_rays(self) -> tuple:
        """What a kernel needs to cast rays itself and name what they hit as the queries
        here do (engine.kernels.subsurface.local_hit): (the scene's
        engine.embree.rays.Target, each ordered mesh's first global triangle and the
        total); None without triangles."""
        if self._scene is None:
            return None
        counts = [len(m.triangles) for m in self.ordered_meshes]
        starts = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        return self.target, starts

    def close(self):
        if self._pool is not None:
            self._pool.shutdown(wait=False)
            self._pool = None

    # -- queries ---------------------------------------------------------------------
    def _query(self, origins, dirs, tmax, time, query, skip=None):
        """Embree on float64 rays whose origins are moved by -center before rounding to
        float32 (engine.embree.rays), split over the pool for large batches; skip: what
        each ray must not hit (see `intersect` and `occluded`). Returns blocked (n,) for
        OCCLUDED; Hits for INTERSECT."""
        o = np.ascontiguousarray(origins, dtype=np.float64)
        d = np.ascontiguousarray(dirs, dtype=np.float64)
        n = len(o)
        far = np.array(np.broadcast_to(tmax, (n,)), dtype=np.float64)
        tm = _NO_F64 if time is None else np.array(np.broadcast_to(time, (n,)), np.float64)
        tg = self.target
        if query == "OCCLUDED":
            out = (np.zeros(n, bool),)
            sk = _NO_SKIP_SHADOW if skip is None else _skips(skip, n, 4)

            def run(a, b):
                occluded_batch(tg, o[a:b], d[a:b], far[a:b], tm[a:b] if len(tm) else tm,
                               sk[a:b] if len(sk) else sk, out[0][a:b])
        else:
            out = (np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n, np.int64),
                   np.empty(n, np.int64), np.empty(n), np.empty(n), np.empty(n))
            sk = _NO_SKIP if skip is None else _skips(skip, n, skip.shape[1])

            def run(a, b):
                intersect_batch(tg, o[a:b], d[a:b], far[a:b], tm[a:b] if len(tm) else tm,
                                sk[a:b] if len(sk) else sk, *(x[a:b] for x in out))
        if self._pool is None or n < _MIN_SPLIT:
            run(0, n)
        else:
            bounds = np.linspace(0, n, self.threads + 1).astype(int)
            for f in [self._pool.submit(run, a, b)
                      for a, b in zip(bounds[:-1], bounds[1:]) if b > a]:
                f.result()
        if query == "OCCLUDED":
            return out[0]
        geom, prim, inst, element, t, u, v = out
        if not self._remaps:        # static triangles alone: ids are global already
            inst.fill(-1)
            return Hits(t, prim, u, v, inst)
        placed = inst >= 0          # an instance's geometry id in the top scene
        hit = geom >= 0
        owner = np.where(placed, inst, geom)[hit]   # the top scene's geometry hit
        prim[hit] += self._geom_base[owner]
        row = np.full(n, -1, np.int64)
        row[hit] = self._geom_row[owner]
        inst = np.where(row >= 0, row + element, -1)
        return Hits(t, prim, u, v, inst)

    def _run(self, origins, dirs, tmax, time, query, skip=None):
        """One batch of queries, counted (and recorded for a benchmark's replay)."""
        n = len(origins)
        if self.moving and time is None:
            raise ValueError("a scene with moving objects needs a time per ray")
        with self._count_lock:
            self.rays_traced[query] += n
            if self.recorder is not None:
                self.recorder.append((query, np.array(origins, np.float64),
                                      np.array(dirs, np.float64),
                                      np.array(np.broadcast_to(tmax, (n,)), np.float64),
                                      None if time is None else np.array(
                                          np.broadcast_to(time, (n,)), np.float64),
                                      None if skip is None else np.array(skip, np.int64)))
        return self._query(origins, dirs, tmax, time if self.moving else None, query, skip)

    def replay(self, batches) -> None:
        """Recorded batches through bare Embree (a benchmark's reference: the same
        queries, without DRT's work around them)."""
        for query, o, d, far, time, skip in batches:
            self._query(o, d, far, time, query, skip)

    def intersect(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray,
                  time: np.ndarray | None = None, skip: np.ndarray | None = None) -> Hits:
        """The closest hit of each ray within [0, tmax]. skip (n, 2) int64: the global
        primitive each ray leaves and its place (Hits.prim and Hits.inst of the hit it
        starts on; -1: none), which it does not hit again; (n, 4): and a second pair,
        the emissive triangle a shadow ray goes to."""
        n = len(origins)
        if n == 0 or self._scene is None:
            return Hits(np.full(n, np.inf), np.full(n, MISS, np.int64), np.zeros(n),
                        np.zeros(n), np.full(n, -1, np.int64))
        return self._run(origins, dirs, tmax, time, "INTERSECT", skip)

    def occluded(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray,
                 time: np.ndarray | None = None, skip: np.ndarray | None = None) -> np.ndarray:
        """True where something lies on the segment [0, tmax) of each ray. skip (n, 4)
        int64: the global primitive and place each ray leaves and the emissive triangle
        and place it goes to (-1: none), which do not block it."""
        n = len(origins)
        if n == 0 or self._scene is None:
            return np.zeros(n, dtype=bool)
        return self._run(origins, dirs, tmax, time, "OCCLUDED", skip)
