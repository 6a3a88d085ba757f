"""The scene description's meshes: `TriangleMesh` (one evaluated mesh, float64
positions), its `Instances` (the places of a mesh kept once) and `ObjectInfo` (what
shader nodes read of the object it belongs to)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

@dataclass
class ObjectInfo:
    """What shader nodes read of the object a mesh instance belongs to: its transform at
    the frame (object coordinates, the Texture Coordinate node's Normal), Object Info's
    Color, Random and pass index, and the texture space Generated coordinates map to
    [0, 1]^3 (centre and half-size, in object space; Blender's auto texture space is
    the mesh's bounding box)."""
    matrix_world: np.ndarray
    color: tuple = (1.0, 1.0, 1.0)
    random: float = 0.0
    pass_index: int = 0
    texspace_location: tuple = (0.0, 0.0, 0.0)
    texspace_size: tuple = (1.0, 1.0, 1.0)


@dataclass
class Instances:
    """The K places of one mesh that appears more than once (Blender's collection
    instances, particles, Geometry Nodes instances, linked duplicates): the mesh is kept
    once, in object space, and Embree traces it as K instances, so memory grows with K,
    not with K times its triangles (engine.instancing).

    matrices: (K, 4, 4) float64 object -> world, one per place.
    colors, randoms, pass_indices: what Object Info reads of each place ((K, 3), (K,),
    (K,)); None: white, 0 and 0.
    names, name_ids: the (object name, asset name) pairs of the places (Cryptomatte,
    engine.cryptomatte) and each place's pair (K,) int; None: the mesh's own names."""
    matrices: np.ndarray
    colors: Optional[np.ndarray] = None
    randoms: Optional[np.ndarray] = None
    pass_indices: Optional[np.ndarray] = None
    names: Optional[tuple] = None
    name_ids: Optional[np.ndarray] = None

    def __post_init__(self):
        m = np.ascontiguousarray(self.matrices, dtype=np.float64)
        if m.ndim != 3 or m.shape[1:] != (4, 4):
            raise ValueError(f"instance matrices must be (K, 4, 4), got {m.shape}")
        if not np.all(np.isfinite(m[:, :3, :4])):
            raise ValueError("an instance's matrix is not finite (NaN or Inf)")
        self.matrices = m
        k = len(m)
        self.colors = (np.ones((k, 3)) if self.colors is None
                       else np.asarray(self.colors, np.float64).reshape(k, -1)[:, :3])
        self.randoms = (np.zeros(k) if self.randoms is None
                        else np.asarray(self.randoms, np.float64).reshape(k))
        self.pass_indices = (np.zeros(k) if self.pass_indices is None
                             else np.asarray(self.pass_indices, np.float64).reshape(k))
        if self.name_ids is not None:
            self.name_ids = np.asarray(self.name_ids, np.int64).reshape(k)
            if self.names is None or (k and not 0 <= self.name_ids.min() <= self.name_ids.max()
                                      < len(self.names)):
                raise ValueError("instance name ids must index `names`")

    def __len__(self):
        return len(self.matrices)


@dataclass
class TriangleMesh:
    """One evaluated mesh in world space, or in object space placed K times when
    `instances` is set.

    positions: (V, 3) float64 vertex positions.
    triangles: (T, 3) int32 vertex indices.
    material_indices: (T,) int32 indices into `Scene.materials`.
    corner_normals: optional (T, 3, 3) float32 shading normals per triangle corner
        (Blender's split normals); None means flat shading.
    uvs: optional (T, 3, 2) float32 texture coordinates per corner.
    tangents: optional (T, 3, 4) float32 tangent space per corner (tangent and bitangent
        sign in the OBJECT's space, also for a mesh whose positions are in the world:
        MikkTSpace as Cycles computes it), for tangent-space Normal Maps, which work in
        object space (engine.nodes.tangent_frame).
    motion: None for a static mesh (positions in world space); an
        `engine.motion.RigidMotion` (positions then in OBJECT space, placed in the world by
        the motion's transform at each ray's time); or an `engine.motion.DeformMotion`
        (vertex positions over the shutter in world space; `positions` is ignored).
    """
    name: str
    positions: np.ndarray
    triangles: np.ndarray
    material_indices: np.ndarray
    corner_normals: Optional[np.ndarray] = None
    uvs: Optional[np.ndarray] = None
    motion: Optional[object] = None
    holdout: bool = False          # Cycles' holdout: a zero-alpha hole for camera rays
    visibility: int = 31           # the ray kinds that see it (engine.visibility)
    object_info: Optional[object] = None   # ObjectInfo, what shader nodes read of it
    tangents: Optional[np.ndarray] = None  # (T, 3, 4) float32: tangent, bitangent sign
    colors: Optional[np.ndarray] = None    # (T, 3, 4) float32: a color attribute, RGBA
    # (T, 3, 3) float32: a displaced mesh's corners before displacement, in object space
    # (engine.displacement): its hits read Generated coordinates there, as in Cycles
    undisplaced: Optional[np.ndarray] = None
    # (T,) bool: the faces shaded flat of a mesh whose corner normals are not all its
    # faces' own (Displacement and Bump leaves them the undisplaced vertex normals, as
    # Cycles' bump does): there, as on every face Cycles does not shade smooth, a Normal
    # Map builds on the face's own normal and shadow rays leave from its plane; None:
    # no such face
    flat_faces: Optional[np.ndarray] = None
    # Shadow Terminator > Geometry Offset (Cycles' per-object setting; 0 = off): how far
    # shadow rays start from the curved surface of a smooth mesh (engine.kernels.terminator)
    terminator_offset: float = 0.1
    # None: one mesh in world space. Instances: positions, corner normals and tangents
    # are in object space, and the mesh stands at each of its places (`object_info`
    # then gives only the texture space; Object Info reads the places' own values)
    instances: Optional[Instances] = None
    pass_index: int = 0            # Blender's object Pass Index (IndexOB pass)
    lightgroup: str = ""           # its emission's light group (Scene.light_groups)
    # Object > Visibility > Shadow Catcher (engine.shadow_catcher): the shadows and light
    # other objects cast on it become a pass of their own, the object itself a hole
    shadow_catcher: bool = False
    # the names Cryptomatte gives its hits (engine.cryptomatte): the Blender object's and
    # its topmost parent's ("": the mesh's name, and the object name)
    object_name: str = ""
    asset_name: str = ""

    def __post_init__(self):
        self.positions = np.ascontiguousarray(self.positions, dtype=np.float64).reshape(-1, 3)
        self.triangles = np.ascontiguousarray(self.triangles, dtype=np.int32).reshape(-1, 3)
        self.material_indices = np.ascontiguousarray(
            self.material_indices, dtype=np.int32).reshape(-1)
        if self.material_indices.size == 1 and len(self.triangles) != 1:
            self.material_indices = np.full(len(self.triangles), self.material_indices[0], np.int32)
        if len(self.material_indices) != len(self.triangles):
            raise ValueError(f"mesh {self.name!r}: {len(self.material_indices)} material indices "
                             f"for {len(self.triangles)} triangles")
        self.uvs = self._per_corner(self.uvs, 2, "UV")
        self.undisplaced = self._per_corner(self.undisplaced, 3, "undisplaced")
        if self.flat_faces is not None:
            self.flat_faces = np.asarray(self.flat_faces, bool).reshape(-1)
            if len(self.flat_faces) != len(self.triangles):
                raise ValueError(f"mesh {self.name!r}: {len(self.flat_faces)} flat-face "
                                 f"flags for {len(self.triangles)} triangles")
        if len(self.triangles) and (self.triangles.min() < 0
                                    or self.triangles.max() >= len(self.positions)):
            raise ValueError(f"mesh {self.name!r}: triangle index out of range")
        if self.instances is not None and self.motion is not None:
            raise ValueError(f"mesh {self.name!r}: instances cannot move (export moving "
                             f"places as meshes of their own)")

    def _per_corner(self, values, width: int, what: str):
        """A per-corner attribute as (T, 3, width) float32 (None stays None)."""
        if values is None:
            return None
        a = np.asarray(values, dtype=np.float32)
        if a.size != len(self.triangles) * 3 * width:
            raise ValueError(f"mesh {self.name!r}: {a.size // (3 * width)} {what} triangles "
                             f"for {len(self.triangles)} triangles")
        return np.ascontiguousarray(a.reshape(-1, 3, width))
