"""Lights with Cycles' units: each Blender lamp as the parameters the light kernels read
(engine.kernels.lights, which sample them, intersect them and give their pdfs), and the
light set's pick probabilities.

Units (Blender's, checked against Cycles 5.0, see ../shared/notes/blender-facts.md):
- Point: strength S (W) gives intensity S / (4 pi) W/sr. With radius r > 0 it is a
  sphere of radiance S / (4 pi^2 r^2), which is the same intensity seen from afar (or,
  with `soft_falloff`, a disc of that radius and radiance facing the shaded point).
- Spot: a point light times Blender's smoothstep cone falloff, not renormalised.
- Sun: strength is irradiance (W/m^2) at normal incidence; with an angular diameter a > 0
  it is a uniform cone of half-angle a/2 and radiance E / (pi sin^2(a/2)).
- Area: one-sided along the light's -Z, radiance S / (pi A) with A the world-space area
  (pi/4 x size product for disks and ellipses); `normalize` off drops the 1/A. A Spread
  below 180 degrees (half angle h) weighs the radiance leaving at angle a from the
  normal by Cycles' soft-box grid, max(tan h - tan a, 0) / (tan h - h) (3 / h^3 for h
  <= 0.05), which keeps the lamp's power (kernels/lights/area.py).
- Emissive triangles (engine.mesh_lights): radiance = the material's emission, two-sided.

Every light model has its parameters (what engine.kernels.lights.pack puts in a row) and
power(scene_radius), the estimated power the light tree weighs entries by. The sampling
strategies are in the kernels' modules: engine/kernels/lights/point.py, sun.py, area.py
(with spherical_rectangle.py), environment.py, environment_map.py and triangles.py.
"""
from __future__ import annotations

import numpy as np

from . import visibility
from .light_distribution import cycles_distribution
from .luminance import luminance
from .scene import AreaLight, PointLight, SunLight
from .warp import orthonormal_basis
from .world_light import world_model

# Spherical rectangle sampling is used above this solid angle (steradians) ...
SOLID_ANGLE_MIN = 1e-4
# ... and when the point is farther from the light's plane than this fraction of the
# rectangle's edge sum (closer, the spherical rectangle degenerates to 0 or 2 pi).
IN_PLANE_REL = 1e-7
# An argument of the spherical rectangle's corner product below 0 but above this is
# rounding, a solid angle of 0, not 2 pi: farther than IN_PLANE_REL from the plane,
# 2 pi - omega is still above 1e-6 (engine.kernels.lights.spherical_rectangle).
SOLID_ANGLE_WRAP = -1e-9


class PointLightModel:
    """Point, spot, sphere (radius > 0) and soft-falloff disc lights."""

    def __init__(self, light: PointLight):
        self.position = np.asarray(light.position, dtype=np.float64)
        self.strength = np.asarray(light.strength, dtype=np.float64)
        self.radius = max(float(light.radius), 0.0)
        self.intensity = self.strength / (4.0 * np.pi)
        self.is_spot = light.spot_size is not None
        if self.is_spot:
            d = np.asarray(light.direction, dtype=np.float64)
            self.axis = d / np.linalg.norm(d)
            self.cos_half = float(np.cos(0.5 * min(max(float(light.spot_size), 0.0), np.pi)))
            self.smooth = min(max(float(light.spot_blend), 0.0), 1.0) * (1.0 - self.cos_half)
        self.delta = not (self.radius > 0.0)
        self.disc = (not self.delta) and bool(getattr(light, "soft_falloff", False))
        self.sphere_radiance = (self.strength / (4.0 * np.pi ** 2 * self.radius ** 2)
                                if not self.delta else None)
        if not self.delta and not np.all(np.isfinite(self.sphere_radiance)):
            self.delta = True                         # r so small r^2 underflows: a point
            self.disc = False
        self.visible = not self.delta
        self.visibility = int(getattr(light, "visibility", visibility.ALL))

    def power(self, scene_radius):
        p = luminance(self.strength)
        if self.is_spot:
            p *= 0.5 * (1.0 - self.cos_half)
        return p

class SunLightModel:
    def __init__(self, light: SunLight):
        d = np.asarray(light.direction, dtype=np.float64)
        self.to_light = -d / np.linalg.norm(d)
        self.irradiance = np.asarray(light.strength, dtype=np.float64)
        half = 0.5 * min(max(float(light.angle), 0.0), np.pi)
        self.one_minus = 2.0 * np.sin(0.5 * half) ** 2          # 1 - cos(half), exactly
        sin2_half = np.sin(half) ** 2
        # Below ~1e-7 rad the disc is a delta (and sin^2 would lose the radiance's digits).
        self.delta = half < 1e-7 or not sin2_half > 0
        self.visible = not self.delta
        self.visibility = int(getattr(light, "visibility", visibility.ALL))
        if not self.delta:
            self.cos_max = float(np.cos(half))
            self.radiance = self.irradiance / (np.pi * sin2_half)
            self.t, self.b = orthonormal_basis(self.to_light[None, :])

    def power(self, scene_radius):
        return luminance(self.irradiance) * np.pi * scene_radius ** 2


class AreaLightModel:
    def __init__(self, light: AreaLight):
        m = np.asarray(light.matrix, dtype=np.float64)
        if m.shape != (4, 4) or not np.all(np.isfinite(m)):
            raise ValueError(f"area light {light.name!r}: matrix must be a finite 4x4")
        self.shape = light.shape
        if self.shape not in ("SQUARE", "RECTANGLE", "DISK", "ELLIPSE"):
            raise ValueError(f"area light {light.name!r}: unknown shape {self.shape!r}")
        sx = float(light.size_x)
        sy = sx if self.shape in ("SQUARE", "DISK") else float(light.size_y)
        self.center = m[:3, 3].copy()
        self.ax = m[:3, 0] * (0.5 * sx)      # half-extent vectors in world space
        self.ay = m[:3, 1] * (0.5 * sy)
        normal = np.cross(self.ax, self.ay)
        area4 = np.linalg.norm(normal)        # |ax x ay| = A_rect / 4
        if not np.isfinite(area4) or area4 <= 0:
            raise ValueError(f"area light {light.name!r} has zero area")
        # Local +Z (emission goes along -Z), taken from the matrix's own Z axis so a
        # mirrored transform does not flip the emitting side.
        self.normal = normal / area4 * (1.0 if normal @ m[:3, 2] >= 0 else -1.0)
        self.round = self.shape in ("DISK", "ELLIPSE")
        self.area = 4.0 * area4 * (np.pi / 4.0 if self.round else 1.0)
        strength = np.asarray(light.strength, dtype=np.float64)
        self.radiance = strength / (np.pi * (self.area if light.normalize else 1.0))
        self.delta = False
        self.visible = True
        self.visible_camera = bool(light.visible_camera)
        self.visibility = int(getattr(light, "visibility", visibility.ALL))
        if not self.visible_camera:
            self.visibility &= ~visibility.CAMERA
        # Inverse of [ax ay normal] maps world offsets to (s, t, z) with s,t in [-1, 1].
        self.inv = np.linalg.inv(np.stack([self.ax, self.ay, self.normal], axis=1))
        # Spherical rectangle frame (rectangles with perpendicular edges only).
        lx, ly = 2.0 * np.linalg.norm(self.ax), 2.0 * np.linalg.norm(self.ay)
        self.xh, self.yh = self.ax / (0.5 * lx), self.ay / (0.5 * ly)
        self.solid_angle_ok = (not self.round) and abs(self.xh @ self.yh) < 1e-9
        self.lx, self.ly = lx, ly
        self.zh = np.cross(self.xh, self.yh)
        self.corner = self.center - self.ax - self.ay
        self.tan_half_spread, self.normalize_spread = spread_parameters(light.spread)

    def power(self, scene_radius):
        return luminance(self.radiance) * np.pi * self.area


MIN_HALF_SPREAD = 1e-4     # radians: a Spread of 0 (Cycles: a single direction) is this


def spread_parameters(spread) -> tuple:
    """(tan h, normalisation) of an area lamp's Spread (full angle, radians; h the half
    angle), as Cycles computes them; (0, 0) for a lamp that emits over the hemisphere.
    The normalisation keeps the power: the integral of cos(a) (tan h - tan a) over the
    cone of half angle h is pi (tan h - h)."""
    spread = float(spread) if np.isfinite(spread) else np.pi
    half = 0.5 * min(max(spread, 0.0), np.pi)
    if half >= 0.5 * np.pi - 1e-6:
        return 0.0, 0.0
    half = max(half, MIN_HALF_SPREAD)
    tan_h = float(np.tan(half))
    return tan_h, (1.0 / (tan_h - half) if half > 0.05 else 3.0 / half ** 3)


class TimeSlicedLight:
    """A lamp that moves during the shutter: the exporter gives the lamp at the middles of
    K equal slices of the shutter (`light.motion_slices`), and each ray uses the lamp of
    the slice its time falls in. This is exact at the slice middles and off by up to half
    a slice's movement elsewhere, and it costs nothing for lamps that do not move."""

    def __init__(self, slices):
        self.slices = [make_light(l) for l in slices]
        kinds = {type(m) for m in self.slices}
        if len(kinds) != 1:
            raise ValueError("a moving light must keep its type over the shutter")
        first = self.slices[0]
        self.delta, self.visible = first.delta, first.visible
        self.visible_camera = getattr(first, "visible_camera", True)
        self.visibility = first.visibility
        self.is_sun = isinstance(first, SunLightModel)
        self.k = len(self.slices)

    def power(self, scene_radius):
        return float(np.mean([m.power(scene_radius) for m in self.slices]))


def make_light(light):
    slices = getattr(light, "motion_slices", None)
    if slices:
        return TimeSlicedLight(slices)
    if isinstance(light, PointLight):
        return PointLightModel(light)
    if isinstance(light, SunLight):
        return SunLightModel(light)
    if isinstance(light, AreaLight):
        return AreaLightModel(light)
    raise TypeError(f"unknown light type {type(light).__name__}")


WORLD = "world"         # LightSet.sources' name for the world's own light


class LightSet:
    """All lights of a scene: the lamps (`models`) followed by the emissive triangles
    (`mesh`, an engine.mesh_lights.EmissiveTriangles, may be None), as one list of
    entries; entry k >= n_lamps is triangle k - n_lamps. With the light tree off,
    next-event estimation picks one entry per shading point as Cycles' light
    distribution does (engine.light_distribution: lamps and the world alike, triangles by
    area): `select_pdf`, over len(self) entries. Each model's estimated power (luminance
    of radiance x pi x area for area lights and triangles, of strength for points, of
    irradiance x pi R^2 for suns) is what the tree weighs it by, and a light of none is
    left out. world_sun: the lamp of `lights` that is the world's Sky Texture sun."""

    def __init__(self, lights, scene_radius: float, mesh_lights=None, world=None,
                 world_sun=None):
        self.models = [make_light(l) for l in lights]
        # what each model was made from: a lamp of `lights`, or WORLD (light groups)
        self.sources = list(lights)
        # the world: a model (engine.world_light), a World or an RGB triple; kept even
        # when it is too dark to be a light, for what escaped rays see
        self.world = None if world is None else (
            world if getattr(world, "is_environment", False) else world_model(world))
        # The world is sampled as a light unless it is an environment whose Sampling
        # Method is None. Cycles never samples a uniform world (its LightManager disables
        # a background light that does not vary in space; BSDF rays that escape find
        # it); DRT does, for less noise, and evaluates refraction towards it on Walter's
        # pairs only (`uniform_world`; engine/kernels/bsdf/dielectric.py's note), which is what
        # Cycles' escaping rays see.
        if self.world is not None and getattr(self.world, "light_sampling", True):
            self.models.append(self.world)
            self.sources.append(WORLD)
        power = np.array([max(m.power(scene_radius), 0.0) for m in self.models], dtype=np.float64)
        power = np.where(np.isfinite(power), power, 0.0)
        keep = power > 0
        self.models = [m for m, k in zip(self.models, keep) if k]
        self.sources = [m for m, k in zip(self.sources, keep) if k]
        self.n_lamps = len(self.models)
        env = [k for k, m in enumerate(self.models) if getattr(m, "is_environment", False)]
        self.env_index = env[0] if env else None
        self.mesh = mesh_lights if mesh_lights is not None and len(mesh_lights) else None
        sun = [k for k, src in enumerate(self.sources)
               if world_sun is not None and src is world_sun]
        self.select_pdf = cycles_distribution(
            self.n_lamps, self.env_index, sun[0] if sun else None,
            self.mesh.area if self.mesh is not None else np.zeros(0))
        self.cdf = np.cumsum(self.select_pdf)
        if len(self.cdf):
            self.cdf[-1] = 1.0

    def __len__(self):
        return len(self.select_pdf)

    def suns(self):
        return [(k, m) for k, m in enumerate(self.models)
                if (isinstance(m, SunLightModel) or getattr(m, "is_sun", False))
                and not m.delta]
