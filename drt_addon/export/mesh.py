"""Evaluated Blender meshes to world-space triangle arrays, via foreach_get.

Object-space arrays are read once per distinct evaluated geometry and reused for every
instance of it within one export (`MeshCache`): linked duplicates without modifiers,
collection instances and geometry-node instances share one evaluated mesh, so a forest of
a thousand instanced trees costs one `to_mesh` and a thousand matrix products.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..engine_link import engine
from .errors import ExportError
from ..blender_compat import prepare_corner_normals
from .matrices import to_numpy
from .layer_overrides import slot_materials
from .tangents import mesh_tangents, uv_layer, wants_tangents
from .vertex_colors import color_request, mesh_colors
from .nodes.displacement import moves_surface

GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT", "CURVES"}
_BLOCK = 1 << 16          # triangles per block of the degenerate-triangle test


@dataclass
class LocalMesh:
    """One evaluated geometry in object space."""
    positions: np.ndarray                  # (V, 3) float64
    triangles: np.ndarray                  # (T, 3) int32
    material: np.ndarray                   # (T,) int32 material slot index
    normals: Optional[np.ndarray] = None   # (T, 3, 3) float32 split normals, None if all flat
    uvs: Optional[np.ndarray] = None       # (T, 3, 2) float32 corner UVs, None if not needed
    uv_request: Optional[str] = None       # the UV map asked for ('' = default), None = none
    kept: Optional[np.ndarray] = None      # indices of the mesh's triangles kept (None: all)
    tangents: Optional[np.ndarray] = None  # (T, 3, 4) float32 tangent + sign, if wanted
    colors: Optional[np.ndarray] = None    # (T, 3, 4) float32 color attribute, if wanted
    # for true displacement (export.displacement), read only for objects whose materials
    # move their surface: the vertices' smooth normals, each triangle's smooth shading,
    # and, once displaced, each vertex's object-space offset
    vertex_normals: Optional[np.ndarray] = None   # (V, 3) float64
    smooth: Optional[np.ndarray] = None           # (T,) bool
    offset: Optional[np.ndarray] = None           # (V, 3) float64
    # a mesh diced by adaptive subdivision (export.dicing): (the LocalMesh it was diced
    # from, the engine.dicing.Diced that maps its vertices to the new ones)
    diced_from: Optional[tuple] = None


def _attribute(mesh, name: str, field: str, dtype, domain: str, components: int = 1):
    """A built-in attribute's values (flat, `components` per element), read as one block;
    None when the mesh has no such attribute on that domain. Reading Blender's
    per-element RNA properties instead (vertices' `co`, polygons' `material_index` and
    `use_smooth`) costs 0.05 to 0.2 s per million elements."""
    attr = mesh.attributes.get(name)
    if attr is None or attr.domain != domain:
        return None
    out = np.empty(len(attr.data) * components, dtype=dtype)
    attr.data.foreach_get(field, out)
    return out


def _triangle_materials(mesh, nt: int) -> np.ndarray:
    """Each loop triangle's material slot index: its face's `material_index` attribute
    (all 0 without one, as in Blender)."""
    faces = _attribute(mesh, "material_index", "value", np.int32, "FACE")
    if faces is None:
        return np.zeros(nt, dtype=np.int32)
    tri_face = np.empty(nt, dtype=np.int32)
    mesh.loop_triangle_polygons.foreach_get("value", tri_face)
    return faces[tri_face]


def mesh_arrays(mesh):
    """(positions (V,3) f64, triangles (T,3) i32, material index (T,) i32,
    corner normals (T,3,3) f32 or None) in object space (mesh_uvs gives the UVs)."""
    mesh.calc_loop_triangles()
    nv = len(mesh.vertices)
    nt = len(mesh.loop_triangles)
    co = _attribute(mesh, "position", "vector", np.float32, "POINT", 3)
    if co is None or len(co) != nv * 3:
        co = np.empty(nv * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", co)
    tris = np.empty(nt * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    mat = _triangle_materials(mesh, nt)
    normals = None
    if nt and _has_smooth_faces(mesh):
        prepare_corner_normals(mesh)
        normals = np.empty(nt * 9, dtype=np.float32)
        mesh.loop_triangles.foreach_get("split_normals", normals)
        normals = normals.reshape(nt, 3, 3)
    return co.reshape(nv, 3).astype(np.float64), tris.reshape(nt, 3), mat, normals


def mesh_uvs(mesh, name: str = "") -> Optional[np.ndarray]:
    """Per-corner texture coordinates (T, 3, 2) float32 of the loop triangles (call after
    `mesh_arrays`, which computes them), from the UV map `name`, or for '' (or a name the
    mesh lacks) the map Cycles uses by default: the active render UV map (Blender's camera
    icon in the UV Maps list), else the active one. None when the mesh has no UV map:
    Cycles then reads (0, 0, 0) as UV, which the tracer does for a mesh without UVs."""
    layer = uv_layer(mesh, name)
    if layer is None:
        return None
    nt = len(mesh.loop_triangles)
    loops = np.empty(nt * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("loops", loops)
    uv = np.empty(len(mesh.loops) * 2, dtype=np.float32)
    if hasattr(layer, "uv"):                       # Blender 3.5+
        layer.uv.foreach_get("vector", uv)
    else:                                          # Blender 3.4
        layer.data.foreach_get("uv", uv)
    return uv.reshape(-1, 2)[loops].reshape(nt, 3, 2)


def uv_request(materials) -> Optional[str]:
    """Which UV map an object's materials (layer_overrides.slot_materials) read through
    image textures: None (no textures, no UVs exported), '' (the default map) or a UV
    map's name (the first one a UV Map node names)."""
    from .materials import material_uv_maps
    names = set()
    for mat in materials:
        found = material_uv_maps(mat)
        if found:
            names |= found
    if not names:
        return None
    named = sorted(n for n in names if n)
    return named[0] if named else ""


def _has_smooth_faces(mesh) -> bool:
    """Whether any face is smooth shaded: not all of the `sharp_face` attribute is set
    (every face is smooth without one)."""
    n = len(mesh.polygons)
    if n == 0:
        return False
    sharp = _attribute(mesh, "sharp_face", "value", bool, "FACE")
    return sharp is None or not bool(sharp.all())


def _cache_key(obj):
    """What identifies an evaluated geometry within one depsgraph.

    For meshes, the evaluated object's data is the evaluated mesh (modifiers applied): two
    objects share it only when they share the mesh and neither has modifiers, so its
    address is the key. Names are not: every evaluated mesh keeps its original's name.
    Other types (curves, text, metaballs) keep their original data after evaluation, so
    the evaluated object is part of the key."""
    data = getattr(obj, "data", None)
    if data is None:
        return None
    if obj.type == "MESH":
        return ("MESH", data.as_pointer())
    original = obj.original
    return (obj.type, original.as_pointer() if original is not None else obj.as_pointer(),
            data.as_pointer())


class MeshCache:
    """Object-space arrays per evaluated geometry, for the length of one export."""

    def __init__(self, reporter=None, uv_pass=False, override=None):
        self._local = {}
        self.reporter = reporter
        self.uv_pass = uv_pass    # every mesh's UVs: the UV pass reads them
        self.override = override  # View Layer > Override > Material (layer_overrides)
        self.evaluations = 0      # to_mesh calls
        self.reuses = 0           # instances served from the cache

    def key(self, obj):
        """What identifies `obj`'s evaluated geometry in this cache (`_cache_key`)."""
        return _cache_key(obj)

    def local(self, obj) -> Optional[LocalMesh]:
        key = self.key(obj)
        materials = slot_materials(obj, self.override)
        want_uv = uv_request(materials)
        if want_uv is None and self.uv_pass:
            want_uv = ""
        want_tangents = wants_tangents(materials)
        want_colors = color_request(materials)
        want_normals = moves_surface(materials)
        if key is not None and key in self._local:
            cached = self._local[key]
            # a shared mesh whose other user needed no UVs (object-linked materials)
            if cached is None or ((want_uv is None or cached.uv_request == want_uv)
                                  and (not want_tangents or cached.tangents is not None)
                                  and (want_colors is None or cached.colors is not None)
                                  and (not want_normals or cached.vertex_normals is not None)):
                self.reuses += 1
                return cached
        local = _evaluate(obj, want_uv, self.reporter, want_tangents, want_colors,
                          want_normals)
        self.evaluations += 1
        if key is not None:
            self._local[key] = local
        return local


def degenerate_triangles(pos: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Triangles Cycles skips: a corner at a non-finite (NaN or infinite) position, or two
    corners at the same position. Returns a boolean mask (T,)."""
    finite = np.isfinite(pos).all(axis=1)
    bad = ~finite[tris].all(axis=1)
    # Two corners can only coincide where their x coordinates do: the whole test runs on
    # those triangles only, block by block (the corners' positions of a whole 1M-triangle
    # mesh would be 72 MB).
    x = np.ascontiguousarray(pos[:, 0])
    for start in range(0, len(tris), _BLOCK):
        t = tris[start:start + _BLOCK]
        tx = x[t]
        with np.errstate(invalid="ignore"):
            maybe = np.flatnonzero((tx[:, 0] == tx[:, 1]) | (tx[:, 1] == tx[:, 2])
                                   | (tx[:, 0] == tx[:, 2]))
            a, b, c = pos[t[maybe, 0]], pos[t[maybe, 1]], pos[t[maybe, 2]]
            bad[start + maybe] |= ((a == b).all(axis=1) | (b == c).all(axis=1)
                                   | (a == c).all(axis=1))
    return bad


def _drop_degenerate(obj, pos, tris, mat, normals, uvs, reporter):
    """The mesh without its degenerate triangles (see `degenerate_triangles`), with one
    warning per object; non-finite vertices left unused are moved onto a used one so
    that every position is finite. Returns (pos, tris, mat, normals, uvs, kept)."""
    bad = degenerate_triangles(pos, tris)
    if not bad.any():
        return pos, tris, mat, normals, uvs, None
    kept = np.flatnonzero(~bad)
    if reporter is not None:
        reporter.warn(f"DRT: object {obj.name!r}: {int(bad.sum())} of {len(tris)} triangles "
                      "have non-finite (NaN or infinite) or coincident vertices; they are "
                      "skipped, as Cycles does", key=(obj.name, "degenerate"))
    tris, mat = tris[kept], mat[kept]
    normals = normals[kept] if normals is not None else None
    uvs = uvs[kept] if uvs is not None else None
    finite = np.isfinite(pos).all(axis=1)
    if not finite.all():
        pos = pos.copy()
        pos[~finite] = pos[tris[0, 0]] if len(tris) else 0.0
    return pos, tris, mat, normals, uvs, kept


def vertex_normals(mesh) -> np.ndarray:
    """The vertices' smooth normals (V, 3) float64, object space (Blender's, which Cycles
    reads)."""
    out = np.empty(len(mesh.vertices) * 3, np.float32)
    if hasattr(mesh, "vertex_normals"):                  # Blender 3.5+
        mesh.vertex_normals.foreach_get("vector", out)
    else:
        mesh.vertices.foreach_get("normal", out)
    return out.reshape(-1, 3).astype(np.float64)


def smooth_triangles(mesh) -> np.ndarray:
    """Whether each loop triangle's face is smooth shaded (T,) bool."""
    nt = len(mesh.loop_triangles)
    sharp = _attribute(mesh, "sharp_face", "value", bool, "FACE")
    if sharp is None:
        return np.ones(nt, bool)
    tri_face = np.empty(nt, dtype=np.int32)
    mesh.loop_triangle_polygons.foreach_get("value", tri_face)
    return ~sharp[tri_face]


def _evaluate(obj, want_uv: Optional[str] = None, reporter=None,
              want_tangents=False, want_colors: Optional[str] = None,
              want_normals=False) -> Optional[LocalMesh]:
    try:
        mesh = obj.to_mesh()
    except RuntimeError as e:     # one object Blender cannot turn into a mesh: the rest renders
        if reporter is not None:
            reporter.warn(f"DRT: object {obj.name!r} is left out: Blender cannot evaluate "
                          f"its mesh ({str(e).strip()})", key=(obj.name, "to_mesh"))
        return None
    uvs = tangents = colors = vnormals = smooth = None
    try:
        if mesh is None:
            return None
        pos, tris, mat, normals = mesh_arrays(mesh)
        if want_normals and len(tris):
            vnormals, smooth = vertex_normals(mesh), smooth_triangles(mesh)
        if want_uv is not None and len(tris):
            uvs = mesh_uvs(mesh, want_uv)
        if want_tangents and len(tris):
            tangents = mesh_tangents(mesh, pos, tris, normals, want_uv or "")
        if want_colors is not None and len(tris):
            colors = mesh_colors(mesh, want_colors)
    finally:
        obj.to_mesh_clear()
    if len(tris) == 0:
        return None
    pos, tris, mat, normals, uvs, kept = _drop_degenerate(obj, pos, tris, mat, normals, uvs,
                                                          reporter)
    if len(tris) == 0:
        return None
    if normals is not None and not np.all(np.isfinite(normals)):
        normals = None                        # degenerate faces: fall back to flat shading
    if uvs is not None and not np.all(np.isfinite(uvs)):
        uvs = np.where(np.isfinite(uvs), uvs, 0.0).astype(np.float32)
    if tangents is not None:
        tangents = tangents[kept] if kept is not None else tangents
        tangents = np.where(np.isfinite(tangents), tangents, 0.0).astype(np.float32)
    if colors is not None:
        colors = colors[kept] if kept is not None else colors
        colors = np.where(np.isfinite(colors), colors, 0.0).astype(np.float32)
    if vnormals is not None:
        vnormals = np.where(np.isfinite(vnormals), vnormals, 0.0)
        smooth = smooth[kept] if kept is not None else smooth
    return LocalMesh(pos, tris, mat, normals, uvs, want_uv, kept, tangents, colors,
                     vnormals, smooth)


def instance_mesh(local: LocalMesh, matrix_world, material_slots, name) -> "engine.TriangleMesh":
    """A LocalMesh placed in the world by `matrix_world`.

    material_slots: global material index per material slot of the instanced object."""
    m = to_numpy(matrix_world)
    m3 = m[:3, :3]
    if not np.all(np.isfinite(m)):
        raise ExportError(f"object {name!r} has a non-finite transform")
    world = local.positions @ m3.T + m[:3, 3]
    tris = local.triangles
    normals = local.normals
    uvs = local.uvs
    tangents = local.tangents           # object space (engine.nodes.tangent_frame)
    colors = local.colors
    undisplaced = undisplaced_corners(local)
    det = float(np.linalg.det(m3))
    if normals is not None:
        normal_matrix = np.linalg.inv(m3).T if abs(det) > 1e-300 else m3
        nw = normals.reshape(-1, 3).astype(np.float64) @ normal_matrix.T
        if cycles_applies_transform(local):
            nw /= np.maximum(np.linalg.norm(nw, axis=1, keepdims=True), 1e-300)
        normals = nw.reshape(-1, 3, 3).astype(np.float32)
    if det < 0:
        # A mirroring transform flips the winding; swap two corners so that the geometric
        # normal still points to the side Blender's normals point to.
        tris = tris[:, [0, 2, 1]]
        if normals is not None:
            normals = normals[:, [0, 2, 1]]
        if uvs is not None:
            uvs = uvs[:, [0, 2, 1]]
        if tangents is not None:
            tangents = tangents[:, [0, 2, 1]]
        if colors is not None:
            colors = colors[:, [0, 2, 1]]
        if undisplaced is not None:
            undisplaced = undisplaced[:, [0, 2, 1]]
    slots = np.asarray(material_slots if len(material_slots) else [0], dtype=np.int32)
    global_mat = slots[np.clip(local.material, 0, len(slots) - 1)]
    return engine.TriangleMesh(name, world, tris, global_mat, corner_normals=normals, uvs=uvs,
                               tangents=tangents, colors=colors, undisplaced=undisplaced,
                               flat_faces=flat_faces(local))


def cycles_applies_transform(local: LocalMesh) -> bool:
    """Whether Cycles moves this mesh into the world before rendering (its
    ObjectManager::apply_static_transforms), and so interpolates its smooth normals there,
    each vertex's normalised; it keeps a mesh with true displacement or adaptive
    subdivision in its object space, where the normals are interpolated before they are
    taken to the world. Unnormalised world corner normals give the latter (a hit
    interpolates and then normalises them); they differ under a non-uniform scale."""
    return local.offset is None and local.diced_from is None


def flat_faces(local: LocalMesh) -> Optional[np.ndarray]:
    """The faces shaded flat of a displaced mesh with corner normals (T,) bool
    (engine.TriangleMesh.flat_faces: Displacement and Bump gives them the undisplaced
    vertex normals); None for any other mesh, whose flat faces have their own normals."""
    if local.offset is None or local.smooth is None or local.normals is None:
        return None
    flat = ~np.asarray(local.smooth, bool)
    return flat if flat.any() else None


def undisplaced_corners(local: LocalMesh) -> Optional[np.ndarray]:
    """A displaced mesh's corners (T, 3, 3) float32 before displacement, object space
    (engine.TriangleMesh.undisplaced); None for a mesh that was not displaced."""
    if local.offset is None:
        return None
    return (local.positions - local.offset)[local.triangles].astype(np.float32)


def export_mesh_instance(obj, matrix_world, material_slots, name,
                         cache: Optional[MeshCache] = None) -> "engine.TriangleMesh | None":
    """One evaluated object instance as a world-space TriangleMesh (None if empty)."""
    local = (cache or MeshCache()).local(obj)
    if local is None:
        return None
    return instance_mesh(local, matrix_world, material_slots, name)
