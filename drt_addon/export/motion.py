"""Motion blur: the scene sampled over the shutter (Blender's settings for it are read
by export.motion_settings, whose names this module re-exports).

How: everything that does not move is exported at the shutter's middle, as Cycles does
(with position START or END that is half a shutter away from the frame). Then the
depsgraph is re-evaluated at each other motion step with `RenderEngine.frame_set`
(or `Scene.frame_set` when exporting a viewport depsgraph outside a render) and each
object instance's `matrix_world` is recorded; the original frame and subframe are
restored afterwards, also when the export fails. Per object:
- transforms that change (keyframes, constraints, parents, drivers): `RigidMotion` of
  the transforms at the steps; the mesh keeps its object-space arrays (evaluated once);
- objects whose evaluated mesh may change (`Object.is_deform_modified`, Cycles' own
  test: shape keys, armatures and other deform modifiers, modifiers that depend on time)
  are evaluated at every step too; if the vertices move within the object, the mesh
  gets a `DeformMotion` of its world-space vertex positions (rigid motion included). A
  topology change within the shutter is reported and the deformation is dropped (the
  transform still blurs), as Cycles does;
- the camera: `Camera.motion`, and `Camera.lens_motion` when a perspective camera's
  focal length changes (zoom blur);
- lamps that move get `motion_slices`: the lamp exported at the middles of
  LIGHT_SLICES equal slices of the shutter, from its transform interpolated like any
  rigid motion (the tracer gives each ray the slice its time falls in, see
  engine.lights.TimeSlicedLight). Emissive meshes blur like any other mesh.
Motion blur off, a zero shutter or nothing moving: nothing is attached and the render
takes the tracer's static path; with motion blur off the frame is never changed.
"""
from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from importlib import import_module
from typing import Optional

import numpy as np

from ..engine_link import engine
from .lights import export_light
from .matrices import to_numpy
from .mesh import _cache_key, instance_mesh
from .motion_settings import (CURVE_SAMPLES, MotionSettings, motion_steps, read_settings,
                              shutter_curve, use_deform_motion)

__all__ = ["CURVE_SAMPLES", "LIGHT_SLICES", "MOVE_TOLERANCE", "MotionExport", "MotionSettings",
           "motion_steps", "read_settings", "set_frame", "shutter_curve", "use_deform_motion"]

emotion = import_module(engine.__name__ + ".motion")   # engine.motion, either layout
interpolate_vertices = import_module(engine.__name__ + ".dicing").interpolate_vertices

MOVE_TOLERANCE = 1e-7         # relative change below which a transform or vertex is still


def set_frame(target, frame: int, subframe: float):
    """Re-evaluate the depsgraph at `frame + subframe`: target is the RenderEngine
    (`RenderEngine.frame_set`) or the Scene (`Scene.frame_set`). Tests spy on this."""
    if hasattr(target, "frame_current"):                  # a Scene
        target.frame_set(int(frame), subframe=float(subframe))
    else:
        target.frame_set(int(frame), float(subframe))


def _key(inst):
    """What identifies one object instance across re-evaluations (Cycles' ObjectKey:
    instancer, persistent id, object)."""
    obj = inst.object
    original = obj.original if obj.original is not None else obj
    if inst.is_instance:
        parent = inst.parent
        pid = parent.original.session_uid if parent is not None and parent.original else 0
        return (pid, tuple(inst.persistent_id), original.session_uid)
    return (original.session_uid,)


def _positions(obj):
    """(object-space vertex positions (V, 3) float64, triangles (T, 3) int32) of an
    evaluated object, or None."""
    try:
        mesh = obj.to_mesh()
    except RuntimeError:
        return None
    try:
        if mesh is None:
            return None
        mesh.calc_loop_triangles()
        co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", co)
        tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
        mesh.loop_triangles.foreach_get("vertices", tris)
    finally:
        obj.to_mesh_clear()
    return co.reshape(-1, 3).astype(np.float64), tris.reshape(-1, 3)


def _moves(arrays, scale) -> bool:
    a = np.asarray(arrays)
    return bool(np.max(np.abs(a - a[0])) > MOVE_TOLERANCE * max(scale, 1.0))


LIGHT_SLICES = 8      # time slices of a moving lamp (see engine.lights.TimeSlicedLight)


@dataclass
class _Tracked:
    key: tuple
    name: str
    steps: int                              # number of motion steps (>= 3)
    mesh_index: int = -1                    # into the exported meshes or lights
    local: object = None                    # LocalMesh (object space, at the centre)
    slots: list = None
    deform: bool = False                    # evaluate the mesh at every step
    matrices: dict = field(default_factory=dict)     # step index -> (4, 4)
    positions: dict = field(default_factory=dict)    # step index -> (V, 3) object space
    topology_changed: bool = False
    source: object = None                   # the original Blender object (lights)


class MotionExport:
    """Samples the scene over the shutter for `export_scene`. Use as a context manager
    around the whole export: entering moves the depsgraph to the shutter's middle (when
    that is not the frame), leaving restores the original frame and subframe."""

    def __init__(self, depsgraph, settings: MotionSettings, reporter, render_engine=None):
        self.depsgraph = depsgraph
        self.scene = depsgraph.scene
        self.settings = settings
        self.reporter = reporter
        self.target = render_engine
        if self.target is None and getattr(depsgraph, "mode", "VIEWPORT") != "RENDER":
            self.target = self.scene
        self.original = (int(self.scene.frame_current), float(self.scene.frame_subframe))
        self.at = float(self.original[0] + self.original[1])
        self.moved = False
        self.frame_sets = 0
        self.tracked: dict = {}
        self.lights: dict = {}
        self.camera_steps = 0
        self.camera_matrices: dict = {}
        self.camera_lenses: dict = {}
        self.stats = {}

    @property
    def usable(self) -> bool:
        return self.target is not None

    # -- frames ------------------------------------------------------------------------
    def goto(self, frame_time: float):
        if frame_time == self.at:
            return
        frame = math.floor(frame_time)
        subframe = frame_time - frame
        self.moved = True
        self.frame_sets += 1
        set_frame(self.target, frame, subframe)
        self.at = frame_time

    def __enter__(self):
        if not self.usable:
            self.reporter.warn("DRT: motion blur needs the render engine to re-evaluate the "
                               "scene at other times; rendering without motion blur",
                               key="motion blur no engine")
            return self
        self.t0 = time.perf_counter()
        self.goto(self.settings.centre)
        return self

    def __exit__(self, *exc):
        if self.moved:
            self.moved = False
            set_frame(self.target, *self.original)
            self.at = float(self.original[0] + self.original[1])
        return False

    # -- the main pass, at the shutter's middle -----------------------------------------
    def note_mesh(self, inst, obj, local, slots, mesh_index: int, name: str):
        if not self.usable:
            return
        parent = inst.parent if inst.is_instance else None
        steps = motion_steps(obj, parent)
        if steps == 0:
            return
        deform = use_deform_motion(obj, parent) and _deform_candidate(obj, self.depsgraph)
        t = _Tracked(_key(inst), name, steps, mesh_index, local, list(slots), deform)
        t.matrices[steps // 2] = to_numpy(inst.matrix_world)
        if deform:
            t.positions[steps // 2] = local.positions
        self.tracked[t.key] = t

    def note_light(self, inst, obj, light_index: int):
        if not self.usable:
            return
        t = _Tracked(_key(inst), obj.name, 3, mesh_index=light_index,
                     source=obj.original if obj.original is not None else obj)
        t.matrices[1] = to_numpy(inst.matrix_world)
        self.lights[t.key] = t

    def note_camera(self, cam_obj):
        if not self.usable or cam_obj is None:
            return
        self.camera_steps = motion_steps(cam_obj)
        if self.camera_steps:
            self._sample_camera(cam_obj, self.camera_steps // 2)

    def _sample_camera(self, cam_obj, i: int):
        ev = cam_obj.evaluated_get(self.depsgraph)
        self.camera_matrices[i] = to_numpy(ev.matrix_world)
        self.camera_lenses[i] = float(ev.data.lens)

    # -- the other steps -----------------------------------------------------------------
    def finish(self, meshes: list, camera, lights: list = ()) -> Optional[object]:
        """Sample the other motion steps, attach motion to `meshes`, `camera` and the
        exported `lights`, and return the engine Shutter (None when motion blur cannot be
        rendered)."""
        if not self.usable:
            return None
        step_counts = {t.steps for t in self.tracked.values()} | {3 if self.lights else 0,
                                                                  self.camera_steps}
        step_counts.discard(0)
        times = sorted({i / (k - 1) for k in step_counts for i in range(k)} - {0.5})
        for t in times:
            self.goto(self.settings.frame_time(t))
            self._sample(t)
        rigid = deforming = 0
        for tr in self.tracked.values():
            kind = self._attach(tr, meshes)
            rigid += kind == "rigid"
            deforming += kind == "deform"
        camera_moves = self._attach_camera(camera)
        moving_lights = 0
        for tr in self.lights.values():
            steps = sorted(tr.matrices)
            mats = [tr.matrices[i] for i in steps]
            if len(mats) > 1 and _moves(mats, np.abs(mats[0][:3, 3]).max()) \
                    and 0 <= tr.mesh_index < len(lights):
                motion = emotion.RigidMotion(np.array(steps) / (len(steps) - 1), mats)
                mids = (np.arange(LIGHT_SLICES) + 0.5) / LIGHT_SLICES
                slices = [export_light(tr.source, m, self.reporter) for m in motion.at(mids)]
                if all(sl is not None for sl in slices):
                    lights[tr.mesh_index].motion_slices = slices
                    moving_lights += 1
        self.stats = dict(frame_sets=self.frame_sets, times=[0.5] + times, rigid=rigid,
                          deforming=deforming, camera=camera_moves, lights=moving_lights,
                          seconds=time.perf_counter() - self.t0)
        return emotion.Shutter(self.settings.curve)

    def _sample(self, t: float):
        per_geometry = {}
        for inst in self.depsgraph.object_instances:
            key = None
            obj = inst.object
            if obj.type == "LIGHT" and self.lights and abs(t * 2 - round(t * 2)) < 1e-12:
                key = _key(inst)
                if key in self.lights:
                    self.lights[key].matrices[int(round(t * 2))] = to_numpy(inst.matrix_world)
                continue
            if not self.tracked:
                continue
            key = _key(inst)
            tr = self.tracked.get(key)
            if tr is None:
                continue
            i = t * (tr.steps - 1)
            if abs(i - round(i)) > 1e-9:
                continue                        # not one of this object's steps
            i = int(round(i))
            tr.matrices[i] = to_numpy(inst.matrix_world)
            if tr.deform:
                gkey = _cache_key(obj) or key
                if gkey not in per_geometry:
                    per_geometry[gkey] = _positions(obj)
                got = per_geometry[gkey]
                # a diced mesh: its vertices follow those it was diced from
                base, diced = tr.local.diced_from or (tr.local, None)
                kept = base.kept
                if (got is None or got[0].shape != base.positions.shape
                        or not np.array_equal(got[1] if kept is None else got[1][kept],
                                              base.triangles)):
                    tr.topology_changed = True
                else:        # a displaced mesh moves by its offset at every step (Cycles)
                    step = got[0] if diced is None else interpolate_vertices(got[0], diced)
                    off = tr.local.offset
                    tr.positions[i] = step if off is None else step + off
        cam = self.scene.camera
        if self.camera_steps and cam is not None:
            i = t * (self.camera_steps - 1)
            if abs(i - round(i)) < 1e-9:
                self._sample_camera(cam, int(round(i)))

    def _attach(self, tr: _Tracked, meshes: list) -> Optional[str]:
        k = tr.steps
        if len(tr.matrices) != k:
            self.reporter.warn(f"DRT: object {tr.name!r} is not there for the whole shutter; "
                               "it is rendered without motion blur",
                               key=(tr.name, "motion missing"))
            return None
        times = np.arange(k) / (k - 1)
        mats = np.stack([tr.matrices[i] for i in range(k)])
        mesh = meshes[tr.mesh_index]
        if tr.deform and tr.topology_changed:
            self.reporter.warn(f"DRT: object {tr.name!r} changes topology during the shutter; "
                               "its deformation is not blurred (its movement still is)",
                               key=(tr.name, "topology"))
        elif tr.deform and len(tr.positions) == k:
            local = np.stack([tr.positions[i] for i in range(k)])
            extent = float(np.abs(local[k // 2]).max()) if local.size else 1.0
            if _moves(local, extent):
                world = np.einsum("kij,kvj->kvi", mats[:, :3, :3], local) + mats[:, None, :3, 3]
                mesh.motion = emotion.DeformMotion(times, world)
                return "deform"
        if not _moves(mats, np.abs(mats[:, :3, 3]).max()):
            return None
        dets = np.linalg.det(mats[:, :3, :3])
        if (np.abs(dets) <= 1e-12 * max(np.abs(dets).max(), 1e-300)).any() or \
                (np.sign(dets) != np.sign(dets[k // 2])).any():
            # Scaled through zero (popping in, mirroring): no inverse at some time, so
            # the transforms are applied to the vertices and traced as a deformation.
            world = np.einsum("kij,vj->kvi", mats[:, :3, :3], tr.local.positions) \
                + mats[:, None, :3, 3]
            mesh.motion = emotion.DeformMotion(times, world)
            return "deform"
        # Rigid: the mesh in object space, placed by the transform at each ray's time.
        obj_space = instance_mesh(tr.local, np.eye(4), tr.slots, mesh.name)
        if np.linalg.det(mats[k // 2][:3, :3]) < 0:
            obj_space = _flip_winding(obj_space)
        obj_space.motion = emotion.RigidMotion(times, mats)
        meshes[tr.mesh_index] = obj_space
        return "rigid"

    def _attach_camera(self, camera) -> bool:
        """The camera's transform and, for a perspective camera, its focal length (zoom)
        over the shutter (Cycles blurs both)."""
        k = self.camera_steps
        if not k or len(self.camera_matrices) != k:
            return False
        times = np.arange(k) / (k - 1)
        mats = np.stack([self.camera_matrices[i] for i in range(k)])
        lenses = np.array([self.camera_lenses[i] for i in range(k)])
        moves = _moves(mats, np.abs(mats[:, :3, 3]).max())
        zooms = camera.kind == "PERSP" and _moves(lenses, float(lenses.max()))
        if moves:
            camera.motion = emotion.RigidMotion(times, mats)
        if zooms and hasattr(camera, "lens_motion"):
            camera.lens_motion = (times, lenses)
        return bool(moves or zooms)


def _flip_winding(mesh):
    """Swap two corners of every triangle (and of every per-corner attribute), as
    `instance_mesh` does for a mirroring transform."""
    names = {f.name for f in dataclasses.fields(mesh)}
    changes = {"triangles": mesh.triangles[:, [0, 2, 1]]}
    for name in ("corner_normals", "uvs"):
        value = getattr(mesh, name, None)
        if name in names and value is not None:
            changes[name] = np.asarray(value)[:, [0, 2, 1]]
    return dataclasses.replace(mesh, **changes)


def _deform_candidate(obj, depsgraph) -> bool:
    """Cycles' test for geometry that may change over time (BKE_object_is_deform_modified:
    shape keys, deform-only modifiers, modifiers depending on time)."""
    original = obj.original if obj.original is not None else obj
    try:
        return bool(original.is_deform_modified(depsgraph.scene, "RENDER"))
    except (AttributeError, TypeError, RuntimeError):
        return False
