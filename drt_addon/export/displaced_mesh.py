"""True displacement at export: an evaluated mesh whose materials move their surface
(Material > Settings > Displacement: Displacement Only, Displacement and Bump) is moved
once, in object space, before it is placed (engine.displacement does the work, as Cycles'
GeometryManager::displace does), and every place of it shares the moved mesh. Like
Cycles, the shader is evaluated with the first object that uses the mesh."""
from __future__ import annotations

import dataclasses
import importlib

import numpy as np

from ..engine_link import engine
from .dicing import dice_local
from .matrices import to_numpy
from .object_info import object_values

D = importlib.import_module(engine.__name__ + ".displacement")
C = importlib.import_module(engine.__name__ + ".nodes.context")


class DisplacedMeshes:
    """The moved meshes of one export, one per (evaluated mesh, materials); a mesh with
    Adaptive Subdivision is diced first (export.dicing) by `dicing`, an
    export.dicing.SceneDicing, as its first user sees it."""

    def __init__(self, dicing=None, warn=None):
        self._done = {}
        self.displaced = 0            # meshes moved
        self.diced = 0                # of which diced
        self.dicing = dicing
        self.warn = warn

    def get(self, local, obj, matrix_world, slots, materials):
        """`local` moved by the displacements of its material slots (indices into
        `materials`), or `local` itself when none moves it."""
        displacements = [materials[i].displacement for i in slots]
        if local is None or all(d is None for d in displacements):
            return local
        key = (id(local), tuple(slots))
        if key not in self._done:
            dicing = self.dicing.of(obj) if self.dicing is not None else None
            if dicing is not None:
                diced = dice_local(local, dicing, matrix_world,
                                   lambda m: self.warn and self.warn(
                                       f"DRT: adaptive subdivision of '{obj.name}' {m}"))
                self.diced += diced is not local
                local = diced
            self._done[key] = displace_local(local, obj, matrix_world, displacements)
            self.displaced += 1
        return self._done[key]


def displace_local(local, obj, matrix_world, displacements):
    """A LocalMesh (export.mesh) moved by `displacements` (one engine Displacement or
    None per material slot), evaluated for object `obj` at `matrix_world`."""
    m = np.asarray(to_numpy(matrix_world), np.float64)
    color, pass_index, (loc, size) = object_values(obj)
    row = C.object_row(m, color, 0.0, pass_index, loc, size)
    normals = local.vertex_normals
    if normals is None:        # every face flat and no normals read: the faces' own
        normals = _area_normals(local.positions, local.triangles)
    positions, moved = D.displace(local.positions, local.triangles, local.material, normals,
                                  displacements, m, row, local.uvs, local.tangents,
                                  local.colors)
    keep = np.array([d is not None and d.keep_normals for d in displacements] + [False])
    kept = moved & keep[np.clip(local.material, 0, len(keep) - 1)]
    corner_normals = D.displaced_normals(positions, local.triangles, moved & ~kept,
                                         local.normals, local.smooth)
    corner_normals = D.bumped_from_vertex_normals(positions, local.triangles, kept,
                                                  corner_normals, local.smooth, normals)
    return dataclasses.replace(local, positions=positions, normals=corner_normals,
                               offset=positions - local.positions)


def _area_normals(positions, triangles):
    n = np.zeros_like(positions)
    a, b, c = (positions[triangles[:, k]] for k in range(3))
    f = np.cross(b - a, c - a)
    for k in range(3):
        np.add.at(n, triangles[:, k], f)
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
