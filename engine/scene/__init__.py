"""The scene description: the whole contract between the Blender exporter and the tracer.

Plain NumPy arrays and small dataclasses, nothing else, so the tracer is tested without
Blender and the exporter is tested without tracing. Units and conventions follow Blender:
metres, right-handed world with +Z up, cameras looking down their local -Z with +Y up,
colours in scene-linear Rec.709, light strengths in Blender's watts (converted to radiance
in `engine.lights`, which is the only place that knows Cycles' unit conventions).

Precision: geometry is stored in float64 so that the exporter never loses bits; the
acceleration structure rounds to float32 (Embree's only format) and hit points are rebuilt
in float64 from barycentrics (see `engine.surface`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from .camera import Camera
from .geometry import Instances, ObjectInfo, TriangleMesh
from .lights import AreaLight, PointLight, SunLight
from .material import Material, Volume
from .world import World

__all__ = ["AreaLight", "Camera", "Instances", "Material", "ObjectInfo", "PointLight",
           "Scene", "SunLight", "TriangleMesh", "Volume", "World"]


@dataclass
class Scene:
    camera: Camera
    width: int
    height: int
    meshes: list = field(default_factory=list)
    materials: list = field(default_factory=lambda: [Material()])
    lights: list = field(default_factory=list)
    world: World = field(default_factory=World)
    pixel_aspect: float = 1.0
    shutter: Optional[object] = None     # engine.motion.Shutter; None = motion blur off
    film_transparent: bool = False       # Blender's Film > Transparent: background alpha 0
    curves: list = field(default_factory=list)   # hair: engine.curves.HairCurves
    # the view layer's light groups (Cycles' Combined_<name> passes): lamps, emissive
    # meshes and the world name theirs by `lightgroup`
    light_groups: tuple = ()

    def __post_init__(self):
        if self.width < 1 or self.height < 1:
            raise ValueError(f"resolution must be positive, got {self.width}x{self.height}")
        if not self.materials:
            self.materials = [Material()]
        for m in self.meshes + self.curves:
            if len(m.material_indices) and m.material_indices.max() >= len(self.materials):
                raise ValueError(f"mesh {m.name!r} uses a material index beyond the "
                                 f"{len(self.materials)} materials")

    def has_motion(self) -> bool:
        """True only when motion blur is on and something actually moves: otherwise the
        render takes the static path (no time dimension, no extra acceleration structures)."""
        if self.shutter is None:
            return False
        moving = [m for m in self.meshes if m.motion is not None and not _is_static(m.motion)]
        camera_moves = self.camera.motion is not None and not _is_static(self.camera.motion)
        lamps_move = any(getattr(l, "motion_slices", None) for l in self.lights)
        lm = self.camera.lens_motion
        zooms = lm is not None and bool(np.ptp(np.asarray(lm[1], dtype=np.float64)) > 0)
        return bool(moving) or camera_moves or zooms or lamps_move

    def has_volumes(self) -> bool:
        """Whether any material or the world holds a medium (engine.kernels.volume)."""
        return any(m.volume is not None or not m.surface for m in self.materials) \
            or self.world.volume is not None

    def has_holdouts(self) -> bool:
        """Whether an object is a holdout, or a material is or holds a Holdout shader (also
        as a side of a Mix Shader)."""
        def holds(m):
            return (getattr(m, "holdout", False) or getattr(m, "holdout_weight", 0.0) > 0
                    or any(holds(side) for side in (getattr(m, "mix", None) or ())))
        return any(m.holdout for m in self.meshes + self.curves) or \
            any(holds(m) for m in self.materials)

    def needs_alpha(self) -> bool:
        """Whether samples carry a coverage (alpha) below one anywhere."""
        return self.film_transparent or self.has_holdouts()

    def triangle_count(self) -> int:
        return int(sum(len(m.triangles) for m in self.meshes))


def _is_static(motion) -> bool:
    if hasattr(motion, "is_static"):
        return motion.is_static()
    p = motion.positions
    return bool(np.all(np.abs(p - p[0]) == 0))
