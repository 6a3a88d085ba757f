"""What one export keeps for the next: the Rendered viewport (drt_addon.viewport) exports
the scene again after every edit, and evaluates again only the geometry and materials the
edit touched, read from the depsgraph's updates (`ExportMemo.forget_updated`).

Kept: the object-space arrays of each evaluated geometry (export.mesh's LocalMesh) and
each exported material. Always read again: placements (object transforms), lamps, the
world and the camera, which cost little. An update the memo cannot attribute (an image,
a node group, a collection, a geometry-nodes instancer) forgets everything of its kind:
the memo may re-evaluate too much, never too little.
"""
from __future__ import annotations

from .materials import export_material
from .mesh import MeshCache, _cache_key

# ID types whose updates change no kept geometry or material (read again every export).
_READ_EVERY_TIME = {"LIGHT", "WORLD", "CAMERA", "SCENE", "OBJECT"}
_SHADING_INPUTS = {"IMAGE", "TEXTURE", "NODETREE"}


def _kind(id_) -> str:
    """An ID's type as Blender names it since 4.0 (`ID.id_type`: OBJECT, MATERIAL, ...);
    Blender 3.4 has no id_type, and its class tells."""
    kind = getattr(id_, "id_type", None)
    if kind:
        return kind
    import bpy
    for name in ("Object", "Material", "Light", "World", "Camera", "Scene", "Image",
                 "Texture", "NodeTree", "Mesh"):
        if isinstance(id_, getattr(bpy.types, name)):
            return name.upper()
    return type(id_).__name__.upper()


def _names(obj):
    """(object name, its original data's name): what an update names."""
    original = obj.original if obj.original is not None else obj
    data = getattr(original, "data", None)
    return original.name_full, (data.name_full if data is not None else None)


class LastingMeshCache(MeshCache):
    """export.mesh.MeshCache whose entries outlive one depsgraph evaluation: keyed by the
    object's and its data's names besides the evaluated geometry's address (an address
    alone could be reused by a new evaluation), and dropped by `forget`."""

    def key(self, obj):
        inner = _cache_key(obj)
        return None if inner is None else (_names(obj), inner)

    def forget(self, object_names=(), data_names=(), everything=False) -> None:
        for key in list(self._local):
            (obj_name, data_name), _ = key
            if everything or obj_name in object_names or data_name in data_names:
                del self._local[key]


class ExportMemo:
    """Geometry and materials of earlier exports, for export.export_scene(memo=...)."""

    def __init__(self):
        self.meshes = None          # LastingMeshCache, made by the first export
        self._mesh_args = None
        self.materials = {}         # material name (None: an empty slot) -> engine.Material
        self.material_exports = 0   # export_material calls in the last export
        self.lights_only = False    # the last updates changed lamps or the world alone

    def begin(self, reporter, uv_pass: bool, override) -> MeshCache:
        """Start an export: its counts start at 0; returns the lasting mesh cache for an
        export with these settings (a new one when the UV pass or the layer's material
        override changed)."""
        self.material_exports = 0
        args = (uv_pass, getattr(override, "name_full", None))
        if self.meshes is None or args != self._mesh_args:
            self.meshes = LastingMeshCache(reporter, uv_pass=uv_pass, override=override)
            self._mesh_args = args
        self.meshes.reporter = reporter
        self.meshes.evaluations = self.meshes.reuses = 0
        return self.meshes

    def material(self, mat, reporter):
        """`mat` exported (export.materials.export_material), or as exported before."""
        key = mat.name_full if mat is not None else None
        found = self.materials.get(key)
        if found is None:
            found = self.materials[key] = export_material(mat, reporter)
            self.material_exports += 1
        return found

    def forget_updated(self, updates) -> set:
        """Drop what the depsgraph's `updates` changed; returns the ID types updated
        ({"SCENE"} alone may be a selection or a setting: the caller compares settings)."""
        kinds = set()
        objects, datas, everything = set(), set(), False
        updates = list(updates)
        # an edit in an embedded node tree comes with its owner's update (a material,
        # a world, a lamp); Blender 3.4 reports a material's as the tree alone
        named = {_kind(u.id) for u in updates}
        owners_named = bool(named & {"MATERIAL", "WORLD", "LIGHT"})
        # a tree of a lamp or the world, not of a material
        light_tree = "MATERIAL" not in named and bool(named & {"WORLD", "LIGHT"})
        self.lights_only = True
        for u in updates:
            id_ = u.id
            kind = _kind(id_)
            kinds.add(kind)
            self.lights_only &= kind in ("LIGHT", "WORLD", "SCENE") or (
                kind == "OBJECT" and getattr(id_, "type", "") == "LIGHT") or (
                kind == "NODETREE" and getattr(id_, "is_embedded_data", False) and light_tree)
            if kind == "OBJECT":
                if u.is_updated_geometry:
                    obj = id_.original if id_.original is not None else id_
                    objects.add(obj.name_full)
                    # instances made by its modifiers or particles carry its name too
                    everything |= bool(obj.modifiers) or bool(
                        getattr(obj, "particle_systems", ())) or obj.is_instancer
            elif kind == "MATERIAL":
                self.materials.pop(id_.name_full, None)
            elif kind == "NODETREE" and getattr(id_, "type", "") == "GEOMETRY":
                everything = True                      # a geometry node group
            elif kind in _SHADING_INPUTS:
                # a material's own tree updates with its material (since Blender 3.5);
                # a shared node group, an image or a texture may be in any material
                if not (getattr(id_, "is_embedded_data", False) and owners_named):
                    self.materials.clear()
            elif kind not in _READ_EVERY_TIME and u.is_updated_geometry:
                original = id_.original if id_.original is not None else id_
                datas.add(original.name_full)
        if self.meshes is not None and (objects or datas or everything):
            self.meshes.forget(objects, datas, everything)
        return kinds
