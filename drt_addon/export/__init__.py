"""From Blender's evaluated depsgraph to DRT's scene description (engine.scene)."""
from __future__ import annotations

from ..engine_link import engine
from .camera import export_camera
from .errors import ExportError, Reporter
from .lights import export_light
from .materials import export_material
from .mesh import GEOMETRY_TYPES, export_mesh_instance
from .world import export_world

__all__ = ["ExportError", "Reporter", "export_scene", "render_size"]


def render_size(scene):
    r = scene.render
    scale = r.resolution_percentage / 100.0
    return max(1, int(r.resolution_x * scale)), max(1, int(r.resolution_y * scale))


def export_scene(depsgraph, reporter: Reporter | None = None, size=None) -> "engine.Scene":
    reporter = reporter or Reporter()
    scene = depsgraph.scene
    width, height = size or render_size(scene)
    camera = export_camera(scene.camera, depsgraph)
    materials, material_index = [], {}

    def material_id(mat):
        key = mat.name_full if mat is not None else None
        if key not in material_index:
            material_index[key] = len(materials)
            materials.append(export_material(mat, reporter))
        return material_index[key]

    meshes, lights = [], []
    for k, inst in enumerate(depsgraph.object_instances):
        obj = inst.object
        if obj.type in GEOMETRY_TYPES:
            if inst.is_instance is False and not inst.show_self:
                continue
            if getattr(obj, "is_holdout", False):
                reporter.warn(f"DRT: holdout object {obj.name!r} is left out", key=(obj.name, "holdout"))
                continue
            slots = [material_id(s.material) for s in obj.material_slots] or [material_id(None)]
            mesh = export_mesh_instance(obj, inst.matrix_world.copy(), slots,
                                        f"{obj.name}#{k}" if inst.is_instance else obj.name)
            if mesh is not None:
                meshes.append(mesh)
        elif obj.type == "LIGHT":
            light = export_light(obj, inst.matrix_world.copy(), reporter)
            if light is not None:
                lights.append(light)
    if not materials:
        materials.append(engine.Material())
    world = export_world(scene.world, reporter)
    aspect = scene.render.pixel_aspect_x / max(scene.render.pixel_aspect_y, 1e-9)
    return engine.Scene(camera, width, height, meshes, materials, lights, world,
                        pixel_aspect=aspect)
