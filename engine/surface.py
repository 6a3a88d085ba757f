"""Surface interactions: what a ray hit, rebuilt in float64.

Hit points come from the triangle's float64 vertices and Embree's barycentrics, so their
error is a few float32 ulps of the vertex coordinates whatever the ray length. A new ray
leaving the surface starts at the hit point itself and names the triangle it leaves,
which Embree's filter then passes (engine.kernels.ray_origin, engine.embree.self_hits),
as Cycles starts its rays: no offset, so no acne and no leaking through thin geometry at
any scene scale. `scale`, each hit's largest coordinate magnitude relative to the centre
Embree sees the static scene around (engine.accel), bounds its float32 error.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from .accel import Accelerator, Hits

# 2**-17 ~ 7.6e-6 of a coordinate's magnitude (64 float32 ulps): how far short of a
# sampled point on an emissive triangle its shadow ray stops (engine.mesh_lights)
RELATIVE_OFFSET = 2.0 ** -17


@dataclass
class SurfaceHit:
    position: np.ndarray         # (n, 3) float64
    geometric_normal: np.ndarray  # (n, 3) unit, facing the incoming ray's side
    shading_normal: np.ndarray   # (n, 3) unit, same hemisphere as geometric_normal
    front_facing: np.ndarray     # (n,) bool: the ray hit the triangle's front side
    material: np.ndarray         # (n,) int64 index into Scene.materials
    scale: np.ndarray            # (n,) float64 coordinate magnitude (float32 error bound)
    uv: np.ndarray | None = None   # (n, 2) texture coordinates, None if no mesh has UVs
    prim: np.ndarray | None = None       # (n,) the triangles hit
    direction: np.ndarray | None = None  # (n, 3) the rays' directions
    bary: np.ndarray | None = None       # (n, 2) barycentrics (u, v) in the triangle
    inst: np.ndarray | None = None       # (n,) the instances' object rows, -1: none


class SurfaceBuilder:
    """Precomputes per-triangle data in the accelerator's global triangle order; for
    moving objects it places the triangle at each ray's own time.

    Triangles are kept as vertex rows, not as per-corner copies: `positions` (V, 3)
    float64 holds the accelerator's static world vertices (the same array, not a copy),
    then each moving object's own vertices (object space for a rigid one, its first time
    step for a deforming one: placeholders, its hits are rebuilt at the ray's time in
    build()); `corners` (T, 3) holds each triangle's three rows of it."""

    def __init__(self, accel: Accelerator, holdout_materials=None):
        self.accel = accel
        ordered = accel.ordered_meshes
        positions, corners, base = [accel.positions], [accel.triangles], len(accel.positions)
        for c in accel.curves:            # hair: each segment as the triangle of its keys
            positions.append(c.positions)
            corners.append(c.triangles.astype(accel.triangles.dtype) + base)
            base += len(c.positions)
        for proto in accel.prototypes:          # instanced meshes, in object space
            m = proto.mesh
            positions.append(m.positions)
            corners.append(m.triangles.astype(accel.triangles.dtype) + base)
            base += len(m.positions)
        for obj in accel.moving:
            m = obj.mesh
            positions.append(m.positions if obj.rigid else obj.motion.positions[0])
            corners.append(m.triangles.astype(accel.triangles.dtype) + base)
            base += len(positions[-1])
        self.positions = positions[0] if len(positions) == 1 else np.concatenate(positions)
        self.corners = corners[0] if len(corners) == 1 else np.concatenate(corners)
        # Unit normals and offset scales are computed per hit (normals(), scales(); the
        # compiled kernels likewise), not stored per triangle.
        self.material = (np.concatenate([m.material_indices for m in ordered]).astype(np.int64)
                         if ordered else np.zeros(0, np.int64))
        # Holdout triangles (None when the scene has none): camera rays end there; those
        # of holdout objects, and of materials that are a Holdout shader
        # (holdout_materials: a flag per material)
        held = (np.zeros(1, bool) if holdout_materials is None
                else np.append(np.asarray(holdout_materials, bool), False))
        self.holdout = (np.concatenate([
            np.full(len(m.triangles), True) if m.holdout
            else held[np.minimum(m.material_indices, len(held) - 1)] for m in ordered])
            if any(m.holdout for m in ordered) or held.any() else None)
        # The ray kinds that see each triangle (engine.visibility); None when all see all.
        self.visibility = (np.concatenate([np.full(len(m.triangles), m.visibility, np.uint8)
                                           for m in ordered])
                           if any(m.visibility != 31 for m in ordered) else None)
        self.tri_object, self.objects = _object_table(ordered, accel.prototypes)
        # Tangent space per corner for Normal Maps (sign 0 where a mesh has none), and
        # a color attribute per corner (0 where a mesh has none, as in Cycles)
        self.corner_tangents = _corner_attribute(ordered, "tangents")
        self.corner_colors = _corner_attribute(ordered, "colors")
        # the undisplaced object-space point of each corner of displaced meshes (NaN
        # elsewhere), where their hits read Generated coordinates (engine.displacement)
        self.corner_undisplaced = None
        if any(getattr(m, "undisplaced", None) is not None for m in ordered):
            self.corner_undisplaced = np.concatenate([
                np.asarray(m.undisplaced, np.float32).reshape(-1, 3, 3)
                if getattr(m, "undisplaced", None) is not None
                else np.full((len(m.triangles), 3, 3), np.nan, np.float32) for m in ordered])
        self.corner_normals = None
        if any(m.corner_normals is not None for m in ordered):
            parts, offset = [], 0
            for m in ordered:
                t = len(m.triangles)
                if m.corner_normals is not None:
                    parts.append(np.asarray(m.corner_normals, np.float32).reshape(-1, 3, 3))
                else:
                    flat = _unit_normals(self.positions, self.corners[offset:offset + t]
                                         ).astype(np.float32)
                    parts.append(np.repeat(flat[:, None, :], 3, axis=1))
                offset += t
            self.corner_normals = np.concatenate(parts)
        # faces shaded flat beside corner normals that are not theirs (a Normal Map builds
        # on their own normal; their shadow rays leave from their plane); None: none
        self.flat_faces = None
        if any(getattr(m, "flat_faces", None) is not None for m in ordered):
            self.flat_faces = np.concatenate([
                np.asarray(m.flat_faces, np.uint8) if getattr(m, "flat_faces", None)
                is not None else np.zeros(len(m.triangles), np.uint8) for m in ordered])
        self.terminator_cutoff = _terminator_cutoff(ordered, accel.moving_start)
        if self.terminator_cutoff is not None and self.flat_faces is not None:
            self.terminator_cutoff[self.flat_faces != 0] = 0.0
        # Texture coordinates per triangle corner (Blender's UV map), for the meshes that
        # have them; triangles of meshes without UVs read (0, 0), as in Cycles.
        self._geometry = None           # geometry(), made on the first build()
        self._tri_mesh = None           # each triangle's mesh (ordered_meshes), on first use
        self.corner_uvs = None
        if any(getattr(m, "uvs", None) is not None for m in ordered):
            parts = []
            for m in ordered:
                t = len(m.triangles)
                if m.uvs is not None:
                    parts.append(np.asarray(m.uvs, np.float32).reshape(t, 3, 2))
                else:
                    parts.append(np.zeros((t, 3, 2), np.float32))
            self.corner_uvs = np.concatenate(parts)

    def vertices(self, prim) -> tuple:
        """The three corners (n, 3) of triangles `prim` as stored (instanced and moving
        ones: placeholders in object space or at their first time step)."""
        c = self.corners[prim]
        return self.positions[c[:, 0]], self.positions[c[:, 1]], self.positions[c[:, 2]]

    def normals(self, prim) -> np.ndarray:
        """Unit geometric normals (n, 3) of triangles `prim` as stored (see vertices)."""
        return _corner_normals(*self.vertices(prim))

    def mesh_of(self, prim) -> np.ndarray:
        """The index in accel.ordered_meshes of the mesh each triangle `prim` belongs to."""
        if self._tri_mesh is None:
            ordered = self.accel.ordered_meshes
            self._tri_mesh = np.repeat(np.arange(len(ordered), dtype=np.int32),
                                       [len(m.triangles) for m in ordered])
        return self._tri_mesh[prim]

    def pass_indices(self, prim, inst) -> np.ndarray:
        """The objects' Pass Index (float64, as Cycles' Object Index pass) of hits on
        triangles `prim` of places `inst` (-1: not an instance)."""
        ordered = self.accel.ordered_meshes
        index = np.array([getattr(m, "pass_index", 0) for m in ordered] or [0], np.float64)
        out = index[self.mesh_of(prim)]
        placed = inst >= 0
        if placed.any():
            from .nodes.context import O_INDEX
            out[placed] = self.objects[inst[placed], O_INDEX]
        return out

    def seen_by_catcher_paths(self, catcher: np.ndarray) -> "SurfaceBuilder":
        """These surfaces as Cycles' shadow catcher paths see them (engine.shadow_catcher):
        the triangles flagged in `catcher` as they are; the others only by camera rays,
        which end there with nothing (as at a holdout), and by no other ray."""
        from . import visibility
        other = copy.copy(self)
        catcher = np.asarray(catcher, bool)
        seen = (self.visibility if self.visibility is not None
                else np.full(len(catcher), visibility.ALL, np.uint8))
        other.visibility = np.where(catcher, seen, seen & visibility.CAMERA).astype(np.uint8)
        held = self.holdout if self.holdout is not None else np.zeros(len(catcher), bool)
        other.holdout = held | ~catcher
        other._geometry = None
        return other

    def geometry(self, camera=None) -> tuple:
        """The primitives as the compiled kernels read them (engine.kernels.surface,
        engine.nodes.shading): (positions, corners, centre, material, corner normals,
        holdout, corner UVs, moving objects, triangle objects, object table, corner
        tangents, corner colours, camera, terminator cutoffs, corners' undisplaced
        points, hair strands (engine.kernels.curve_hit.PackedCurves), flat faces beside
        corner normals (uint8 per triangle)); empty arrays for
        what the scene has not. camera: the packed render camera (engine.kernels.camera_rays),
        which shader nodes read; None: none."""
        from .nodes.context import N_OBJ
        return (self.positions, self.corners,
                np.asarray(self.accel.center, dtype=np.float64), self.material,
                or_empty(self.corner_normals, (0, 3, 3), np.float32),
                or_empty(self.holdout, 0, bool),
                or_empty(self.corner_uvs, (0, 3, 2), np.float32),
                self.accel.motion,
                or_empty(self.tri_object, 0, np.int32),
                or_empty(self.objects, (0, N_OBJ), np.float64),
                or_empty(self.corner_tangents, (0, 3, 4), np.float32),
                or_empty(self.corner_colors, (0, 3, 4), np.float32),
                np.zeros(0) if camera is None else camera,
                or_empty(self.terminator_cutoff, 0, np.float64),
                or_empty(self.corner_undisplaced, (0, 3, 3), np.float32),
                self.accel.packed_curves,
                or_empty(self.flat_faces, 0, np.uint8))

    def build(self, hits: Hits, index: np.ndarray, ray_dirs: np.ndarray,
              time: np.ndarray | None = None, origins: np.ndarray | None = None
              ) -> SurfaceHit:
        """Interactions for the rays `index` (which must all have hit), rebuilt by the
        kernels' own `surface_at`; `time` is the per-ray shutter time of all rays
        (needed when the scene has moving objects); `origins` the rays' origins (needed
        where they hit hair: engine.kernels.curve_hit)."""
        from .kernels.surface import rebuild_batch
        if self._geometry is None:
            self._geometry = self.geometry()
        index = np.asarray(index, np.int64)
        prim = np.ascontiguousarray(hits.prim[index], np.int64)
        inst = np.ascontiguousarray(hits.inst[index], np.int64)
        u = np.ascontiguousarray(hits.u[index], np.float64)
        v = np.ascontiguousarray(hits.v[index], np.float64)
        d = np.ascontiguousarray(np.asarray(ray_dirs)[index], np.float64)
        if origins is None and self.accel.curves:
            raise ValueError("a scene with hair needs the rays' origins")
        o = np.zeros((len(index), 3)) if origins is None else \
            np.ascontiguousarray(np.asarray(origins)[index], np.float64)
        t = np.ascontiguousarray(hits.t[index], np.float64)
        if self.accel.moving and time is None:
            raise ValueError("a scene with moving objects needs a time per ray")
        tm = np.zeros(0) if time is None else np.ascontiguousarray(
            np.broadcast_to(time, (len(ray_dirs),))[index], np.float64)
        n = len(prim)
        pos, ng, ns = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
        front, scale = np.empty(n, bool), np.empty(n)
        rebuild_batch(self._geometry, prim, inst, u, v, o, t, d, tm, pos, ng, ns, front,
                      scale)
        uv = None
        if self.corner_uvs is not None:
            # the same barycentric weights as the position: w vertex 0, u vertex 1, v vertex 2
            cu = self.corner_uvs[prim].astype(np.float64)
            w = (1.0 - u - v)[:, None]
            uv = w * cu[:, 0] + u[:, None] * cu[:, 1] + v[:, None] * cu[:, 2]
        return SurfaceHit(pos, ng, ns, front, self.material[prim], scale, uv, prim, d,
                          np.stack([u, v], axis=1), inst)


def or_empty(a, shape, dtype):
    """`a` as a contiguous array, or an empty one of `shape` and `dtype` for None (what the
    kernels read for an attribute the scene has not)."""
    return np.ascontiguousarray(a) if a is not None else np.zeros(shape, dtype)


def _corner_attribute(ordered, name):
    """(T, 3, 4) float32 of every mesh's per-corner attribute `name` (zeros for meshes
    without it), or None when no mesh has it."""
    if not any(getattr(m, name, None) is not None for m in ordered):
        return None
    return np.concatenate([np.asarray(getattr(m, name), np.float32).reshape(-1, 3, 4)
                           if getattr(m, name, None) is not None
                           else np.zeros((len(m.triangles), 3, 4), np.float32)
                           for m in ordered])


def _terminator_cutoff(ordered, moving_start):
    """Each triangle's Shadow Terminator Geometry Offset (engine.kernels.terminator), 0
    where there is no curved surface to start shadow rays from: flat meshes and moving
    objects' triangles (from moving_start on); None when no triangle has one."""
    if not any(m.corner_normals is not None for m in ordered):
        return None
    cut = np.concatenate([np.full(len(m.triangles), getattr(m, "terminator_offset", 0.1)
                                  if m.corner_normals is not None else 0.0)
                          for m in ordered])
    cut[moving_start:] = 0.0
    return cut if (cut > 0.0).any() else None


def _object_table(ordered, prototypes=()):
    """(each triangle's object (int32), the object table (engine.nodes.context O_* rows))
    when some mesh carries ObjectInfo (its materials run shader programs) or is
    instanced, else (None, None). The table holds the places of the instanced meshes
    first (a hit's `inst` is its row, engine.accel), then one row per mesh; a mesh
    without ObjectInfo is the identity object with its bounding box as texture space."""
    if not prototypes and not any(getattr(m, "object_info", None) is not None
                                  for m in ordered):
        return None, None
    from .instancing import object_rows
    from .nodes.context import N_OBJ, object_row
    places = [object_rows(p.mesh) for p in prototypes]
    first = sum(len(p) for p in places)
    rows = np.zeros((len(ordered), N_OBJ))
    for k, m in enumerate(ordered):
        info = m.object_info
        if info is None:
            lo, hi = (m.positions.min(0), m.positions.max(0)) if len(m.positions) else \
                (np.zeros(3), np.ones(3))
            rows[k] = object_row(np.eye(4), texspace_location=(lo + hi) / 2,
                                 texspace_size=(hi - lo) / 2)
        else:
            rows[k] = object_row(info.matrix_world, info.color, info.random,
                                 info.pass_index, info.texspace_location,
                                 info.texspace_size)
    counts = [len(m.triangles) for m in ordered]
    return (np.repeat(np.arange(first, first + len(ordered), dtype=np.int32), counts),
            np.concatenate(places + [rows]))


# Triangles per block of the per-triangle normals built from vertex rows: temporaries
# of a block, never of the whole mesh (a 1M-triangle mesh's corners in float64 are 72 MB).
_BLOCK = 1 << 16


def triangle_scale(v0, v1, v2, center) -> np.ndarray:
    """Per triangle, the largest coordinate magnitude of its corners relative to `center`
    ((3,), or (n, 3): one per triangle)."""
    if not len(v0):
        return np.zeros(0)
    return np.max(np.abs(np.stack([v0 - center, v1 - center, v2 - center], 1)), axis=(1, 2))


def _unit_normals(positions, corners):
    """Unit normals (T, 3) of triangles `corners` (rows of positions), block by block."""
    n = np.empty((len(corners), 3))
    for a in range(0, len(corners), _BLOCK):
        c = corners[a:a + _BLOCK]
        v0 = positions[c[:, 0]]
        n[a:a + _BLOCK] = _corner_normals(v0, positions[c[:, 1]], positions[c[:, 2]])
    return n


def _corner_normals(v0, v1, v2):
    n = np.cross(v1 - v0, v2 - v0)
    length = np.linalg.norm(n, axis=1)
    ok = length > 0
    n[ok] /= length[ok, None]
    n[~ok] = (0.0, 0.0, 1.0)                     # never hit by Embree anyway
    return n
