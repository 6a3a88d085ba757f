"""True displacement: Material > Settings > Displacement set to Displacement Only or
Displacement and Bump moves a mesh's vertices by its material's displacement before the
acceleration structure is built, as Cycles' GeometryManager::displace does
(scene/mesh_displace.cpp):

- each vertex moves once, by the first triangle (in the mesh's order) whose material
  displaces, read at that triangle's corner (its UV, tangent and colour) with the
  vertex's smooth normal (Cycles forces smooth shading for displacement, whatever the
  face's shading);
- the offset is the displacement vector taken into the object's space; a non-finite
  offset is 0 (Cycles' ensure_finite);
- Displacement Only: the normals of the displaced triangles are recomputed, each vertex's
  as the normalised sum of the unit normals of its displaced triangles (Cycles' rule, not
  Blender's angle-weighted one); flat faces take their new face normal. Displacement and
  Bump keeps the undisplaced normals, which the material's bump then bends.

The surface keeps what Cycles keeps of the undisplaced mesh: TriangleMesh.undisplaced,
each corner's object-space position before it moved, from which hits read Generated
texture coordinates, and a Displacement and Bump material's bump its undisplaced point
(engine.nodes.context H_UNDISPLACED, engine.nodes.bump DISP_ENTER).

All of it runs once per mesh at export, in NumPy and the shader program's compiled
interpreter, over the mesh's vertices; a scene without true displacement never calls it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from .nodes.context import hit_rows
from .nodes.interpreter import evaluate_registers

SPACES = ("OBJECT", "WORLD", "TANGENT")


@dataclass
class Displacement:
    """What a material's Displacement socket computes, to move vertices by.

    program: the displacement's own engine.nodes ShaderProgram (surface hits never run it).
    kind 'NORMAL', a Displacement node: (Height - Midlevel) x Scale (`height`, a float
      Value) along `direction` (a vector Value: its Normal, world space), taken into
      object space and normalised there when `space` is 'OBJECT' (the node's default),
      used as it is for 'WORLD'.
    kind 'VECTOR', a Vector Displacement node or any vector linked to the socket:
      `direction` is the offset; 'TANGENT' reads it as (tangent, normal, bitangent)
      components in object space (Cycles' order), 'OBJECT' as object space, 'WORLD' as
      world space.
    keep_normals: Displacement and Bump (the undisplaced normals stay, for the bump)."""
    program: object
    direction: object
    height: object = None
    kind: str = "NORMAL"
    space: str = "OBJECT"
    keep_normals: bool = False

    def __post_init__(self):
        if self.kind not in ("NORMAL", "VECTOR"):
            raise ValueError(f"displacement kind must be NORMAL or VECTOR, got {self.kind!r}")
        if self.space not in SPACES or (self.kind == "NORMAL" and self.space == "TANGENT"):
            raise ValueError(f"displacement space {self.space!r} is not one of {SPACES}")
        if self.kind == "NORMAL" and self.height is None:
            raise ValueError("a NORMAL displacement needs its height")


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.divide(v, n, out=np.zeros_like(v), where=n > 0.0)


def face_normals(positions: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Unit normals (T, 3) of the triangles by their winding (0 for a degenerate one)."""
    a, b, c = (positions[triangles[:, k]] for k in range(3))
    return _unit(np.cross(b - a, c - a))


def first_corners(triangles: np.ndarray, displaced: np.ndarray):
    """(vertex, triangle, corner) of each vertex's first corner, in the mesh's order, on a
    triangle that `displaced` (T,) marks; the vertices in increasing order."""
    tri = np.flatnonzero(displaced)
    flat = triangles[tri].reshape(-1)
    vertex, first = np.unique(flat, return_index=True)
    return vertex, tri[first // 3], first % 3


def _world_rows(positions, vertex_normals, triangles, vertex, tri, corner, matrix, object_row,
                uvs, tangents, colors):
    """The hit rows (engine.nodes.context) of the chosen corners, in the world."""
    m3, t = matrix[:3, :3], matrix[:3, 3]
    det = np.linalg.det(m3)
    normal_matrix = np.linalg.inv(m3).T if abs(det) > 1e-300 else m3
    p = positions[vertex] @ m3.T + t
    n = _unit(vertex_normals[vertex] @ normal_matrix.T)
    ng = _unit(face_normals(positions, triangles[tri]) @ normal_matrix.T)
    n = np.where(np.linalg.norm(n, axis=1, keepdims=True) > 0.0, n, ng)
    uv = None if uvs is None else uvs[tri, corner].astype(np.float64)
    tan = None
    if tangents is not None:
        tt = tangents[tri, corner].astype(np.float64)
        tan = np.column_stack([_unit(tt[:, :3] @ m3.T), tt[:, 3] * (1.0 if det >= 0 else -1.0)])
    col = None if colors is None else colors[tri, corner].astype(np.float64)
    return hit_rows(p, n, geometric_normal=ng, uv=uv, objects=object_row[None, :], obj=0,
                    tangent=tan, color=col)


def _offsets(d: Displacement, regs, matrix, vertex_normals_obj, tangents_obj):
    """Object-space offsets (n, 3) of a displacement's registers at n vertices."""
    def vec(value):
        return regs[:, value.reg:value.reg + 3]
    m3 = matrix[:3, :3]
    inv = np.linalg.pinv(m3)
    if d.kind == "NORMAL":
        h = regs[:, d.height.reg][:, None]
        n = vec(d.direction)
        if d.space == "OBJECT":
            return _unit(n @ m3) * h          # M^T n, normalised: the normal in object space
        return (n * h) @ inv.T
    v = vec(d.direction)
    if d.space == "WORLD":
        return v @ inv.T
    if d.space == "OBJECT":
        return v
    # tangent space, in object space: x along the tangent, y the normal, z the bitangent
    n = _unit(vertex_normals_obj)
    if tangents_obj is None:
        t = np.zeros_like(n)
        sign = np.ones(len(n))
    else:
        t, sign = _unit(tangents_obj[:, :3]), tangents_obj[:, 3]
    b = _unit(np.cross(n, t)) * np.where(sign != 0.0, sign, 1.0)[:, None]
    return t * v[:, :1] + n * v[:, 1:2] + b * v[:, 2:3]


def displace(positions: np.ndarray, triangles: np.ndarray, material: np.ndarray,
             vertex_normals: np.ndarray, displacements: Sequence[Optional[Displacement]],
             matrix: np.ndarray, object_row: np.ndarray, uvs=None, tangents=None,
             colors=None):
    """The displaced positions (V, 3) of an object-space mesh, and the triangles (T,) bool
    whose material displaces it.

    positions, vertex_normals: (V, 3) object space (the vertices' smooth normals);
    triangles (T, 3); material (T,) indexes `displacements` (None: not displaced);
    matrix: the object's 4 x 4 object -> world; object_row: its engine.nodes.context O_*
    row (texture space, Object Info); uvs (T, 3, 2), tangents (T, 3, 4) object space,
    colors (T, 3, 4): corner attributes, or None."""
    positions = np.asarray(positions, np.float64)
    matrix = np.asarray(matrix, np.float64)
    material = np.asarray(material, np.int64)
    has = np.array([d is not None for d in displacements] + [False], bool)
    displaced = has[np.clip(material, 0, len(has) - 1)] & (material >= 0)
    if not displaced.any():
        return positions, displaced
    vertex, tri, corner = first_corners(triangles, displaced)
    rows = _world_rows(positions, np.asarray(vertex_normals, np.float64), triangles, vertex,
                       tri, corner, matrix, np.asarray(object_row, np.float64), uvs,
                       tangents, colors)
    out = positions.copy()
    by = material[tri]
    for k in np.unique(by):
        d = displacements[k]
        pick = by == k
        regs = evaluate_registers(d.program, rows[pick])
        tan = None if tangents is None else tangents[tri[pick], corner[pick]].astype(np.float64)
        off = _offsets(d, regs, matrix, np.asarray(vertex_normals, np.float64)[vertex[pick]],
                       tan)
        off = np.where(np.isfinite(off), off, 0.0)
        out[vertex[pick]] += off
    return out, displaced


def displaced_normals(positions: np.ndarray, triangles: np.ndarray, recompute: np.ndarray,
                      corner_normals: Optional[np.ndarray], smooth: Optional[np.ndarray]):
    """Corner normals (T, 3, 3) float32 after Displacement Only moved the triangles that
    `recompute` (T,) marks: on those, a smooth triangle's corners take the normalised sum
    of the unit normals of the recomputed triangles around each vertex, a flat one its
    own face normal; the other triangles keep `corner_normals`. corner_normals None
    (every face flat) stays None; smooth: (T,) bool, None: all smooth."""
    if corner_normals is None or not np.any(recompute):
        return corner_normals
    fn = face_normals(positions, triangles)
    summed = np.zeros((len(positions), 3))
    idx = np.flatnonzero(recompute)
    for k in range(3):
        np.add.at(summed, triangles[idx, k], fn[idx])
    vn = _unit(summed)
    out = np.array(corner_normals, np.float32, copy=True)
    smooth_here = np.ones(len(triangles), bool) if smooth is None else np.asarray(smooth, bool)
    s = idx[smooth_here[idx]]
    f = idx[~smooth_here[idx]]
    out[s] = vn[triangles[s]]
    out[f] = np.repeat(fn[f][:, None, :], 3, axis=1)
    return out


def bumped_from_vertex_normals(positions: np.ndarray, triangles: np.ndarray,
                               kept: np.ndarray, corner_normals: Optional[np.ndarray],
                               smooth: Optional[np.ndarray], vertex_normals: np.ndarray):
    """Corner normals (T, 3, 3) float32 where Displacement and Bump moved flat faces
    (`kept`, (T,) bool): Cycles bumps those from the undisplaced vertex normals (its
    undisplaced-normal attribute, smooth whatever the face's shading), not from the
    moved face's own normal, so they take the vertex normals; every other flat face keeps
    its own (moved) face normal. Unchanged when no flat face was so moved."""
    smooth_here = np.ones(len(triangles), bool) if smooth is None else np.asarray(smooth, bool)
    flat = np.asarray(kept, bool) & ~smooth_here
    if not flat.any():
        return corner_normals
    if corner_normals is None:
        corner_normals = np.repeat(face_normals(positions, triangles)[:, None, :], 3, axis=1)
    out = np.array(corner_normals, np.float32, copy=True)
    out[flat] = _unit(np.asarray(vertex_normals, np.float64))[triangles[flat]]
    return out
