"""Surface interactions: what a ray hit, rebuilt in float64, and safe ray origins.

Hit points come from the triangle's float64 vertices and Embree's barycentrics, so their
error is a few float32 ulps of the vertex coordinates whatever the ray length. A new ray
leaving the surface starts at the hit point pushed along the geometric normal, to the
side it leaves from, by an amount proportional to the magnitude of the coordinates
involved: that bounds the float32 rounding Embree applies to origins and triangles, so
there is no self-intersection (acne) and, the offset being relative, no leaking through
thin geometry at any scene scale from 1e-3 to 1e4. The magnitude is measured from the
centre Embree sees the static scene around (engine.accel), so it does not grow when the
whole scene is far from the world origin.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .accel import Accelerator, Hits
from .motion import inverse3

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
    uv: np.ndarray | None = None   # (n, 2) texture coordinates, None if no mesh has UVs
    prim: np.ndarray | None = None       # (n,) the triangles hit
    direction: np.ndarray | None = None  # (n, 3) the rays' directions
    bary: np.ndarray | None = None       # (n, 2) barycentrics (u, v) in the triangle


class SurfaceBuilder:
    """Precomputes per-triangle data in the accelerator's global triangle order; for
    moving objects it places the triangle at each ray's own time.

    Triangles are kept as vertex rows, not as per-corner copies: `positions` (V, 3)
    float64 holds the accelerator's static world vertices (the same array, not a copy),
    then each moving object's own vertices (object space for a rigid one, its first time
    slice for a deforming one: placeholders, its hits are rebuilt at the ray's time in
    build()); `corners` (T, 3) holds each triangle's three rows of it."""

    def __init__(self, accel: Accelerator, meshes=None):
        self.accel = accel
        ordered = accel.ordered_meshes
        positions, corners, base = [accel.positions], [accel.triangles], len(accel.positions)
        for obj in accel.moving:
            m = obj.mesh
            positions.append(m.positions if obj.rigid else obj.slice_positions[0])
            corners.append(m.triangles.astype(accel.triangles.dtype) + base)
            base += len(positions[-1])
        self.positions = positions[0] if len(positions) == 1 else np.concatenate(positions)
        self.corners = corners[0] if len(corners) == 1 else np.concatenate(corners)
        # Unit normals and offset scales are computed per hit (normals(), scales(); the
        # compiled kernels likewise), not stored per triangle.
        self.material = (np.concatenate([m.material_indices for m in ordered]).astype(np.int64)
                         if ordered else np.zeros(0, np.int64))
        # Holdout triangles (None when the scene has none): camera rays end there.
        self.holdout = (np.concatenate([np.full(len(m.triangles), m.holdout) for m in ordered])
                        if any(m.holdout for m in ordered) else None)
        # The ray kinds that see each triangle (engine.visibility); None when all see all.
        self.visibility = (np.concatenate([np.full(len(m.triangles), m.visibility, np.uint8)
                                           for m in ordered])
                           if any(m.visibility != 31 for m in ordered) else None)
        self.tri_object, self.objects = _object_table(ordered)
        # Tangent space per corner for Normal Maps (sign 0 where a mesh has none), and
        # a color attribute per corner (0 where a mesh has none, as in Cycles)
        self.corner_tangents = _corner_attribute(ordered, "tangents")
        self.corner_colors = _corner_attribute(ordered, "colors")
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
        self.terminator_cutoff = _terminator_cutoff(ordered, accel.static_count)
        # Texture coordinates per triangle corner (Blender's UV map), for the meshes that
        # have them; triangles of meshes without UVs read (0, 0), as in Cycles.
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

    def shader_rows(self, si: SurfaceHit, ray=1, depth=0) -> np.ndarray:
        """The hit rows shader programs read (engine.nodes.context) for the hits si."""
        from .nodes.context import hit_rows
        obj = self.tri_object[si.prim] if self.tri_object is not None else None
        tangent = None
        if self.corner_tangents is not None:
            c = self.corner_tangents[si.prim].astype(np.float64)
            u, v = si.bary[:, :1], si.bary[:, 1:]
            tangent = (1.0 - u - v) * c[:, 0] + u * c[:, 1] + v * c[:, 2]
            t = tangent[:, :3]
            tangent[:, :3] = t / np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-300)
            tangent[:, 3] = np.sign(tangent[:, 3])
        color = None
        if self.corner_colors is not None:
            c = self.corner_colors[si.prim].astype(np.float64)
            u, v = si.bary[:, :1], si.bary[:, 1:]
            color = (1.0 - u - v) * c[:, 0] + u * c[:, 1] + v * c[:, 2]
        return hit_rows(si.position, si.shading_normal, si.geometric_normal, si.direction,
                        si.uv, si.front_facing, ray, depth, None, self.objects, obj, tangent,
                        color)

    def vertices(self, prim) -> tuple:
        """The three corners (n, 3) of triangles `prim` (moving ones: placeholders)."""
        c = self.corners[prim]
        return self.positions[c[:, 0]], self.positions[c[:, 1]], self.positions[c[:, 2]]

    def normals(self, prim) -> np.ndarray:
        """Unit geometric normals (n, 3) of triangles `prim` (moving ones: placeholders)."""
        return _corner_normals(*self.vertices(prim))

    def scales(self, prim, vertices=None) -> np.ndarray:
        """The offset scales of triangles `prim`: their coordinates' magnitude, relative to
        the static scene's centre (engine.accel) for static triangles, absolute for
        moving ones (at `vertices`, their corners where the ray's time put them)."""
        v0, v1, v2 = self.vertices(prim) if vertices is None else vertices
        static = (prim < self.accel.static_count)[:, None]
        return triangle_scale(v0, v1, v2, np.where(static, self.accel.center, 0.0))

    def _moving_vertices(self, prim, time):
        """World vertices, normal matrices (or None) of hit triangles at the rays' times."""
        v0, v1, v2 = self.vertices(prim)
        normal_m = None
        for obj in self.accel.moving:
            lo, hi = obj.prim_offset, obj.prim_offset + len(obj.mesh.triangles)
            rows = np.nonzero((prim >= lo) & (prim < hi))[0]
            if rows.size == 0:
                continue
            local = prim[rows] - lo
            tri = obj.mesh.triangles[local]
            if obj.rigid:
                m = obj.mesh.motion.at(time[rows])
                a, t = m[:, :3, :3], m[:, :3, 3]
                for dst, k in ((v0, 0), (v1, 1), (v2, 2)):
                    dst[rows] = np.einsum("nij,nj->ni", a, obj.mesh.positions[tri[:, k]]) + t
                if normal_m is None:
                    normal_m = np.broadcast_to(np.eye(3), (len(prim), 3, 3)).copy()
                normal_m[rows] = np.transpose(inverse3(a), (0, 2, 1))
            else:
                sl = obj.mesh.motion.slice_of(time[rows])
                for s in np.unique(sl):
                    r = rows[sl == s]
                    pos = obj.slice_positions[s]
                    tr = tri[sl == s]
                    v0[r], v1[r], v2[r] = pos[tr[:, 0]], pos[tr[:, 1]], pos[tr[:, 2]]
        return v0, v1, v2, normal_m

    def build(self, hits: Hits, index: np.ndarray, ray_dirs: np.ndarray,
              time: np.ndarray | None = None) -> SurfaceHit:
        """Interactions for the rays `index` (which must all have hit); `time` is the
        per-ray shutter time of all rays (needed when the scene has moving objects)."""
        prim = hits.prim[index]
        u = hits.u[index][:, None]
        v = hits.v[index][:, None]
        w = 1.0 - u - v
        normal_m = None
        if self.accel.moving and (prim >= self.accel.static_count).any():
            v0, v1, v2, normal_m = self._moving_vertices(prim, time[index])
            ng = _corner_normals(v0, v1, v2)
            tri_scale = self.scales(prim, (v0, v1, v2))
        else:
            v0, v1, v2 = self.vertices(prim)
            ng = _corner_normals(v0, v1, v2)
            tri_scale = self.scales(prim, (v0, v1, v2))
        pos = w * v0 + u * v1 + v * v2
        d = ray_dirs[index]
        front = (ng * d).sum(1) < 0.0
        sign = np.where(front, 1.0, -1.0)[:, None]
        ng_f = ng * sign
        if self.corner_normals is not None:
            cn = self.corner_normals[prim].astype(np.float64)
            if normal_m is not None:
                cn = np.einsum("nij,nkj->nki", normal_m, cn)
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
        scale = tri_scale              # bounds the hit point's coordinates too
        uv = None
        if self.corner_uvs is not None:
            # the same barycentric weights as the position: w vertex 0, u vertex 1, v vertex 2
            cu = self.corner_uvs[prim].astype(np.float64)
            uv = w * cu[:, 0] + u * cu[:, 1] + v * cu[:, 2]
        return SurfaceHit(pos, ng_f, ns, front, self.material[prim], scale, uv, prim,
                          np.asarray(ray_dirs)[index], np.hstack([u, v]))


def _corner_attribute(ordered, name):
    """(T, 3, 4) float32 of every mesh's per-corner attribute `name` (zeros for meshes
    without it), or None when no mesh has it."""
    if not any(getattr(m, name, None) is not None for m in ordered):
        return None
    return np.concatenate([np.asarray(getattr(m, name), np.float32).reshape(-1, 3, 4)
                           if getattr(m, name, None) is not None
                           else np.zeros((len(m.triangles), 3, 4), np.float32)
                           for m in ordered])


def _terminator_cutoff(ordered, static_count):
    """Each triangle's Shadow Terminator Geometry Offset (engine.kernels.terminator), 0
    where there is no curved surface to start shadow rays from: flat meshes and moving
    objects' triangles (from static_count on); None when no triangle has one."""
    if not any(m.corner_normals is not None for m in ordered):
        return None
    cut = np.concatenate([np.full(len(m.triangles), getattr(m, "terminator_offset", 0.1)
                                  if m.corner_normals is not None else 0.0)
                          for m in ordered])
    cut[static_count:] = 0.0
    return cut if (cut > 0.0).any() else None


def _object_table(ordered):
    """(each triangle's object (int32), the object table (engine.nodes.context O_* rows))
    when some mesh carries ObjectInfo (its materials run shader programs), else (None,
    None). A mesh without it is the identity object with its bounding box as texture
    space."""
    if not any(getattr(m, "object_info", None) is not None for m in ordered):
        return None, None
    from .nodes.context import N_OBJ, object_row
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
    return np.repeat(np.arange(len(ordered), dtype=np.int32), counts), rows


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


def offset_origin(position: np.ndarray, normal: np.ndarray, scale: np.ndarray,
                  direction: np.ndarray) -> np.ndarray:
    """Move origins off the surface to the side `direction` leaves towards."""
    side = np.where((normal * direction).sum(1) >= 0.0, 1.0, -1.0)[:, None]
    eps = (RELATIVE_OFFSET * np.maximum(scale, 1e-30))[:, None]
    return position + normal * (eps * side)
