"""Instances: one mesh kept once and placed K times (engine.scene.Instances).

Embree traces an instanced mesh as one scene of its own, in object space, and each place
as an instance of it (engine.accel): a ray is moved into the instance's space by
Embree, and the hit is rebuilt in float64 in world space by the place's matrix
(engine.kernels.surface.rebuild_at_time). What a hit reads per place (its transform,
Object Info's colour, random and pass index) is a row of the object table
(engine.nodes.context), one per place: the hit's `inst`.

Some meshes are not kept instanced but expanded into K world-space meshes before the
render (`resolve`): those whose materials emit light (light sampling picks triangles in
world space, engine.mesh_lights) or hold a volume (a medium's boundary and its
heterogeneous density belong to one object, engine.kernels.volume), and a mesh placed
only once, which costs less as a plain mesh than as an instance.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .scene import ObjectInfo, TriangleMesh


def is_instanced(mesh: TriangleMesh) -> bool:
    return getattr(mesh, "instances", None) is not None


def expand(mesh: TriangleMesh) -> list[TriangleMesh]:
    """The K places of an instanced mesh as K world-space meshes (a mesh that is not
    instanced: itself). Corner normals go through each place's inverse-transpose, not
    renormalised: hits interpolate them and normalise the result, so a hit on a copy is
    the hit on the instance (as Cycles interpolates an instance's normals in object
    space). Tangents stay in object space, as every mesh's do (engine.nodes.tangent_frame).
    A mirroring place turns the copy's winding over, as the instance's hits turn its
    geometric normal back."""
    if not is_instanced(mesh):
        return [mesh]
    inst = mesh.instances
    info = mesh.object_info
    out = []
    for k, m in enumerate(inst.matrices):
        a, t = m[:3, :3], m[:3, 3]
        try:
            inverse_t = np.linalg.inv(a).T
        except np.linalg.LinAlgError:
            inverse_t = np.linalg.pinv(a).T
        normals = None if mesh.corner_normals is None else (
            np.asarray(mesh.corner_normals, np.float64) @ inverse_t.T).astype(np.float32)
        order = [0, 1, 2]
        if np.linalg.det(a) < 0.0:
            order = [0, 2, 1]
        corner = (lambda x: None if x is None else np.ascontiguousarray(
            np.asarray(x).reshape(len(mesh.triangles), 3, -1)[:, order]))
        names = {}
        if inst.names is not None and inst.name_ids is not None:
            names = dict(zip(("object_name", "asset_name"), inst.names[inst.name_ids[k]]))
        placed_info = None
        if info is not None:
            placed_info = replace(info, matrix_world=m.copy(),
                                  color=tuple(inst.colors[k]), random=float(inst.randoms[k]),
                                  pass_index=int(inst.pass_indices[k]))
        out.append(replace(mesh, name=f"{mesh.name}#{k}", positions=mesh.positions @ a.T + t,
                           triangles=mesh.triangles[:, order], corner_normals=corner(normals),
                           uvs=corner(mesh.uvs), tangents=corner(mesh.tangents),
                           colors=corner(mesh.colors), undisplaced=corner(mesh.undisplaced),
                           object_info=placed_info,
                           instances=None, **names))
    return out


def resolve(meshes: list, keep_instanced) -> list:
    """The meshes a render traces: instanced meshes for which keep_instanced(mesh) is
    False, or placed only once, expanded into world-space meshes (see the module)."""
    out = []
    for mesh in meshes:
        if is_instanced(mesh) and (len(mesh.instances) < 2 or not keep_instanced(mesh)):
            out.extend(expand(mesh))
        else:
            out.append(mesh)
    return out


def world_bounds(mesh: TriangleMesh) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) of an instanced mesh over all its places: each place's box of the
    object-space bounding box's eight corners."""
    p = mesh.positions
    lo, hi = p.min(axis=0), p.max(axis=0)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])
    m = mesh.instances.matrices
    world = np.einsum("kij,cj->kci", m[:, :3, :3], corners) + m[:, None, :3, 3]
    return world.min(axis=(0, 1)), world.max(axis=(0, 1))


def object_rows(mesh: TriangleMesh) -> np.ndarray:
    """The object table rows (engine.nodes.context) of an instanced mesh's places: each
    place's matrix, colour, random and pass index, and the mesh's texture space (its
    ObjectInfo's, or its object-space bounding box)."""
    from .nodes.context import object_rows as rows
    info = mesh.object_info
    if info is None:
        lo, hi = mesh.positions.min(axis=0), mesh.positions.max(axis=0)
        info = ObjectInfo(np.eye(4), texspace_location=tuple((lo + hi) / 2),
                          texspace_size=tuple((hi - lo) / 2))
    inst = mesh.instances
    return rows(inst.matrices, inst.colors, inst.randoms, inst.pass_indices,
                info.texspace_location, info.texspace_size)
