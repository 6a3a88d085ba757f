"""Lights with Cycles' units, their sampling and their pdfs.

Units (Blender's, checked against Cycles 5.0, see ../shared/notes/blender-facts.md):
- Point: strength S (W) gives intensity S / (4 pi) W/sr. With radius r > 0 it is a
  sphere of radiance S / (4 pi^2 r^2), which is the same intensity seen from afar.
- Spot: a point light times Blender's smoothstep cone falloff, not renormalised.
- Sun: strength is irradiance (W/m^2) at normal incidence; with an angular diameter a > 0
  it is a uniform cone of half-angle a/2 and radiance E / (pi sin^2(a/2)).
- Area: one-sided along the light's -Z, radiance S / (pi A) with A the world-space area
  (pi/4 x size product for disks and ellipses); `normalize` off drops the 1/A.

Each light samples a direction from a shading point with a pdf in solid angle (area
lights by area, converted; sphere lights by the cone they subtend), and area, sphere and
sun lights can also be hit by BSDF-sampled rays, which multiple importance sampling
needs: `intersect` and `pdf` give what those rays see.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .scene import AreaLight, PointLight, SunLight
from .warp import concentric_disk, one_minus_cos, orthonormal_basis, uniform_cone, uniform_sphere

INF = np.inf


def luminance(rgb) -> float:
    r, g, b = np.asarray(rgb, dtype=np.float64)[..., :3].T
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


def _smoothstep01(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


@dataclass
class LightSample:
    wi: np.ndarray        # (n, 3) unit direction towards the light
    dist: np.ndarray      # (n,) distance to the sampled point (inf for the sun)
    radiance: np.ndarray  # (n, 3) radiance arriving along -wi (0 where it cannot)
    pdf: np.ndarray       # (n,) solid-angle pdf (1 for delta lights)
    delta: bool           # a point or a zero-angle sun: no MIS, BSDF rays never hit it


class PointLightModel:
    def __init__(self, light: PointLight):
        self.position = np.asarray(light.position, dtype=np.float64)
        self.strength = np.asarray(light.strength, dtype=np.float64)
        self.radius = max(float(light.radius), 0.0)
        self.intensity = self.strength / (4.0 * np.pi)
        self.is_spot = light.spot_size is not None
        if self.is_spot:
            d = np.asarray(light.direction, dtype=np.float64)
            self.axis = d / np.linalg.norm(d)
            self.cos_half = float(np.cos(0.5 * min(float(light.spot_size), np.pi)))
            self.smooth = max(float(light.spot_blend), 0.0) * (1.0 - self.cos_half)
        self.sphere_radiance = (self.strength / (4.0 * np.pi ** 2 * self.radius ** 2)
                                if self.radius > 0 else None)
        self.delta = self.radius == 0.0
        self.visible = not self.delta

    def power(self, scene_radius):
        p = luminance(self.strength)
        if self.is_spot:
            p *= 0.5 * (1.0 - self.cos_half)
        return p

    def _spot(self, dir_from_light):
        if not self.is_spot:
            return 1.0
        c = dir_from_light @ self.axis
        if self.smooth > 0.0:
            return _smoothstep01((c - self.cos_half) / self.smooth)
        return (c > self.cos_half).astype(np.float64)

    def sample(self, p, u):
        to = self.position - p
        d2 = (to * to).sum(1)
        dist_c = np.sqrt(d2)
        n = len(p)
        if self.delta:
            wi = to / np.maximum(dist_c, 1e-300)[:, None]
            rad = self.intensity[None, :] / np.maximum(d2, 1e-300)[:, None]
            rad = rad * np.atleast_1d(self._spot(-wi))[:, None] if self.is_spot else rad
            return LightSample(wi, dist_c, rad, np.ones(n), True)
        r = self.radius
        inside = dist_c <= r
        # Uniform cone of directions subtended by the sphere.
        sin2 = np.minimum((r * r) / np.maximum(d2, 1e-300), 1.0)
        cos_max = np.sqrt(np.maximum(0.0, 1.0 - sin2))
        axis = to / np.maximum(dist_c, 1e-300)[:, None]
        local = uniform_cone(u, cos_max)
        t, b = orthonormal_basis(axis)
        wi = local[:, :1] * t + local[:, 1:2] * b + local[:, 2:3] * axis
        # Distance to the near side of the sphere along wi.
        proj = dist_c * local[:, 2]
        disc = np.maximum(r * r - (d2 - proj * proj), 0.0)
        dist = proj - np.sqrt(disc)
        pdf = 1.0 / (2.0 * np.pi * np.maximum(one_minus_cos(cos_max), 1e-300))
        if inside.any():                                 # inside the sphere: uniform sphere
            wi_in = uniform_sphere(u[inside])
            wi[inside] = wi_in
            pdf[inside] = 1.0 / (4.0 * np.pi)
            dist[inside] = self._exit_distance(p[inside], wi_in)
        rad = np.broadcast_to(self.sphere_radiance, (n, 3)).copy()
        if self.is_spot:
            rad *= np.atleast_1d(self._spot(-axis))[:, None]
        return LightSample(wi, np.maximum(dist, 0.0), rad, pdf, False)

    def _exit_distance(self, p, d):
        oc = p - self.position
        b = (oc * d).sum(1)
        c = (oc * oc).sum(1) - self.radius ** 2
        return -b + np.sqrt(np.maximum(b * b - c, 0.0))

    def intersect(self, o, d):
        """Distance to the sphere along each ray (inf if missed) and its radiance."""
        n = len(o)
        if self.delta:
            return np.full(n, INF), None
        oc = o - self.position
        b = (oc * d).sum(1)
        c = (oc * oc).sum(1) - self.radius ** 2
        disc = b * b - c
        ok = disc >= 0
        sq = np.sqrt(np.maximum(disc, 0.0))
        t0, t1 = -b - sq, -b + sq
        t = np.where(t0 > 0, t0, np.where(t1 > 0, t1, INF))
        t = np.where(ok, t, INF)
        rad = np.broadcast_to(self.sphere_radiance, (n, 3)).copy()
        if self.is_spot:
            rad *= np.atleast_1d(self._spot(-((self.position - o) / np.maximum(
                np.linalg.norm(self.position - o, axis=1), 1e-300)[:, None])))[:, None]
        return t, rad

    def pdf(self, p, wi, t):
        to = self.position - p
        d2 = (to * to).sum(1)
        sin2 = np.minimum(self.radius ** 2 / np.maximum(d2, 1e-300), 1.0)
        cos_max = np.sqrt(np.maximum(0.0, 1.0 - sin2))
        pdf = 1.0 / (2.0 * np.pi * np.maximum(one_minus_cos(cos_max), 1e-300))
        return np.where(d2 <= self.radius ** 2, 1.0 / (4.0 * np.pi), pdf)


class SunLightModel:
    def __init__(self, light: SunLight):
        d = np.asarray(light.direction, dtype=np.float64)
        self.to_light = -d / np.linalg.norm(d)
        self.irradiance = np.asarray(light.strength, dtype=np.float64)
        half = 0.5 * min(max(float(light.angle), 0.0), np.pi)
        self.delta = half < 1e-7
        self.visible = not self.delta
        if not self.delta:
            self.cos_max = float(np.cos(half))
            self.one_minus = float(one_minus_cos(self.cos_max))
            self.radiance = self.irradiance / (np.pi * np.sin(half) ** 2)
            self.t, self.b = orthonormal_basis(self.to_light[None, :])

    def power(self, scene_radius):
        return luminance(self.irradiance) * np.pi * scene_radius ** 2

    def sample(self, p, u):
        n = len(p)
        if self.delta:
            wi = np.broadcast_to(self.to_light, (n, 3)).copy()
            rad = np.broadcast_to(self.irradiance, (n, 3)).copy()
            return LightSample(wi, np.full(n, INF), rad, np.ones(n), True)
        local = uniform_cone(u, self.cos_max)
        wi = local[:, :1] * self.t + local[:, 1:2] * self.b + local[:, 2:3] * self.to_light
        pdf = np.full(n, 1.0 / (2.0 * np.pi * self.one_minus))
        rad = np.broadcast_to(self.radiance, (n, 3)).copy()
        return LightSample(wi, np.full(n, INF), rad, pdf, False)

    def escaped(self, d):
        """Radiance seen along escaping rays d (zero outside the sun's disc)."""
        n = len(d)
        if self.delta:
            return np.zeros((n, 3))
        inside = (d @ self.to_light) >= self.cos_max
        return np.where(inside[:, None], self.radiance[None, :], 0.0)

    def pdf(self, p, wi, t):
        return np.full(len(wi), 1.0 / (2.0 * np.pi * self.one_minus))


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
        # Inverse of [ax ay normal] maps world offsets to (s, t, z) with s,t in [-1, 1].
        self.inv = np.linalg.inv(np.stack([self.ax, self.ay, self.normal], axis=1))

    def power(self, scene_radius):
        return luminance(self.radiance) * np.pi * self.area

    def sample(self, p, u):
        if self.round:
            st = concentric_disk(u)
        else:
            st = 2.0 * u - 1.0
        q = self.center + st[:, :1] * self.ax + st[:, 1:2] * self.ay
        to = q - p
        d2 = (to * to).sum(1)
        dist = np.sqrt(d2)
        wi = to / np.maximum(dist, 1e-300)[:, None]
        cos_l = wi @ self.normal                      # > 0 when p is on the emitting (-Z) side
        ok = (cos_l > 0) & (dist > 0)
        pdf = np.where(ok, d2 / (self.area * np.maximum(cos_l, 1e-300)), 0.0)
        rad = np.where(ok[:, None], self.radiance[None, :], 0.0)
        return LightSample(wi, dist, rad, pdf, False)

    def intersect(self, o, d):
        denom = d @ self.normal
        # Only the emitting side counts: rays travelling along +Z hit the -Z face.
        front = denom > 0
        t = np.where(front, ((self.center - o) @ self.normal) / np.where(front, denom, 1.0), INF)
        t = np.where(t > 0, t, INF)
        q = o + d * np.where(np.isfinite(t), t, 0.0)[:, None]
        st = (q - self.center) @ self.inv.T
        if self.round:
            inside = st[:, 0] ** 2 + st[:, 1] ** 2 <= 1.0
        else:
            inside = (np.abs(st[:, 0]) <= 1.0) & (np.abs(st[:, 1]) <= 1.0)
        t = np.where(inside, t, INF)
        rad = np.broadcast_to(self.radiance, (len(o), 3))
        return t, rad

    def pdf(self, p, wi, t):
        cos_l = np.abs(wi @ self.normal)
        return t * t / (self.area * np.maximum(cos_l, 1e-300))


def make_light(light):
    if isinstance(light, PointLight):
        return PointLightModel(light)
    if isinstance(light, SunLight):
        return SunLightModel(light)
    if isinstance(light, AreaLight):
        return AreaLightModel(light)
    raise TypeError(f"unknown light type {type(light).__name__}")


class LightSet:
    """All lights of a scene, one picked per shading point in proportion to its power."""

    def __init__(self, lights, scene_radius: float):
        self.models = [make_light(l) for l in lights]
        power = np.array([max(m.power(scene_radius), 0.0) for m in self.models], dtype=np.float64)
        keep = power > 0
        self.models = [m for m, k in zip(self.models, keep) if k]
        power = power[keep]
        self.select_pdf = power / power.sum() if len(power) else power
        self.cdf = np.cumsum(self.select_pdf)
        if len(self.cdf):
            self.cdf[-1] = 1.0

    def __len__(self):
        return len(self.models)

    def sample(self, p, u_pick, u_point):
        """Pick one light per point and sample it. Returns (LightSample with pdf
        including the pick probability, light index, delta mask)."""
        n = len(p)
        idx = np.searchsorted(self.cdf, u_pick, side="right").clip(0, len(self.models) - 1)
        wi = np.zeros((n, 3))
        dist = np.zeros(n)
        rad = np.zeros((n, 3))
        pdf = np.zeros(n)
        delta = np.zeros(n, dtype=bool)
        for k, model in enumerate(self.models):
            sel = np.nonzero(idx == k)[0]
            if sel.size == 0:
                continue
            s = model.sample(p[sel], u_point[sel])
            wi[sel], dist[sel], rad[sel] = s.wi, s.dist, s.radiance
            pdf[sel] = s.pdf * self.select_pdf[k]
            delta[sel] = s.delta
        return LightSample(wi, dist, rad, pdf, False), idx, delta

    def hit_surfaces(self, o, d, tmax):
        """The nearest area or sphere light along each ray before tmax:
        (t, light index or -1, radiance)."""
        n = len(o)
        best_t = np.asarray(tmax, dtype=np.float64).copy()
        best_i = np.full(n, -1, dtype=np.int64)
        rad = np.zeros((n, 3))
        for k, model in enumerate(self.models):
            if not model.visible or isinstance(model, SunLightModel):
                continue
            t, r = model.intersect(o, d)
            closer = t < best_t
            if closer.any():
                best_t[closer] = t[closer]
                best_i[closer] = k
                rad[closer] = r[closer]
        return best_t, best_i, rad

    def pdf(self, k_index, p, wi, t):
        """Solid-angle pdf, pick probability included, of sampling direction wi from p
        towards light k_index[i] (hit at distance t)."""
        out = np.zeros(len(p))
        for k, model in enumerate(self.models):
            sel = np.nonzero(k_index == k)[0]
            if sel.size:
                out[sel] = model.pdf(p[sel], wi[sel], t[sel]) * self.select_pdf[k]
        return out

    def suns(self):
        return [(k, m) for k, m in enumerate(self.models)
                if isinstance(m, SunLightModel) and not m.delta]
