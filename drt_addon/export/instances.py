"""Blender's repeated geometry as DRT's instances (engine.scene.Instances).

Collection instances, particle instances, Geometry Nodes instances and linked
duplicates place one evaluated mesh many times. The export groups the places of each
evaluated mesh (`MeshCache` already evaluates it once) that also share their materials
and object settings; a group of two or more places becomes one mesh in object space
with the places' matrices and Object Info values, which the tracer keeps once and
traces as one Embree instance array. A mesh placed once is exported in world space as
before.

A place costs the export a matrix and a random number: what the rest depends on (the
object's mesh, materials, holdout, ray visibility, colour and pass index) is worked out
once per source object and instancer (`InstanceGroups.known`), so 100,000 Geometry
Nodes instances export in about a second.

Mirroring places need nothing here: the tracer turns a mirrored instance's geometric
normal and bitangent sign back itself (engine.kernels.surface).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..engine_link import engine
from .errors import ExportError
from .mesh import LocalMesh, flat_faces, instance_mesh, undisplaced_corners
from .object_info import random_of


@dataclass
class Group:
    """The places of one evaluated mesh with the same materials and settings."""
    local: LocalMesh
    slots: tuple
    name: str
    holdout: bool
    terminator_offset: float
    visibility: int
    with_info: bool                  # its materials run shader programs
    texspace: tuple                  # (location, size) Generated coordinates map from
    lightgroup: str = ""             # Object > Shading > Light Group (its emission's)
    shadow_catcher: bool = False     # Object > Visibility > Shadow Catcher
    matrices: list = field(default_factory=list)      # mathutils matrices, one a place
    random_ids: list = field(default_factory=list)    # Blender's random id of each place
    colors: list = field(default_factory=list)        # Object Info colour of each place
    pass_indices: list = field(default_factory=list)
    name_ids: list = field(default_factory=list)      # each place's (object, asset) names
    names: dict = field(default_factory=dict)         # (object, asset) name -> its id

    def place(self, matrix_world, random_id: int, color, pass_index: int, names) -> None:
        self.matrices.append(matrix_world.copy())
        self.random_ids.append(random_id)
        self.colors.append(color)
        self.pass_indices.append(pass_index)
        self.name_ids.append(self.names.setdefault(names, len(self.names)))

    def arrays(self):
        """(matrices (K, 4, 4), randoms (K,)), checked finite."""
        m = np.array(self.matrices, dtype=np.float64).reshape(-1, 4, 4)
        if not np.all(np.isfinite(m)):
            raise ExportError(f"object {self.name!r} has a non-finite transform")
        return m, random_of(self.random_ids)


@dataclass
class Source:
    """What the export worked out once for a source object under one instancer."""
    group: Group
    color: tuple
    pass_index: int
    holdout: bool
    names: tuple              # (object name, asset name): what Cryptomatte calls it


class InstanceGroups:
    """Places collected during one export, in the order first seen."""

    def __init__(self):
        self._groups: dict = {}
        self.known: dict = {}         # source key (see `source_key`) -> Source
        self.places = 0

    def group(self, local: LocalMesh, slots, name: str, holdout: bool,
              terminator_offset: float, visibility: int, with_info: bool,
              texspace, lightgroup: str = "", shadow_catcher: bool = False,
              alone: bool = False) -> Group:
        """The group of places with this mesh, materials and settings (`alone`: a group
        of its own, whatever it shares)."""
        key = (id(local), tuple(slots), holdout, terminator_offset, visibility, with_info,
               lightgroup, shadow_catcher, name if alone else None)
        found = self._groups.get(key)
        if found is None:
            found = self._groups[key] = Group(local, tuple(slots), name, holdout,
                                              terminator_offset, visibility, with_info,
                                              texspace, lightgroup, shadow_catcher)
        return found

    def place(self, source: Source, matrix_world, random_id: int) -> None:
        source.group.place(matrix_world, random_id, source.color, source.pass_index,
                           source.names)
        self.places += 1

    def meshes(self) -> list:
        """One engine.TriangleMesh per group: in world space for a single place, in
        object space with its Instances for more."""
        return [_single(g) if len(g.matrices) == 1 else _instanced(g)
                for g in self._groups.values() if g.matrices]

    def instanced(self) -> int:
        """How many places are exported as instances (groups of two or more)."""
        return sum(len(g.matrices) for g in self._groups.values() if len(g.matrices) > 1)


def regroup_still(meshes: list, held: list, groups: InstanceGroups) -> list:
    """With motion blur on, every place was exported as a world-space mesh of its own, so
    that the shutter's samples could give it motion (export.motion). `held`: (index in
    meshes, its Source, its matrix, its random id) of each. The places left without
    motion that share a group with another still place become that group's instances,
    as without motion blur; the moving ones, and a still place alone, stay as they are."""
    still = [h for h in held if meshes[h[0]].motion is None]
    count: dict = {}
    for _, source, _, _ in still:
        count[id(source.group)] = count.get(id(source.group), 0) + 1
    grouped = set()
    for index, source, matrix, random_id in still:
        if count[id(source.group)] > 1:
            groups.place(source, matrix, random_id)
            grouped.add(index)
    if not grouped:
        return meshes
    return [m for i, m in enumerate(meshes) if i not in grouped] + groups.meshes()


def source_key(inst, obj):
    """What identifies a source object under its instancer within one depsgraph walk:
    Blender reuses one temporary object for every instance it generates, so its own
    address says nothing; its evaluated data and its original do."""
    data = getattr(obj, "data", None)
    original = obj.original if obj.original is not None else obj
    parent = inst.parent if inst.is_instance else None
    return (obj.type, data.as_pointer() if data is not None else 0, original.as_pointer(),
            parent.as_pointer() if parent is not None else 0, inst.is_instance)


def _settings(mesh, g: Group):
    mesh.holdout = g.holdout
    mesh.terminator_offset = g.terminator_offset
    mesh.visibility = g.visibility
    mesh.lightgroup = g.lightgroup
    mesh.shadow_catcher = g.shadow_catcher
    return mesh


def _single(g: Group):
    m, randoms = g.arrays()
    mesh = _settings(instance_mesh(g.local, m[0], g.slots, g.name), g)
    mesh.pass_index = g.pass_indices[0]
    mesh.object_name, mesh.asset_name = next(iter(g.names))
    if g.with_info:
        mesh.object_info = engine.ObjectInfo(m[0], g.colors[0], float(randoms[0]),
                                             g.pass_indices[0], *g.texspace)
    return mesh


def _instanced(g: Group):
    local = g.local
    m, randoms = g.arrays()
    slots = np.asarray(g.slots if len(g.slots) else [0], dtype=np.int32)
    materials = slots[np.clip(local.material, 0, len(slots) - 1)]
    places = engine.Instances(m, colors=np.array(g.colors, np.float64),
                              randoms=randoms, pass_indices=np.array(g.pass_indices),
                              names=tuple(g.names), name_ids=np.array(g.name_ids))
    mesh = engine.TriangleMesh(g.name, local.positions, local.triangles, materials,
                               corner_normals=local.normals, uvs=local.uvs,
                               tangents=local.tangents, colors=local.colors,
                               undisplaced=undisplaced_corners(local),
                               flat_faces=flat_faces(local), instances=places)
    _settings(mesh, g)
    # the texture space Generated coordinates map to (the same for every place)
    mesh.object_info = engine.ObjectInfo(np.eye(4), texspace_location=g.texspace[0],
                                         texspace_size=g.texspace[1])
    return mesh
