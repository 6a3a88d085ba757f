"""Ray queries against the scene's triangles through Intel Embree's own C API
(`engine.embree`: scenes on shared NumPy buffers, queries in compiled kernels).

Batches of rays are traced by one compiled call each (`engine.embree.rays`), at tnear 0:
ray origins are offset by the caller (`engine.surface.offset_origin`); batches are split
over threads (every kernel releases the GIL). Motion is built here from plain scenes:
- static geometry: one shared Embree scene in world space (the only one a scene without
  motion ever builds, so static scenes pay nothing for motion blur);
- each rigidly moving object: its own Embree scene in object space; every ray is moved
  into object space by the inverse of the object's transform at that ray's own time
  (the ray parameter t is unchanged by an affine map, so distances compare directly);
- each deforming object: one Embree scene per stratified time slice of the shutter,
  built from the vertex positions at the slice's middle; a ray is traced against the
  slice its time falls in (see `engine.motion.DeformMotion` for what that costs).
The nearest hit across all of them wins. Triangles get global ids in that order.

Instances (engine.instancing): an instanced mesh is one Embree scene in object space,
and its places one Embree instance array in the static scene (one shared float32
buffer of transforms, each the place's matrix moved by -center like the static
triangles). Its triangles get
global ids once, after the static ones (the prototypes), and a hit on one reports the
place too: `Hits.inst`, the place's row in the object table (engine.surface; -1 for a
hit on a mesh that is not instanced). Memory then grows with the places, not with
places x triangles.

Many moving objects: a ray does not visit every moving object. A top-level hierarchy
over the moving objects' swept world bounds (`engine.kernels.motion_tlas`: the bounds
hold at every time of the shutter, rotation included) is walked by one compiled call per
batch (`engine.kernels.motion_trace`), which intersects small objects (at most
KERNEL_TRIANGLES triangles) on the spot in float64 and lists the (ray, object) pairs of
the large ones, whose bounds the ray crosses before its nearest hit so far; only those
pairs go to Embree, grouped by object, each ray moved into object space at its own time
(`engine.kernels.motion_pairs`). `Accelerator(..., motion_tlas=False)` visits every
moving object with every ray instead: the reference the hierarchy must equal; with
kernel_triangles=0 as well, every moving object goes through Embree.

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

from .embree.rays import intersect_batch, occluded_batch
from .embree.scene import Scene as EmbreeScene
from .instancing import is_instanced
from .kernels.motion import pack_motion
from .kernels.motion_pairs import group_pairs, merge_blocked, merge_hits
from .kernels.motion_tlas import MotionTLAS, build_tlas
from .kernels.motion_trace import trace_moving
from .motion import DeformMotion, RigidMotion
from .scene import TriangleMesh

MISS = -1
# Moving objects of at most this many triangles are intersected inside the compiled
# traversal (float64, no Embree call); larger ones by their own Embree scene.
KERNEL_TRIANGLES = 256
_ORIGIN = np.zeros(3)
_NO_F64, _NO_I64, _NO_BOOL = np.zeros(0), np.zeros(0, np.int64), np.zeros(0, bool)
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
    """All triangles of a scene: static ones in one Embree scene (with the instances of
    instanced meshes), moving ones apart."""

    def __init__(self, meshes: list[TriangleMesh], threads: int = 0, time_enabled: bool = False,
                 motion_tlas: bool = True, kernel_triangles: int = KERNEL_TRIANGLES):
        for m in meshes:
            if not np.all(np.isfinite(m.positions)):
                raise ValueError(f"mesh {m.name!r} has non-finite (NaN or Inf) vertex positions")
        static = [m for m in meshes if not _is_moving(m, time_enabled) and not is_instanced(m)]
        instanced = [m for m in meshes if is_instanced(m)]
        moving = [m for m in meshes if _is_moving(m, time_enabled) and not is_instanced(m)]
        self.ordered_meshes = static + instanced + moving    # the global triangle order
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
        places = [m.instances.matrices[:, :3, 3] for m in instanced]
        self.center = (np.median(self.positions, axis=0) if len(self.positions) else
                       np.median(np.concatenate(places), axis=0) if places else np.zeros(3))
        self.threads = threads or min(os.cpu_count() or 1, 8)
        self._pool = ThreadPoolExecutor(self.threads) if self.threads > 1 else None
        # Embree builds the hierarchy when the scene is committed: here, as part of
        # building the accelerator (and before a cancel can come), not of the first sample
        self.prototypes: list[Prototype] = []
        self.instance_count = 0
        offset = self.static_count
        for m in instanced:
            self.prototypes.append(Prototype(m, offset, _embree_scene(m.positions, m.triangles),
                                             self.instance_count))
            offset += len(m.triangles)
            self.instance_count += len(m.instances)
        self.moving_start = offset
        self._scene = self._static_scene() if len(self.triangles) or instanced else None
        self.moving: list[MovingObject] = []
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
        # (ray, moving object unit) pairs examined: intersected in the kernel or listed
        # for Embree (all threads).
        self.pairs_visited = 0
        self.recorder = None
        self._count_lock = threading.Lock()
        self.scene_count = ((self._scene is not None) + len(self.prototypes)
                            + sum(len(o.scenes) for o in self.moving))
        # Moving objects packed for the kernels (engine.kernels.motion), and the
        # top-level hierarchy over them (motion_tlas=False: brute force, the reference).
        self.motion = pack_motion(self)
        self.motion_tlas = motion_tlas
        self.kernel_triangles = kernel_triangles
        self.tlas: MotionTLAS | None = None
        if self.moving:
            self.build_tlas()

    def _static_scene(self) -> EmbreeScene:
        """The static triangles (geometry 0, when there are any) and the places of every
        instanced mesh (one instance array each), relative to `center`. Fills the maps
        from an Embree instance array's id to its prototype's first global triangle id
        and to the object-table row of its first place."""
        scene = EmbreeScene()
        ids = []
        if len(self.triangles):
            ids.append((scene.add_triangles(self.positions, self.triangles, self.center),
                        0, -1))
        for proto in self.prototypes:
            places = proto.mesh.instances.matrices[:, :3, :].copy()
            places[:, :, 3] -= self.center
            ids.append((scene.add_instance_array(proto.scene, places), proto.prim_offset,
                        proto.first_row))
        n = max(g for g, _, _ in ids) + 1 if ids else 0
        self._inst_base = np.zeros(n, np.int64)
        self._inst_row = np.full(n, -1, np.int64)
        for g, base, row in ids:
            self._inst_base[g], self._inst_row[g] = base, row
        return scene.commit()

    def build_tlas(self, swept: bool = True):
        """(Re)build the hierarchy over the moving objects. swept=False is a negative
        control for tests: rigid bounds at the motion steps only, which misses hits."""
        n = len(self.moving)
        lo, hi = np.zeros((n, 3)), np.zeros((n, 3))
        for i, obj in enumerate(self.moving):
            if obj.rigid and len(obj.mesh.positions):
                lo[i] = obj.mesh.positions.min(axis=0)
                hi[i] = obj.mesh.positions.max(axis=0)
        self.tlas = build_tlas(self.motion, lo, hi, swept=swept,
                               kernel_triangles=self.kernel_triangles)
        self._unit_scene = [self.moving[o].scenes[s]
                            for o, s in zip(self.tlas.unit_obj, self.tlas.unit_slice)]
        self._embree_units = bool((self.tlas.unit_root < 0).any())

    def close(self):
        if self._pool is not None:
            self._pool.shutdown(wait=False)
            self._pool = None

    # -- raw queries -------------------------------------------------------------------
    def _query(self, scene, center, origins, dirs, tmax, time, query):
        """Embree on float64 rays whose origins are moved by -center before rounding to
        float32 (engine.embree.rays), split over the pool for large batches. Returns
        blocked (n,) for OCCLUDED; (prim, t, u, v) for INTERSECT (prim -1, t inf where
        missed)."""
        o = np.ascontiguousarray(origins, dtype=np.float64)
        d = np.ascontiguousarray(dirs, dtype=np.float64)
        n = len(o)
        far = np.array(np.broadcast_to(tmax, (n,)), dtype=np.float64)
        tm = _NO_F64 if time is None else np.ascontiguousarray(time, dtype=np.float64)
        if query == "OCCLUDED":
            out = (np.zeros(n, bool),)

            def run(a, b):
                occluded_batch(scene.handle, center, o[a:b], d[a:b], far[a:b],
                               tm[a:b] if len(tm) else tm, out[0][a:b])
        else:
            out = (np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n, np.int64),
                   np.empty(n, np.int64), np.empty(n), np.empty(n), np.empty(n))

            def run(a, b):
                intersect_batch(scene.handle, center, o[a:b], d[a:b], far[a:b],
                                tm[a:b] if len(tm) else tm, *(x[a:b] for x in out))
        if self._pool is None or n < _MIN_SPLIT:
            run(0, n)
        else:
            bounds = np.linspace(0, n, self.threads + 1).astype(int)
            for f in [self._pool.submit(run, a, b)
                      for a, b in zip(bounds[:-1], bounds[1:]) if b > a]:
                f.result()
        if query == "OCCLUDED":
            return out[0]
        _, prim, inst, element, t, u, v = out
        if scene is self._scene and self.prototypes:
            placed = inst >= 0          # the instance array's geometry id, the place's index
            g = inst[placed]
            prim[placed] += self._inst_base[g]
            inst[placed] = self._inst_row[g] + element[placed]
        else:
            inst[:] = -1
        return prim, t, u, v, inst

    def _run(self, origins, dirs, tmax, query):
        """The static scene's queries, counted (and recorded for a benchmark's replay)."""
        n = len(origins)
        with self._count_lock:
            self.rays_traced[query] += n
            if self.recorder is not None:
                self.recorder.append((query, np.array(origins, np.float64),
                                      np.array(dirs, np.float64),
                                      np.array(np.broadcast_to(tmax, (n,)), np.float64)))
        return self._query(self._scene, self.center, origins, dirs, tmax, None, query)

    def replay(self, batches) -> None:
        """The recorded static-scene batches through bare Embree (a benchmark's reference:
        the same queries, without DRT's work around them)."""
        for query, o, d, far in batches:
            self._query(self._scene, self.center, o, d, far, None, query)

    # -- motion ------------------------------------------------------------------------
    def _trace_moving(self, origins, dirs, time, best, t, prim, u, v, blocked, occlusion):
        """The moving objects against the rays (see the module docstring): the kernel
        objects inside `trace_moving`, then the Embree objects' (ray, object) pairs it
        lists, grouped by object. Updates (t, prim, u, v, best) or blocked in place."""
        n = len(origins)
        o = np.ascontiguousarray(origins, np.float64)
        d = np.ascontiguousarray(dirs, np.float64)
        tm = np.array(np.broadcast_to(time, (n,)), np.float64)   # writable: one kernel type
        hit_unit = np.full(n, -1, np.int64)
        cap = 2 * n + 256 if self._embree_units else 0
        while True:
            pr, pu = np.empty(cap, np.int64), np.empty(cap, np.int64)
            visits = np.zeros(1, np.int64)
            count = trace_moving(self.tlas, self.motion, o, d, tm, best, t, prim, u, v,
                                 hit_unit, blocked, occlusion, self.motion_tlas, pr, pu,
                                 visits)
            if count <= cap:
                break
            cap = count
        with self._count_lock:
            self.pairs_visited += int(visits[0])
        if count == 0:
            return
        s_ray, s_unit = np.empty(count, np.int64), np.empty(count, np.int64)
        # each pair's ray in its unit's space, rounded to float32 by group_pairs as Embree
        # takes it, and kept in float64 arrays, which the ray kernels read as they are
        o_unit, d_unit, far_unit = np.empty((count, 3)), np.empty((count, 3)), np.empty(count)
        unit_start = np.empty(len(self._unit_scene) + 1, np.int64)
        group_pairs(self.motion, self.tlas, pr, pu, count, o, d, best, tm,
                    s_ray, s_unit, o_unit, d_unit, far_unit, unit_start)
        query = "OCCLUDED" if occlusion else "INTERSECT"
        parts = []
        for k in np.flatnonzero(unit_start[1:] > unit_start[:-1]):
            a, b = unit_start[k], unit_start[k + 1]
            found = self._query(self._unit_scene[k], _ORIGIN, o_unit[a:b], d_unit[a:b],
                                far_unit[a:b], None, query)
            parts.append(found if occlusion else found[:4])
        with self._count_lock:
            self.rays_traced[query] += count
        if occlusion:
            merge_blocked(s_ray, np.where(np.concatenate(parts), 0, MISS), blocked)
        else:
            merge_hits(self.motion, self.tlas, s_ray, s_unit,
                       *(np.concatenate([p[i] for p in parts]) for i in range(4)),
                       t, prim, u, v, best, hit_unit)

    # -- public queries ----------------------------------------------------------------
    def intersect(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray,
                  time: np.ndarray | None = None) -> Hits:
        n = len(origins)
        t = np.full(n, np.inf)
        prim = np.full(n, MISS, np.int64)
        u, v = np.zeros(n), np.zeros(n)
        inst = np.full(n, -1, np.int64)
        if n == 0:
            return Hits(t, prim, u, v, inst)
        if self._scene is not None:
            prim, t, u, v, inst = self._run(origins, dirs, tmax, "INTERSECT")
        if self.moving:
            if time is None:
                raise ValueError("a scene with moving objects needs a time per ray")
            best = np.array(np.broadcast_to(np.minimum(t, tmax), (n,)), np.float64)
            t, prim = np.array(t, np.float64), np.array(prim, np.int64)
            u, v = np.array(u, np.float64), np.array(v, np.float64)
            self._trace_moving(origins, dirs, time, best, t, prim, u, v, _NO_BOOL, False)
            if self.prototypes:
                inst = np.where(prim >= self.moving_start, -1, inst)
        return Hits(t, prim, u, v, inst)

    def occluded(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray,
                 time: np.ndarray | None = None) -> np.ndarray:
        """True where something lies on the segment [0, tmax) of each ray."""
        n = len(origins)
        blocked = np.zeros(n, dtype=bool)
        if n == 0:
            return blocked
        if self._scene is not None:
            blocked = self._run(origins, dirs, tmax, "OCCLUDED")
        if self.moving:
            if time is None:
                raise ValueError("a scene with moving objects needs a time per ray")
            blocked = np.array(blocked, bool)
            far = np.array(np.broadcast_to(tmax, (n,)), np.float64)
            self._trace_moving(origins, dirs, time, far, _NO_F64, _NO_I64, _NO_F64, _NO_F64,
                               blocked, True)
        return blocked
