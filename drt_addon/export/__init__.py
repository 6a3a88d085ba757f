"""From Blender's evaluated depsgraph to DRT's scene description (engine.scene)."""
from __future__ import annotations

import copy
import time

from ..engine_link import engine
from .dicing import SceneDicing
from .displaced_mesh import DisplacedMeshes
from .camera import RenderRegion, export_camera, render_region, window_camera
from .errors import ExportError, Reporter
from .hair import curves_object, hair_systems, particle_hair
from .instances import InstanceGroups, Source, regroup_still, source_key
from .left_out import LEFT_OUT_TYPES, LeftOut
from .libraries import missing_library_messages
from .settings_check import check as check_file_settings
from .lights import export_light, object_visibility
from .layer_overrides import material_override, render_world, slot_materials
from .materials import export_default_volume, export_material
from .mesh import GEOMETRY_TYPES, MeshCache, instance_mesh, uv_request
from .motion import MotionExport, read_settings
from .object_info import object_info, object_values, random_id
from .volume_objects import density_scale, domain, read_volume
from .volumes import is_heterogeneous, suns_blocked_message, world_volume
from .world import export_world

__all__ = ["BLACK_IMAGE", "ExportError", "RenderRegion", "Reporter", "export_scene",
           "render_region", "render_size"]


def render_size(scene):
    """The full frame's size in pixels (resolution x percentage, Blender's integer maths)."""
    region = render_region(scene)
    return region.full_width, region.full_height


def _is_holdout(inst, obj, view_layer) -> bool:
    """Holdout by the object's own flag or by a holdout collection (of the object, or of
    the instancer for instanced geometry), as Cycles decides it."""
    if getattr(obj, "is_holdout", False):
        return True
    owner = inst.parent if inst.is_instance and inst.parent is not None else obj
    original = owner.original if owner.original is not None else owner
    try:
        return bool(original.holdout_get(view_layer=view_layer))
    except (TypeError, RuntimeError, AttributeError):
        return False


def crypto_names(inst, obj) -> tuple:
    """(object name, asset name) of an instance as Cycles' Cryptomatte names it: the
    object's own name (an instance: its source object's) and its topmost parent's."""
    source = obj.original if obj.original is not None else obj
    top = source
    while top.parent is not None:
        top = top.parent
    return source.name, top.name


def export_scene(depsgraph, reporter: Reporter | None = None, size=None,
                 region: RenderRegion | None = None, stats: dict | None = None,
                 render_engine=None, check_cancel=None, memo=None,
                 view=None, motion=None, alone=None) -> "engine.Scene":
    """The scene as DRT's description.

    region: the pixels to render (default: Blender's render size and border, see
    `render_region`); the Scene then has the region's size and a camera for just that
    region. `size=(w, h)` renders the whole frame at that size instead. stats, if given,
    receives counts of the export (mesh evaluations, reused instances, seconds).

    Motion blur (see `export.motion`): with it on, the scene is exported at the shutter's
    middle and sampled at the motion steps with `render_engine.frame_set` (the
    RenderEngine rendering; without one, as in export tests, Scene.frame_set); the frame
    is restored afterwards.

    The file's render settings DRT does not honour are warned about through `reporter`
    (export.file_settings). check_cancel, if given, is called before each object is
    exported (the RenderEngine's cancel: it raises to stop the export).

    The Rendered viewport passes `view`, (engine.Camera, width, height) of the 3D view
    (drt_addon.viewport_camera; the scene needs no camera then, and there is no motion
    blur, as in Cycles' viewport), and `memo`, an export.memo.ExportMemo whose geometry and
    materials are reused from the last export unless an update dropped them.

    `motion` (an export.motion.MotionSettings) exports the scene with that shutter whatever
    the file's motion blur says: the Vector pass's scene over frames f - 1 to f + 1.

    `alone`, an object's name: that object becomes a mesh of its own, never an instance
    of a mesh it shares (a bake finds its triangles there: drt_addon.bake)."""
    reporter = reporter or Reporter()
    check_file_settings(depsgraph.scene, depsgraph.view_layer, reporter)
    for message in missing_library_messages():
        reporter.warn(f"DRT: {message}")
    blur = motion or (read_settings(depsgraph.scene) if view is None else None)
    if blur is None:
        return _export_scene(depsgraph, reporter, size, region, stats, None, check_cancel,
                             memo, view, alone)
    with MotionExport(depsgraph, blur, reporter, render_engine) as tracker:
        return _export_scene(depsgraph, reporter, size, region, stats,
                             tracker if tracker.usable else None, check_cancel)


def _export_scene(depsgraph, reporter, size, region, stats, tracker,
                  check_cancel=None, memo=None, view=None, alone=None) -> "engine.Scene":
    t0 = time.perf_counter()
    scene = depsgraph.scene
    if view is not None:
        region = RenderRegion(view[1], view[2], 0, 0, view[1], view[2])
    elif region is None:
        if size is not None:
            region = RenderRegion(size[0], size[1], 0, 0, size[0], size[1])
        else:
            region = render_region(scene)
    aspect = scene.render.pixel_aspect_x / max(scene.render.pixel_aspect_y, 1e-9)
    if view is not None:
        camera, aspect = view[0], 1.0
    else:
        camera = window_camera(export_camera(scene.camera, depsgraph), region, aspect)
    if tracker is not None:
        tracker.note_camera(scene.camera)
    view_layer = depsgraph.view_layer
    materials, material_index = [], {}

    def material_id(mat, owner=None, grids=None, density_scale=1.0):
        """The index of `mat` for object `owner`: a material whose volume varies in space
        gets one copy per object (the engine evaluates it in that object's coordinates);
        on a Volume object (its `grids`) it is exported for that object alone."""
        if grids is not None:
            materials.append(export_material(mat, reporter, grids, density_scale)
                             if mat is not None
                             else export_default_volume(reporter, grids, density_scale))
            return len(materials) - 1
        key = mat.name_full if mat is not None else None
        if key not in material_index:
            material_index[key] = len(materials)
            materials.append(memo.material(mat, reporter) if memo is not None
                             else export_material(mat, reporter))
            het_owner[key] = owner
        index = material_index[key]
        if is_heterogeneous(materials[index]) and het_owner[key] != owner:
            if (key, owner) not in material_index:
                material_index[(key, owner)] = len(materials)
                materials.append(copy.copy(materials[index]))
            index = material_index[(key, owner)]
        return index

    het_owner = {}

    # the UV pass reads every mesh's UVs (its active map, where no material names one)
    override = material_override(view_layer)
    uv_pass = bool(getattr(view_layer, "use_pass_uv", False))
    cache = (memo.begin(reporter, uv_pass, override) if memo is not None
             else MeshCache(reporter, uv_pass=uv_pass, override=override))
    meshes, lights = [], []
    groups = InstanceGroups()
    displaced = DisplacedMeshes(SceneDicing(depsgraph, view, aspect), reporter.warn)
    held = []
    left_out = LeftOut()
    holdouts = 0
    curves = []
    # View Layer > Filter > Curves: hair drawn or not (Cycles' use_hair)
    use_hair = bool(getattr(view_layer, "use_strand", True))
    rendering = getattr(depsgraph, "mode", "RENDER") == "RENDER"
    for k, inst in enumerate(depsgraph.object_instances):
        if check_cancel is not None:
            check_cancel()
        obj = inst.object
        if obj.type == "VOLUME":
            if inst.is_instance or inst.show_self:
                _place_volume(inst, obj, k, groups, material_id, reporter, view_layer,
                              slot_materials(obj, override))
            continue
        if obj.type == "CURVES" or (obj.type == "MESH" and inst.show_particles):
            if use_hair and (obj.type == "MESH" or inst.is_instance or inst.show_self):
                curves += _hair(inst, obj, k, material_id, materials, override, view_layer,
                                rendering)
            if obj.type == "CURVES":
                continue
        if obj.type in GEOMETRY_TYPES:
            if not inst.is_instance and not inst.show_self:
                continue
            if obj.type != "CURVES" and (obj.data is None
                                         or obj.data.bl_rna.identifier != "Mesh"):
                # a curve, text, surface or metaball object itself: Blender hands its
                # mesh on as an instance of it, which is drawn (Cycles' object_is_geometry)
                continue
            key = source_key(inst, obj) if tracker is None else None
            source = groups.known.get(key) if key is not None else None
            if source is not None:               # a place of a source worked out before
                holdouts += source.holdout
                groups.place(source, inst.matrix_world, random_id(inst, obj))
                continue
            holdout = _is_holdout(inst, obj, view_layer)
            holdouts += holdout
            if not inst.is_instance:
                left_out.note_smoke_domain(obj)
            local = cache.local(obj)
            if local is None:
                continue
            slots = ([material_id(m, k) for m in slot_materials(obj, override)]
                     or [material_id(None)])
            # true displacement moves the mesh once, with its first user (as Cycles)
            local = displaced.get(local, obj, inst.matrix_world, slots, materials)
            name = f"{obj.name}#{k}" if inst.is_instance else obj.name
            # Object > Shadow Terminator > Geometry Offset (engine.kernels.terminator)
            offset = float(getattr(obj, "shadow_terminator_geometry_offset", 0.1))
            if local.smooth is not None and not local.smooth.any():
                offset = 0.0          # Cycles lifts smooth faces only (a flat mesh's normals
                #                       may come from its displacement's bump: displaced_mesh)
            # an instance is seen by the rays that see both it and its instancer (Cycles)
            seen = _instance_visibility(inst, obj)
            programmed = any(_runs_program(materials[i]) for i in slots)
            color, pass_index, texspace = object_values(obj)
            catcher = _is_shadow_catcher(inst, obj)
            source = Source(groups.group(local, slots, name, holdout, offset, seen,
                                         programmed, texspace, _lightgroup(obj), catcher,
                                         alone=not inst.is_instance and obj.name == alone),
                            color, pass_index, holdout, crypto_names(inst, obj))
            if tracker is None:
                # without motion blur, repeated geometry becomes instances (export.instances)
                groups.place(source, inst.matrix_world, random_id(inst, obj))
                # a volume that varies in space has one material per object: not shared
                if not any(is_heterogeneous(materials[i]) for i in slots):
                    groups.known[key] = source
                continue
            meshes.append(instance_mesh(local, inst.matrix_world.copy(), slots, name))
            meshes[-1].holdout = holdout
            meshes[-1].terminator_offset = offset
            if programmed:
                meshes[-1].object_info = object_info(inst, obj, inst.matrix_world)
            meshes[-1].visibility = seen
            meshes[-1].pass_index = int(getattr(obj, "pass_index", 0))
            meshes[-1].lightgroup = _lightgroup(obj)
            meshes[-1].shadow_catcher = catcher
            meshes[-1].object_name, meshes[-1].asset_name = crypto_names(inst, obj)
            tracker.note_mesh(inst, obj, local, slots, len(meshes) - 1, name)
            # with motion blur, each place is a mesh of its own until the shutter is
            # sampled; those that do not move become instances then (regroup_still)
            held.append((len(meshes) - 1, source, inst.matrix_world.copy(),
                         random_id(inst, obj)))
        elif obj.type in LEFT_OUT_TYPES and (inst.is_instance or inst.show_self):
            left_out.note_object(obj)
        elif obj.type == "LIGHT":
            light = export_light(obj, inst.matrix_world.copy(), reporter)
            if light is not None:
                light.lightgroup = _lightgroup(obj)
                # a lamp lights the shadow catchers' copies of paths unless its object
                # is no shadow catcher (on by default for lamps, as Cycles reads it)
                light.shadow_catcher = bool(getattr(obj, "is_shadow_catcher", True))
                lights.append(light)
                if tracker is not None:
                    tracker.note_light(inst, obj, len(lights) - 1)
    meshes.extend(groups.meshes())
    if left_out.message():
        reporter.warn(left_out.message(), key="left out")
    if not materials:
        materials.append(engine.Material())
    world_id = render_world(scene, view_layer)
    world = export_world(world_id, reporter)
    if world_id is not None:
        world.volume = world_volume(world_id, reporter)
        world.lightgroup = _lightgroup(world_id)
        blocked = suns_blocked_message(world.volume, lights)
        if blocked:
            reporter.warn(blocked, key="suns in a world volume")
    shutter = None
    if tracker is not None:
        shutter = tracker.finish(meshes, camera, lights)
        meshes = regroup_still(meshes, held, groups)
    dark = dark_scene_message(meshes, materials, lights, world)
    if dark:
        reporter.warn(dark, key=BLACK_IMAGE)
    if stats is not None:
        stats.update(mesh_evaluations=cache.evaluations, mesh_reuses=cache.reuses,
                     material_exports=(memo.material_exports if memo is not None
                                       else len(material_index)),
                     displaced_meshes=displaced.displaced, diced_meshes=displaced.diced,
                     meshes=len(meshes), lights=len(lights), holdouts=holdouts,
                     triangles=int(sum(len(m.triangles) for m in meshes)),
                     instances=groups.instanced(),
                     seconds=time.perf_counter() - t0)
        if tracker is not None:
            stats["motion"] = tracker.stats
    if stats is not None:
        stats.update(hair_strands=int(sum(c.curve_count for c in curves)))
    return engine.Scene(camera, region.width, region.height, meshes, materials, lights, world,
                        pixel_aspect=aspect, shutter=shutter,
                        film_transparent=bool(scene.render.film_transparent), curves=curves,
                        # (the viewport draws Combined alone)
                        light_groups=light_groups(view_layer) if view is None else ())


def light_groups(view_layer) -> tuple:
    """The view layer's light groups (View Layer > Light Groups), by name."""
    return tuple(g.name for g in getattr(view_layer, "lightgroups", ()) if g.name)


def _is_shadow_catcher(inst, obj) -> bool:
    """Object > Visibility > Shadow Catcher, of the object or of its instancer."""
    if getattr(obj, "is_shadow_catcher", False):
        return True
    parent = inst.parent if inst.is_instance else None
    return bool(parent is not None and getattr(parent, "is_shadow_catcher", False))


def _lightgroup(id_block) -> str:
    """An object's or a world's Light Group (Blender 3.2+; "" for none)."""
    return str(getattr(id_block, "lightgroup", "") or "")


def _instance_visibility(inst, obj) -> int:
    """The ray kinds that see an instance: those that see both it and its instancer, as
    in Cycles (engine.visibility)."""
    seen = object_visibility(obj)
    if inst.is_instance and inst.parent is not None:
        seen &= object_visibility(inst.parent)
    return seen


def _hair(inst, obj, k, material_id, materials, override, view_layer, rendering) -> list:
    """The strands of one instance (export.hair): a Curves object's, or a mesh's
    particle hair, with the object's materials, holdout, ray visibility and names."""
    if obj.type == "MESH" and next(hair_systems(obj, rendering), None) is None:
        return []
    mats = slot_materials(obj, override)
    slots = [material_id(m, k) for m in mats] or [material_id(None)]
    name = f"{obj.name}#{k}" if inst.is_instance else obj.name
    if obj.type == "CURVES":
        found = [c for c in [curves_object(obj, inst.matrix_world, slots, name)] if c]
    else:
        found = particle_hair(obj, inst.matrix_world, slots, rendering, uv_request(mats),
                              name)
    seen = _instance_visibility(inst, obj)
    for c in found:
        c.holdout = _is_holdout(inst, obj, view_layer)
        c.visibility = seen
        c.pass_index = int(getattr(obj, "pass_index", 0))
        c.object_name, c.asset_name = crypto_names(inst, obj)
        if any(_runs_program(materials[i]) for i in slots):
            c.object_info = object_info(inst, obj, inst.matrix_world)
    return found


def _runs_program(material) -> bool:
    """Whether a material runs a shader program at hits (its own, or its AOV Output
    nodes'): its objects then carry what programs read of them (ObjectInfo)."""
    return material.shader is not None or getattr(material, "aovs", None) is not None


def _place_volume(inst, obj, k, groups, material_id, reporter, view_layer,
                  materials) -> None:
    """A Volume object: its grids, read from its OpenVDB file, in the box around them,
    with its materials (layer_overrides.slot_materials) exported for those grids
    (export.volume_objects)."""
    grids = read_volume(obj, reporter, materials)
    if grids is None:
        return
    scale = density_scale(obj, inst.matrix_world)
    slots = ([material_id(m, k, grids, scale) for m in materials]
             or [material_id(None, k, grids, scale)])
    name = f"{obj.name}#{k}" if inst.is_instance else obj.name
    holdout = _is_holdout(inst, obj, view_layer)
    seen = object_visibility(obj)
    color, pass_index, texspace = object_values(obj)
    source = Source(groups.group(domain(grids), slots, name, holdout, 0.0, seen, True,
                                 texspace),
                    color, pass_index, holdout, crypto_names(inst, obj))
    groups.place(source, inst.matrix_world, random_id(inst, obj))


# the key of the one warning about a black image (said by the export, or after the render)
BLACK_IMAGE = "black image"


def _emits(material) -> bool:
    volume = getattr(material, "volume", None)
    return (material.is_emissive() or (volume is not None and any(v > 0 for v in volume.emission))
            or any(_emits(side) for side in (material.mix or ())))


def dark_scene_message(meshes, materials, lights, world) -> str | None:
    """Why the image will be black, when nothing in the scene gives light (no lamp, no
    emissive material, a black world): said once, so that a black render is never a
    silent surprise. None when something may light the scene."""
    world_lit = (world.texture is not None or world.sun is not None
                 or max(world.color) * max(world.strength) > 0
                 or (world.volume is not None and any(v > 0 for v in world.volume.emission)))
    if lights or world_lit or any(_emits(m) for m in materials):
        return None
    if not meshes:
        return ("DRT: the scene is empty (no visible objects, no lights, a black world); "
                "the image is black")
    return ("DRT: nothing lights the scene (no lights, no emissive material, a black "
            "world); the image is black")
