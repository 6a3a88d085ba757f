"""Adaptive subdivision at export: a mesh whose last modifier is a Subdivision modifier
with Adaptive Subdivision on, and whose materials move it (true displacement), is diced
as Cycles dices it (engine.dicing) before it is displaced: its edges cut to the modifier's
Pixel Size times Render > Subdivision > Dicing Rate on screen (Viewport rate in the
viewport), seen from the Dicing Camera or the scene's camera, or to its Edge Length in
object space; at most Max Subdivisions levels per edge of the cage, coarser off screen
by the Offscreen Scale. A mesh that nothing displaces is left at its render levels: its
surface would not change."""
from __future__ import annotations

import dataclasses
import importlib
from dataclasses import dataclass

import numpy as np

from ..engine_link import engine
from .camera import export_camera
from .matrices import to_numpy

D = importlib.import_module(engine.__name__ + ".dicing")
CameraModel = importlib.import_module(engine.__name__ + ".camera").CameraModel

# the triangles one diced mesh may grow to: beyond, its rate is coarsened and a warning
# names it (about 100 bytes a triangle once displaced and placed)
MAX_TRIANGLES = 8_000_000


@dataclass(frozen=True)
class Dicing:
    """How one mesh is diced: segments of `rate` (pixels with a camera, else object-space
    length), at most `max_factor` per edge of the mesh DRT receives."""
    rate: float
    max_factor: int
    camera: object = None              # engine.dicing.DicingCamera, Pixel space


def adaptive_modifier(obj, rendering: bool = True):
    """The object's last modifier when it is an enabled Subdivision modifier with
    Adaptive Subdivision on (the one Cycles dices), else None."""
    mods = getattr(obj, "modifiers", None)
    if not mods:
        return None
    m = mods[-1]
    enabled = m.show_render if rendering else m.show_viewport
    if m.type != "SUBSURF" or not enabled or not getattr(m, "use_adaptive_subdivision",
                                                          False):
        return None
    return m


class SceneDicing:
    """The scene's dicing settings (scene.cycles), and its dicing camera, made once when
    a mesh first needs it."""

    def __init__(self, depsgraph, view=None, aspect: float = 1.0):
        self.depsgraph = depsgraph
        self.scene = depsgraph.scene
        self.view = view
        self.aspect = aspect
        self.rendering = view is None
        self._camera = None
        cycles = getattr(self.scene, "cycles", None)
        self.rate = float(getattr(cycles, "dicing_rate" if self.rendering
                                  else "preview_dicing_rate", 1.0 if self.rendering else 8.0))
        self.max_level = int(getattr(cycles, "max_subdivisions", 12))
        self.offscreen = float(getattr(cycles, "offscreen_dicing_scale", 4.0))

    def camera(self):
        """The engine.dicing.DicingCamera: the viewport's view, or the Dicing Camera (the
        scene's camera without one) over the whole frame."""
        if self._camera is None:
            if self.view is not None:
                model = CameraModel(*self.view)
            else:
                cycles = getattr(self.scene, "cycles", None)
                cam = getattr(cycles, "dicing_camera", None) or self.scene.camera
                r = self.scene.render
                pct = r.resolution_percentage / 100.0
                model = CameraModel(export_camera(cam, self.depsgraph),
                                    max(1, int(r.resolution_x * pct)),
                                    max(1, int(r.resolution_y * pct)), self.aspect)
            self._camera = D.DicingCamera.from_model(model, self.offscreen)
        return self._camera

    def of(self, obj):
        """The object's Dicing, or None when it asks for no adaptive subdivision."""
        m = adaptive_modifier(obj, self.rendering)
        if m is None:
            return None
        levels = int(m.render_levels if self.rendering else m.levels)
        max_factor = 2 ** max(self.max_level - levels, 0)
        if getattr(m, "adaptive_space", "PIXEL") == "OBJECT":
            return Dicing(self.rate * float(m.adaptive_object_edge_length), max_factor)
        if self.view is None and self.scene.camera is None:
            return None
        return Dicing(max(self.rate * float(m.adaptive_pixel_size), 0.1), max_factor,
                      self.camera())


def dice_local(local, dicing: Dicing, matrix_world, warn=None):
    """`local` (export.mesh.LocalMesh, object space) diced by `dicing`, placed at
    `matrix_world` (Pixel space); `local` itself when every edge keeps one segment.
    `warn(message)` hears of a mesh coarsened to stay within MAX_TRIANGLES."""
    positions = local.positions
    edges, _ = D.unique_edges(local.triangles)
    if dicing.camera is not None:
        m = np.asarray(to_numpy(matrix_world), np.float64)
        points = positions @ m[:3, :3].T + m[:3, 3]
    else:
        points = positions
    rate = dicing.rate
    factors = D.edge_factors(points[edges[:, 0]], points[edges[:, 1]], rate,
                             dicing.max_factor, dicing.camera)
    size = D.tessellation_size(local.triangles, factors)
    if size > MAX_TRIANGLES:
        rate *= np.sqrt(size / MAX_TRIANGLES)
        factors = D.edge_factors(points[edges[:, 0]], points[edges[:, 1]], rate,
                                 dicing.max_factor, dicing.camera)
        if warn is not None:
            warn(f"would make {size:,} triangles; diced at {rate:.3g} "
                 f"{'pixels' if dicing.camera is not None else 'units'} instead of "
                 f"{dicing.rate:.3g}")
    if factors.max() <= 1:
        return local
    diced = D.dice(positions, local.triangles, factors)
    return diced_mesh(local, diced)


def diced_mesh(local, diced):
    """The LocalMesh of `diced` (engine.dicing.Diced) from `local`: each new corner
    interpolates its parent triangle's corners, each new vertex its parent vertices."""
    parent = diced.parent

    def corners(values, unit=False):
        if values is None:
            return None
        out = D.interpolate_corners(values, diced)
        return _unit(out) if unit else out
    tangents = None
    if local.tangents is not None:
        tangents = corners(local.tangents)
        tangents[..., :3] = _unit(tangents[..., :3])
        tangents[..., 3] = np.sign(local.tangents[parent][:, :1, 3])   # the parent's sign
    vertex_normals = None
    if local.vertex_normals is not None:
        vertex_normals = _unit(D.interpolate_vertices(local.vertex_normals, diced))
    return dataclasses.replace(
        local, positions=diced.positions, triangles=diced.triangles,
        material=local.material[parent], normals=corners(local.normals, unit=True),
        uvs=corners(local.uvs), tangents=tangents, colors=corners(local.colors),
        kept=None if local.kept is None else local.kept[parent],
        vertex_normals=vertex_normals,
        smooth=None if local.smooth is None else local.smooth[parent], offset=None,
        diced_from=(local, diced))


def _unit(v):
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(n > 0, v / np.where(n > 0, n, 1), v).astype(v.dtype)
