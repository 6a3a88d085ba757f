"""Evaluated Blender meshes to world-space triangle arrays, via foreach_get."""
from __future__ import annotations

import numpy as np

from ..engine_link import engine
from .errors import ExportError
from .matrices import to_numpy

GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT", "CURVES"}


def mesh_arrays(mesh):
    """(positions (V,3) f64, triangles (T,3) i32, material index (T,) i32,
    corner normals (T,3,3) f32 or None) in object space."""
    mesh.calc_loop_triangles()
    nv = len(mesh.vertices)
    nt = len(mesh.loop_triangles)
    co = np.empty(nv * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    tris = np.empty(nt * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    mat = np.empty(nt, dtype=np.int32)
    mesh.loop_triangles.foreach_get("material_index", mat)
    normals = None
    if nt and _has_smooth_faces(mesh):
        normals = np.empty(nt * 9, dtype=np.float32)
        mesh.loop_triangles.foreach_get("split_normals", normals)
        normals = normals.reshape(nt, 3, 3)
    return co.reshape(nv, 3).astype(np.float64), tris.reshape(nt, 3), mat, normals


def _has_smooth_faces(mesh) -> bool:
    n = len(mesh.polygons)
    if n == 0:
        return False
    smooth = np.empty(n, dtype=bool)
    mesh.polygons.foreach_get("use_smooth", smooth)
    return bool(smooth.any())


def export_mesh_instance(obj, matrix_world, material_slots, name) -> "engine.TriangleMesh | None":
    """One evaluated object instance as a world-space TriangleMesh (None if empty).

    material_slots: global material index per slot of this object."""
    try:
        mesh = obj.to_mesh()
    except RuntimeError as e:
        raise ExportError(f"object {obj.name!r}: cannot evaluate its mesh ({e})") from e
    if mesh is None:
        return None
    try:
        pos, tris, mat, normals = mesh_arrays(mesh)
    finally:
        obj.to_mesh_clear()
    if len(tris) == 0:
        return None
    if not np.all(np.isfinite(pos)):
        raise ExportError(f"object {obj.name!r} has non-finite (NaN or Inf) vertex positions")
    m = to_numpy(matrix_world)
    world = pos @ m[:3, :3].T + m[:3, 3]
    if normals is not None:
        normal_matrix = np.linalg.inv(m[:3, :3]).T if abs(np.linalg.det(m[:3, :3])) > 1e-300 \
            else m[:3, :3]
        nw = normals.reshape(-1, 3).astype(np.float64) @ normal_matrix.T
        nw /= np.maximum(np.linalg.norm(nw, axis=1, keepdims=True), 1e-300)
        normals = nw.reshape(-1, 3, 3).astype(np.float32)
    slots = np.asarray(material_slots if len(material_slots) else [0], dtype=np.int32)
    global_mat = slots[np.clip(mat, 0, len(slots) - 1)]
    return engine.TriangleMesh(name, world, tris, global_mat, corner_normals=normals)
