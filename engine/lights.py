"""Lights with Cycles' units, their sampling and their pdfs.

Units (Blender's, checked against Cycles 5.0, see ../shared/notes/blender-facts.md):
- Point: strength S (W) gives intensity S / (4 pi) W/sr. With radius r > 0 it is a
  sphere of radiance S / (4 pi^2 r^2), which is the same intensity seen from afar (or,
  with `soft_falloff`, a disc of that radius and radiance facing the shaded point).
- Spot: a point light times Blender's smoothstep cone falloff, not renormalised.
- Sun: strength is irradiance (W/m^2) at normal incidence; with an angular diameter a > 0
  it is a uniform cone of half-angle a/2 and radiance E / (pi sin^2(a/2)).
- Area: one-sided along the light's -Z, radiance S / (pi A) with A the world-space area
  (pi/4 x size product for disks and ellipses); `normalize` off drops the 1/A.
- Emissive triangles (engine.mesh_lights): radiance = the material's emission, two-sided.

Every light model has
  sample(p, u) -> LightSample(wi, dist, radiance, pdf, delta): one direction per shading
      point p from u in [0,1)^2, through a continuous map of u (stratification survives),
      pdf in solid angle at p;
  intersect(o, d) -> (t, radiance): what a BSDF-sampled ray sees (inf where it misses);
  pdf(p, wi, t): the solid-angle pdf with which sample(p, .) produces wi (t = distance of
      the light along wi). It is a deterministic function of (p, wi): whatever strategy
      sample() chose for p (solid angle or area), pdf() chooses the same, so the power
      heuristic weights of multiple importance sampling sum to one.

Strategies (all pdfs in solid angle, omega = solid angle subtended, A = area):
- sphere light outside the sphere: the uniform cone it subtends, pdf 1 / (2 pi (1 - cos
  theta_max)) with sin^2 theta_max = r^2 / d^2 (1 - cos computed without cancellation so
  a 1e-6 m light 1e4 m away keeps its precision); inside: uniform sphere, 1 / (4 pi).
- sun disc: uniform cone, 1 / (2 pi (1 - cos(a/2))), 1 - cos(x) = 2 sin^2(x/2).
- rectangle and square area lights: uniform in the spherical rectangle they subtend,
  pdf 1 / omega (Urena, Fajardo, King 2013, "An Area-Preserving Parametrization for
  Spherical Rectangles", EGSR), rewritten here in a cancellation-free form (see
  `SphericalRectangle`). Fallback to uniform area sampling, pdf d^2 / (A |cos theta_l|),
  when (rule `_use_solid_angle`):
    omega < SOLID_ANGLE_MIN           (far or edge-on light: area sampling is then as good
                                       and the spherical inversion loses digits),
    |z| < IN_PLANE_REL x (edge sum)   (p almost in the light's plane: omega -> 0 or 2 pi),
    the edges are not perpendicular   (a sheared transform makes a parallelogram).
- disk and ellipse area lights: uniform area sampling (Shirley-Chiu concentric map), as
  Cycles does for ellipses.
- point light with soft_falloff and r > 0: uniform area sampling of the facing disc.
"""
from __future__ import annotations

import numpy as np

from . import visibility
from .light_sample import LightSample, luminance  # noqa: F401 (re-exported)
from .scene import AreaLight, PointLight, SunLight
from .warp import concentric_disk, orthonormal_basis, uniform_sphere
from .world_light import EnvironmentLightModel, world_model

INF = np.inf
TWO_PI = 2.0 * np.pi

# Spherical rectangle sampling is used above this solid angle (steradians) ...
SOLID_ANGLE_MIN = 1e-4
# ... and when the point is farther from the light's plane than this fraction of the
# rectangle's edge sum (closer, the spherical rectangle degenerates to 0 or 2 pi).
IN_PLANE_REL = 1e-7
# An argument of the spherical rectangle's corner product below 0 but above this is
# rounding, a solid angle of 0, not 2 pi: farther than IN_PLANE_REL from the plane,
# 2 pi - omega is still above 1e-6 (SphericalRectangle).
SOLID_ANGLE_WRAP = -1e-9


def _smoothstep01(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def cone_from_one_minus_cos(u, one_minus_cos_max):
    """Uniform directions in the cone about +Z whose half-angle theta_max is given by
    1 - cos(theta_max) (so tiny cones keep full precision); pdf 1 / (2 pi (1 - cos
    theta_max)). Continuous in u: 1 - cos theta = u0 (1 - cos theta_max), phi = 2 pi u1."""
    om = np.asarray(one_minus_cos_max, dtype=np.float64)
    omz = u[..., 0] * om
    sin_t = np.sqrt(np.maximum(0.0, omz * (2.0 - omz)))
    phi = TWO_PI * u[..., 1]
    return np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), 1.0 - omz], axis=-1)


def _safe_unit(v):
    n = np.linalg.norm(v, axis=-1)
    ok = n > 0
    out = np.where(ok[:, None], v / np.where(ok, n, 1.0)[:, None], np.array([0.0, 0.0, 1.0]))
    return out, n


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

    def _spot(self, dir_from_light):
        if not self.is_spot:
            return np.ones(len(dir_from_light))
        c = dir_from_light @ self.axis
        if self.smooth > 0.0:
            return _smoothstep01((c - self.cos_half) / self.smooth)
        return (c > self.cos_half).astype(np.float64)

    def _cone(self, d2):
        """1 - cos(theta_max) of the cone subtended by the sphere, cancellation-free."""
        sin2 = np.minimum(self.radius ** 2 / np.maximum(d2, 1e-300), 1.0)
        return sin2 / (1.0 + np.sqrt(1.0 - sin2))

    def sample(self, p, u, time=None):
        to = self.position - p
        d2 = (to * to).sum(1)
        axis, dist_c = _safe_unit(to)
        n = len(p)
        away = -axis                                     # from the light towards p
        if self.delta:
            ok = d2 > 0
            rad = self.intensity[None, :] / np.where(ok, d2, 1.0)[:, None]
            rad = rad * (self._spot(away) * ok)[:, None]
            return LightSample(axis, dist_c, rad, ok.astype(np.float64), True)
        if self.disc:
            return self._sample_disc(p, u, axis, dist_c, away)
        r = self.radius
        inside = d2 <= r * r
        om = self._cone(d2)
        local = cone_from_one_minus_cos(u, om)
        t, b = orthonormal_basis(axis)
        wi = local[:, :1] * t + local[:, 1:2] * b + local[:, 2:3] * axis
        # Distance to the near side of the sphere along wi: proj - sqrt(r^2 - d^2 sin^2).
        omz = u[:, 0] * om
        sin2 = omz * (2.0 - omz)
        proj = dist_c * local[:, 2]
        dist = proj - np.sqrt(np.maximum(r * r - d2 * sin2, 0.0))
        pdf = 1.0 / (TWO_PI * np.maximum(om, 1e-300))
        if inside.any():                                 # inside the sphere: uniform sphere
            wi_in = uniform_sphere(u[inside])
            wi[inside] = wi_in
            pdf[inside] = 1.0 / (4.0 * np.pi)
            dist[inside] = self._exit_distance(p[inside], wi_in)
        rad = np.broadcast_to(self.sphere_radiance, (n, 3)) * self._spot(away)[:, None]
        return LightSample(wi, np.maximum(dist, 0.0), rad, pdf, False)

    def _sample_disc(self, p, u, axis, dist_c, away):
        """Uniform point on the disc of radius r through the centre, facing p."""
        t, b = orthonormal_basis(axis)
        st = concentric_disk(u) * self.radius
        q = self.position + st[:, :1] * t + st[:, 1:2] * b
        wi, dist = _safe_unit(q - p)
        cos_l = np.abs((wi * axis).sum(1))
        area = np.pi * self.radius ** 2
        ok = (dist > 0) & (cos_l > 0) & (dist_c > 0)
        pdf = np.where(ok, dist * dist / (area * np.where(ok, cos_l, 1.0)), 0.0)
        rad = self.sphere_radiance[None, :] * (self._spot(away) * ok)[:, None]
        return LightSample(wi, dist, rad, pdf, False)

    def _exit_distance(self, p, d):
        oc = p - self.position
        b = (oc * d).sum(1)
        c = (oc * oc).sum(1) - self.radius ** 2
        return -b + np.sqrt(np.maximum(b * b - c, 0.0))

    def intersect(self, o, d, time=None):
        """Distance to the sphere (or facing disc) along each ray (inf if missed) and
        its radiance."""
        n = len(o)
        if self.delta:
            return np.full(n, INF), np.zeros((n, 3))
        axis, dist_c = _safe_unit(self.position - o)
        rad = np.broadcast_to(self.sphere_radiance, (n, 3)) * self._spot(-axis)[:, None]
        if self.disc:
            den = (d * axis).sum(1)
            front = (den > 0) & (dist_c > 0)
            t = np.where(front, dist_c / np.where(front, den, 1.0), INF)
            q = o + d * np.where(front, t, 0.0)[:, None] - self.position
            inside = (q * q).sum(1) <= self.radius ** 2
            return np.where(front & inside, t, INF), rad
        oc = o - self.position
        b = (oc * d).sum(1)
        c = (oc * oc).sum(1) - self.radius ** 2
        disc = b * b - c
        ok = disc >= 0
        sq = np.sqrt(np.maximum(disc, 0.0))
        t0, t1 = -b - sq, -b + sq
        t = np.where(t0 > 0, t0, np.where(t1 > 0, t1, INF))
        return np.where(ok, t, INF), rad

    def pdf(self, p, wi, t, time=None):
        to = self.position - p
        d2 = (to * to).sum(1)
        if self.delta:
            return np.zeros(len(p))
        if self.disc:
            axis, dist_c = _safe_unit(to)
            cos_l = np.abs((wi * axis).sum(1))
            ok = (cos_l > 0) & (dist_c > 0)
            area = np.pi * self.radius ** 2
            return np.where(ok, t * t / (area * np.where(ok, cos_l, 1.0)), 0.0)
        pdf = 1.0 / (TWO_PI * np.maximum(self._cone(d2), 1e-300))
        return np.where(d2 <= self.radius ** 2, 1.0 / (4.0 * np.pi), pdf)


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

    def sample(self, p, u, time=None):
        n = len(p)
        if self.delta:
            wi = np.broadcast_to(self.to_light, (n, 3)).copy()
            rad = np.broadcast_to(self.irradiance, (n, 3)).copy()
            return LightSample(wi, np.full(n, INF), rad, np.ones(n), True)
        local = cone_from_one_minus_cos(u, self.one_minus)
        wi = local[:, :1] * self.t + local[:, 1:2] * self.b + local[:, 2:3] * self.to_light
        pdf = np.full(n, 1.0 / (TWO_PI * self.one_minus))
        rad = np.broadcast_to(self.radiance, (n, 3)).copy()
        return LightSample(wi, np.full(n, INF), rad, pdf, False)

    def _inside(self, d):
        # 1 - cos(angle to the sun's centre) >= 0 compared without cancellation
        diff = d - self.to_light
        return 0.5 * (diff * diff).sum(1) <= self.one_minus

    def escaped(self, d, time=None):
        """Radiance seen along escaping rays d (zero outside the sun's disc)."""
        n = len(d)
        if self.delta:
            return np.zeros((n, 3))
        return np.where(self._inside(d)[:, None], self.radiance[None, :], 0.0)

    def pdf(self, p, wi, t, time=None):
        if self.delta:
            return np.zeros(len(wi))
        return np.where(self._inside(wi), 1.0 / (TWO_PI * self.one_minus), 0.0)


class SphericalRectangle:
    """The spherical rectangle a rectangle subtends from points p (Urena et al. 2013).

    Local frame: x, y along the rectangle's edges (lengths lx, ly) from its corner c,
    z = x cross y; with (x0, y0, z') = (c - p) in that frame, the rectangle is
    [x0, x1] x [y0, y1] at height z' (x1 = x0 + lx, y1 = y0 + ly); z = |z'|.

    Solid angle omega = g0 + g1 + g2 + g3 - 2 pi with the interior angles g_i at the
    corners, here as atan2(|n_i x n_j|, -n_i . n_j) of the edge-plane normals, which
    simplifies to  g = atan2(z |v|, s x y)  at a corner v = (x, y, z) with the sign s
    alternating (+, -, +, -) over (x1, y0), (x1, y1), (x0, y1), (x0, y0): exact even
    when z -> 0 or omega -> 0 (acos of a dot product would lose half the digits). The
    angles are added as arguments of the complex numbers c = s x y + i z |v|: omega is
    the argument of c0 c1 c2 c3 (one atan2, taken in [0, 2 pi); an argument just below 0
    is rounding, a solid angle of 0), and the map's starting angle k = 2 pi - g2 - g3
    enters through its cosine and sine, those of the conjugate of c2 c3.

    Sampling u -> (xu, yv) (the paper's eqs. with cancellation-free rewrites):
      k = 2 pi - g2 - g3,  au = u0 omega + k  (cos and sin of au from those of u0 omega
      and of k),
      N = cos(au) b0 - b1,  D = sin(au),  b0 = -y0 / sqrt(y0^2 + z^2),
      b1 = y1 / sqrt(y1^2 + z^2),  1 - b0^2 = z^2 / (y0^2 + z^2),
      xu = sign(N) z D / sqrt(N^2 - (1 - b0^2) D^2)   [= -cu z0 / sqrt(1 - cu^2) of the
           paper with cu = sign(fu) / sqrt(fu^2 + b0^2), fu = N / D; no division by D]
      dd = sqrt(xu^2 + z^2), h_i = y_i / sqrt(dd^2 + y_i^2), hv = h0 + u1 (h1 - h0),
      yv = hv dd / sqrt((1 - hv)(1 + hv)),  with 1 -+ hv interpolated from 1 -+ h_i, each
      computed without cancellation.
    Both steps are continuous and monotonic in u; the result is uniform in solid angle.
    """

    def __init__(self, p, corner, xh, yh, zh, lx, ly):
        d = corner - p
        self.x0 = d @ xh
        self.y0 = d @ yh
        self.z_signed = d @ zh
        self.z = np.abs(self.z_signed)
        self.x1 = self.x0 + lx
        self.y1 = self.y0 + ly
        self.frame = (xh, yh, zh)                   # unit x, y, z axes of the rectangle
        z2 = self.z * self.z

        def c(x, y, s):                             # the corner's angle, as a complex number
            return s * x * y, self.z * np.sqrt(x * x + y * y + z2)

        def times(a, b):                            # a b, its larger part scaled to 1
            r, i = a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]
            m = np.maximum(np.abs(r), np.abs(i))
            ok = m > 0
            m = np.where(ok, m, 1.0)
            return np.where(ok, r / m, 1.0), np.where(ok, i / m, 0.0)

        g01 = times(c(self.x1, self.y0, 1.0), c(self.x1, self.y1, -1.0))
        g23 = times(c(self.x0, self.y1, 1.0), c(self.x0, self.y0, -1.0))
        sr, si = times(g01, g23)
        omega = np.arctan2(si, sr)
        self.solid_angle = np.where(omega >= 0, omega,
                                    np.where(omega < SOLID_ANGLE_WRAP, omega + TWO_PI, 0.0))
        norm = np.sqrt(g23[0] ** 2 + g23[1] ** 2)
        self.cos_k, self.sin_k = g23[0] / norm, -g23[1] / norm

    def take(self, mask) -> "SphericalRectangle":
        """The same spherical rectangles for the points p[mask] only."""
        out = SphericalRectangle.__new__(SphericalRectangle)
        for name, value in vars(self).items():
            setattr(out, name, value[mask] if isinstance(value, np.ndarray)
                    and value.ndim == 1 else value)
        return out

    def sample(self, u):
        """Offsets (n, 3) from p to uniformly distributed points on the rectangle."""
        x0, x1, y0, y1, z = self.x0, self.x1, self.y0, self.y1, self.z
        z2 = z * z
        r00 = np.sqrt(y0 * y0 + z2)
        r01 = np.sqrt(y1 * y1 + z2)
        b0 = -y0 / np.where(r00 > 0, r00, 1.0)
        b1 = y1 / np.where(r01 > 0, r01, 1.0)
        b0c2 = z2 / np.where(r00 > 0, r00 * r00, 1.0)      # 1 - b0^2
        a = u[:, 0] * self.solid_angle
        cu, su = np.cos(a), np.sin(a)
        num = (cu * self.cos_k - su * self.sin_k) * b0 - b1           # cos(au) b0 - b1
        den = su * self.cos_k + cu * self.sin_k                        # sin(au)
        den2 = num * num - b0c2 * den * den
        ok = den2 > 0
        xu = np.sign(num) * z * den / np.sqrt(np.where(ok, den2, 1.0))
        xu = np.where(ok, xu, np.where(u[:, 0] < 0.5, x0, x1))
        xu = np.clip(xu, x0, x1)
        dd2 = xu * xu + z2

        def one_minus_plus(y):
            r = np.sqrt(dd2 + y * y)
            rs = np.where(r > 0, r, 1.0)
            pos = y >= 0
            small = dd2 / (rs * (rs + np.abs(y)))           # 1 - |h|, exactly
            large = (rs + np.abs(y)) / rs                    # 1 + |h|
            return np.where(pos, small, large), np.where(pos, large, small)

        om0, op0 = one_minus_plus(y0)
        om1, op1 = one_minus_plus(y1)
        v = u[:, 1]
        om = (1.0 - v) * om0 + v * om1                       # 1 - hv
        op = (1.0 - v) * op0 + v * op1                       # 1 + hv
        hv = 0.5 * (op - om)
        prod = om * op
        yv = np.where(prod > 0, hv * np.sqrt(dd2) / np.sqrt(np.where(prod > 0, prod, 1.0)),
                      np.where(hv > 0, y1, y0))
        yv = np.clip(yv, y0, y1)
        xh, yh, zh = self.frame
        return xu[:, None] * xh + yv[:, None] * yh + self.z_signed[:, None] * zh


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

    def power(self, scene_radius):
        return luminance(self.radiance) * np.pi * self.area

    def _spherical(self, p):
        """(SphericalRectangle or None, mask of points that use it): the rule of the
        module docstring, a function of p only."""
        if not self.solid_angle_ok:
            return None, np.zeros(len(p), dtype=bool)
        sr = SphericalRectangle(p, self.corner, self.xh, self.yh, self.zh, self.lx, self.ly)
        use = (sr.solid_angle >= SOLID_ANGLE_MIN) & (sr.z > IN_PLANE_REL * (self.lx + self.ly))
        return sr, use

    def _emitting_side(self, p):
        return (self.center - p) @ self.normal > 0          # p below the light's -Z face

    def sample(self, p, u, time=None):
        sr, use = self._spherical(p)
        if sr is not None and use.all():
            offset = sr.sample(u)
        else:
            st = concentric_disk(u) if self.round else 2.0 * u - 1.0
            offset = self.center - p + st[:, :1] * self.ax + st[:, 1:2] * self.ay
            if use.any():
                offset[use] = sr.take(use).sample(u[use])
        wi, dist = _safe_unit(offset)
        cos_l = wi @ self.normal                      # > 0 when p is on the emitting (-Z) side
        ok = (cos_l > 0) & (dist > 0) & self._emitting_side(p)
        area_pdf = dist * dist / (self.area * np.where(ok, cos_l, 1.0))
        pdf = np.where(use, 1.0 / np.where(use, sr.solid_angle, 1.0) if sr is not None else 0.0,
                       area_pdf)
        pdf = np.where(ok, pdf, 0.0)
        rad = np.where(ok[:, None], self.radiance[None, :], 0.0)
        return LightSample(wi, dist, rad, pdf, False)

    def intersect(self, o, d, time=None):
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

    def pdf(self, p, wi, t, time=None):
        """Solid-angle pdf of sample(p, .) producing wi, the light being hit at distance
        t (assumed: the caller found the hit with intersect)."""
        cos_l = np.abs(wi @ self.normal)
        ok = (cos_l > 0) & np.isfinite(t)
        out = np.where(ok, t * t / (self.area * np.where(ok, cos_l, 1.0)), 0.0)
        sr, use = self._spherical(p)
        if sr is not None:
            out = np.where(use & ok, 1.0 / np.where(use, sr.solid_angle, 1.0), out)
        return out


class TimeSlicedLight:
    """A lamp that moves during the shutter: the exporter gives the lamp at the middles of
    K equal slices of the shutter (`light.motion_slices`), and each ray uses the lamp of
    the slice its time falls in. Like time-sliced deformation (engine.motion) this is
    exact at the slice middles and off by up to half a slice's movement elsewhere, and
    it costs nothing for lamps that do not move."""

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

    def _groups(self, n, time):
        if time is None:                      # no time: the middle of the shutter
            yield self.slices[self.k // 2], slice(None)
            return
        sl = np.clip((np.asarray(time) * self.k).astype(np.int64), 0, self.k - 1)
        for j in np.unique(sl):
            yield self.slices[j], np.nonzero(sl == j)[0]

    def sample(self, p, u, time=None):
        n = len(p)
        out = LightSample(np.zeros((n, 3)), np.zeros(n), np.zeros((n, 3)), np.zeros(n),
                          self.delta, np.zeros(n))
        for model, rows in self._groups(n, time):
            s = model.sample(p[rows], u[rows])
            out.wi[rows], out.dist[rows], out.radiance[rows], out.pdf[rows] = \
                s.wi, s.dist, s.radiance, s.pdf
            if s.margin is not None:
                out.margin[rows] = s.margin
        return out

    def intersect(self, o, d, time=None):
        n = len(o)
        t, rad = np.full(n, INF), np.zeros((n, 3))
        for model, rows in self._groups(n, time):
            tt, rr = model.intersect(o[rows], d[rows])
            t[rows] = tt
            if rr is not None:
                rad[rows] = rr
        return t, rad

    def pdf(self, p, wi, t, time=None):
        out = np.zeros(len(wi))
        for model, rows in self._groups(len(wi), time):
            out[rows] = model.pdf(None if p is None else p[rows], wi[rows],
                                  None if t is None else t[rows])
        return out

    def escaped(self, d, time=None):
        out = np.zeros((len(d), 3))
        for model, rows in self._groups(len(d), time):
            out[rows] = model.escaped(d[rows])
        return out


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


class LightSet:
    """All lights of a scene: the lamps (`models`) followed by the emissive triangles
    (`mesh`, an engine.mesh_lights.EmissiveTriangles, may be None), as one list of
    entries. Next-event estimation picks one entry per shading point with probability
    proportional to its estimated power (luminance of radiance x pi x area for area
    lights and triangles, of strength for points, of irradiance x pi R^2 for suns):
    `select_pdf`, over len(self) entries; entry k >= n_lamps is triangle k - n_lamps."""

    def __init__(self, lights, scene_radius: float, mesh_lights=None, world=None):
        self.models = [make_light(l) for l in lights]
        # the world: a model (engine.world_light), a World or an RGB triple; kept even
        # when it is too dark to be a light, for what escaped rays see
        self.world = None if world is None else (
            world if getattr(world, "is_environment", False) else world_model(world))
        # The world is sampled as a light unless it is an environment whose Sampling
        # Method is None. Cycles never samples a uniform world (its LightManager disables
        # a background light that does not vary in space; BSDF rays that escape find
        # it); DRT does, for less noise, and evaluates refraction towards it on Walter's
        # pairs only (`uniform_world`; engine/bsdf/dielectric.py's note), which is what
        # Cycles' escaping rays see.
        if self.world is not None and getattr(self.world, "light_sampling", True):
            self.models.append(self.world)
        power = np.array([max(m.power(scene_radius), 0.0) for m in self.models], dtype=np.float64)
        power = np.where(np.isfinite(power), power, 0.0)
        keep = power > 0
        self.models = [m for m, k in zip(self.models, keep) if k]
        self.n_lamps = len(self.models)
        env = [k for k, m in enumerate(self.models) if getattr(m, "is_environment", False)]
        self.env_index = env[0] if env else None
        self.mesh = mesh_lights if mesh_lights is not None and len(mesh_lights) else None
        mesh_power = self.mesh.power if self.mesh is not None else np.zeros(0)
        power = np.concatenate([power[keep], mesh_power])
        total = power.sum()
        self.select_pdf = power / total if total > 0 else power
        self.cdf = np.cumsum(self.select_pdf)
        if len(self.cdf):
            self.cdf[-1] = 1.0

    def __len__(self):
        return len(self.select_pdf)

    def uniform_world(self, entries) -> np.ndarray:
        """Whether each sampled entry is the uniform world (bool array)."""
        k = self.env_index
        if k is None or not isinstance(self.models[k], EnvironmentLightModel):
            return np.zeros(len(entries), bool)
        return np.asarray(entries) == k

    def sample(self, p, u_pick, u_point, time=None):
        """Pick one light per point and sample it (time: the points' shutter times, for
        moving lamps). Returns (LightSample with pdf including the pick probability,
        entry index, delta mask)."""
        n = len(p)
        idx = np.searchsorted(self.cdf, u_pick, side="right").clip(0, len(self) - 1)
        wi = np.zeros((n, 3))
        wi[:, 2] = 1.0
        dist = np.zeros(n)
        margin = np.zeros(n)
        rad = np.zeros((n, 3))
        pdf = np.zeros(n)
        delta = np.zeros(n, dtype=bool)
        for k, model in enumerate(self.models):
            sel = np.nonzero(idx == k)[0]
            if sel.size == 0:
                continue
            s = model.sample(p[sel], u_point[sel], None if time is None else time[sel])
            wi[sel], dist[sel], rad[sel] = s.wi, s.dist, s.radiance
            pdf[sel] = s.pdf * self.select_pdf[k]
            delta[sel] = s.delta
        if self.mesh is not None:
            sel = np.nonzero(idx >= self.n_lamps)[0]
            if sel.size:
                s = self.mesh.sample(p[sel], idx[sel] - self.n_lamps, u_point[sel])
                wi[sel], dist[sel], rad[sel] = s.wi, s.dist, s.radiance
                pdf[sel] = s.pdf * self.select_pdf[idx[sel]]
                margin[sel] = s.margin
        return LightSample(wi, dist, rad, pdf, False, margin), idx, delta

    def hit_surfaces(self, o, d, tmax, time=None):
        """The nearest area or sphere lamp along each ray before tmax:
        (t, lamp index or -1, radiance). Emissive triangles are scene geometry: the
        integrator finds them with the ordinary ray cast."""
        n = len(o)
        best_t = np.asarray(tmax, dtype=np.float64).copy()
        best_i = np.full(n, -1, dtype=np.int64)
        rad = np.zeros((n, 3))
        for k, model in enumerate(self.models):
            if not model.visible or isinstance(model, SunLightModel) \
                    or getattr(model, "is_sun", False):
                continue
            t, r = model.intersect(o, d, time)
            closer = t < best_t
            if closer.any():
                best_t[closer] = t[closer]
                best_i[closer] = k
                rad[closer] = r[closer]
        return best_t, best_i, rad

    def pdf(self, k_index, p, wi, t, time=None):
        """Solid-angle pdf, pick probability included, of sampling direction wi from p
        towards lamp k_index[i] (hit at distance t)."""
        out = np.zeros(len(p))
        for k, model in enumerate(self.models):
            sel = np.nonzero(k_index == k)[0]
            if sel.size:
                out[sel] = model.pdf(p[sel], wi[sel], t[sel],
                                     None if time is None else time[sel]) * self.select_pdf[k]
        return out

    def mesh_pdf(self, prim, p, q):
        """Solid-angle pdf, pick probability included, with which next-event estimation
        from points p samples the points q on global triangles `prim` (0 for triangles
        that are not lights)."""
        if self.mesh is None:
            return np.zeros(len(p))
        entry = self.mesh.entry_of(prim)
        is_light = entry >= 0
        sel = np.maximum(entry, 0)
        pdf = self.mesh.pdf_area_to_solid_angle(sel, p, q)
        return np.where(is_light, pdf * self.select_pdf[self.n_lamps + sel], 0.0)

    def environment_pdf(self, d):
        """Pick probability x solid-angle pdf of the world light for escaped rays along
        d (n, 3) (zeros when the world is not a light)."""
        if self.env_index is None:
            return np.zeros(len(d))
        return self.models[self.env_index].pdf(None, d, None) * self.select_pdf[self.env_index]

    def suns(self):
        return [(k, m) for k, m in enumerate(self.models)
                if (isinstance(m, SunLightModel) or getattr(m, "is_sun", False))
                and not m.delta]
