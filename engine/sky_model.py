"""The physical sky of Blender's Sky Texture node (Multiple Scattering, Blender 5.0's
default): the atmosphere model Cycles precomputes into its sky table, as compiled
scalar kernels (engine.kernels.jit: the table's 65536 rays x 64 steps take 1-3 s;
NumPy arrays took 6-12 s, same values to 3e-14).

The model (Fernando Garcia Linan's spectral sky, Blender's intern/sky, restated from
its formulas): a spherical Earth of radius 6371 km under a 100 km atmosphere of
molecules (Rayleigh scattering, height profile exp(-0.0777 h^1.1636)), ozone (absorption
only, a log-normal profile in height) and aerosols (exponential, scale height 0.73 km,
plus a constant background; Henyey-Greenstein-like phase with g = 0.8), each scaled by
the node's Air, Aerosol and Ozone densities. Light is tracked at four wavelengths
(630, 560, 490, 430 nm) and turned into CIE XYZ by a fixed 4 x 3 matrix.

- `_transmittance(cos_zenith, normalized_altitude)`: exp(-optical depth) from a point to
  the top of the atmosphere along a direction (64 mid-point steps; the Earth is not an
  occluder here, as in Blender);
- a 256 x 64 transmittance table over (cos zenith in [-1, 1], altitude in [0, 100] km),
  read bilinearly with clamped indices;
- `_inscattering`: single scattering of sunlight along the view ray (64 steps, each
  step integrated analytically against its own extinction, Hillaire 2016) plus an
  analytic multiple-scattering term: a fitted isotropic ambient
  0.02 (0.217, 0.347, 0.594, 1) / (1 + 5 exp(-17.92 cos)) and second-order light from
  a grey ground of albedo 0.3 (isotropic phase), both at the sample's sun cosine;
- `sky_table(...)`: Cycles' 512 x 256 sky image: texel (x, y) centred at
  u = (x + 0.5) / W, v = (y + 0.5) / H looks along azimuth 2 pi u and elevation
  sign(l) l^2 pi / 2 (l = 2 v - 1: more rows near the horizon) from
  altitude clamp(altitude, 1 m, 99999 m) with the sun at azimuth pi; rays that hit the
  ground stop there. The image is symmetric about the sun's azimuth (x and W - 1 - x);
- `sun_pixels(...)`: the sun disc's radiance at its lowest and highest point,
  sun irradiance x transmittance / the disc's solid angle 2 pi (1 - cos(size / 2)).

Everything is in XYZ (Cycles converts to scene-linear RGB after the lookup).
"""
from __future__ import annotations

import math

import numpy as np

from .kernels.jit import kernel

EARTH_RADIUS = 6371.0               # km
ATMOSPHERE_THICKNESS = 100.0        # km
ATMOSPHERE_RADIUS = EARTH_RADIUS + ATMOSPHERE_THICKNESS
TRANSMITTANCE_STEPS = 64
INSCATTERING_STEPS = 64
LUT_WIDTH, LUT_HEIGHT = 256, 64
TABLE_WIDTH, TABLE_HEIGHT = 512, 256

GROUND_ALBEDO = 0.3
AEROSOL_G = 0.8
SUN_SPECTRAL_IRRADIANCE = np.array([1.679, 1.828, 1.986, 1.307])
MOLECULAR_SCATTERING = np.array([6.605e-3, 1.067e-2, 1.842e-2, 3.156e-2])
OZONE_CROSS_SECTION = np.array([3.472e-25, 3.914e-25, 1.349e-25, 11.03e-27])
OZONE_MEAN_DOBSON = 334.5
AEROSOL_ABSORPTION = np.array([2.8722e-24, 4.6168e-24, 7.9706e-24, 1.3578e-23])
AEROSOL_SCATTERING = np.array([1.5908e-22, 1.7711e-22, 2.0942e-22, 2.4033e-22])
AEROSOL_BASE_DENSITY = 1.3681e20
AEROSOL_BACKGROUND_DENSITY = 2e6
AEROSOL_HEIGHT_SCALE = 0.73
MULTIPLE_SCATTERING_TINT = 0.02 * np.array([0.217, 0.347, 0.594, 1.0])
# rows: the four wavelengths; columns: X, Y, Z
SPECTRAL_TO_XYZ = np.array([
    [53.386917738564668023, 22.981337506691024754, 0.0],
    [43.904844466369358263, 71.347795700053393866, 0.102506867965741307],
    [1.6137278251608962005, 18.422960591455485011, 31.742921188390805758],
    [20.762668673810577145, 2.3614213523314368527, 110.48009643252140334]])


@kernel
def _coefficients(h, air, aerosol, ozone, out):
    """out[0:4] molecular scattering, out[4:8] aerosol scattering, out[8:12] extinction
    at height h km."""
    density = AEROSOL_BASE_DENSITY * (math.exp(-h / AEROSOL_HEIGHT_SCALE)
                                      + AEROSOL_BACKGROUND_DENSITY
                                      / AEROSOL_BASE_DENSITY) * aerosol
    log_h = math.log(max(h, 1e-4))
    ozone_density = 3.78547397e20 * math.exp(-(log_h - 3.22261) ** 2 * 5.55555555 - log_h)
    air_profile = math.exp(-0.07771971 * h ** 1.16364243) * air
    for k in range(4):
        molecular = MOLECULAR_SCATTERING[k] * air_profile
        scattering = AEROSOL_SCATTERING[k] * density
        out[k] = molecular
        out[4 + k] = scattering
        out[8 + k] = (AEROSOL_ABSORPTION[k] * density + scattering + molecular
                      + OZONE_CROSS_SECTION[k] * OZONE_MEAN_DOBSON * ozone_density * ozone)


@kernel
def ray_sphere(ox, oy, oz, dx, dy, dz, radius):
    """Distance along unit d from o to the sphere of `radius` about the Earth's centre:
    the far hit from inside, the near one from outside, -1 when missed (or when the
    sphere lies behind an outside origin)."""
    b = ox * dx + oy * dy + oz * dz
    c = ox * ox + oy * oy + oz * oz - radius * radius
    if c > 0.0 and b > 0.0:
        return -1.0
    d = b * b - c
    if d < 0.0:
        return -1.0
    if d >= b * b:
        return -b + math.sqrt(d)
    return -b - math.sqrt(d)


@kernel
def _transmittance(cos_zenith, normalized_altitude, air, aerosol, ozone, out):
    """out[0:4]: transmittance to the top of the atmosphere, marched directly."""
    r = EARTH_RADIUS + (ATMOSPHERE_RADIUS - EARTH_RADIUS) * normalized_altitude
    sx = -math.sqrt(max(1.0 - cos_zenith * cos_zenith, 0.0))
    dt = ray_sphere(0.0, 0.0, r, sx, 0.0, cos_zenith, ATMOSPHERE_RADIUS) \
        / TRANSMITTANCE_STEPS
    coef = np.empty(12)
    depth = np.zeros(4)
    for step in range(TRANSMITTANCE_STEPS):
        t = (step + 0.5) * dt
        x, z = sx * t, r + cos_zenith * t
        h = max(math.sqrt(x * x + z * z) - EARTH_RADIUS, 0.0)
        _coefficients(h, air, aerosol, ozone, coef)
        for k in range(4):
            depth[k] += coef[8 + k] * dt
    for k in range(4):
        out[k] = math.exp(-depth[k])


@kernel
def _transmittance_table(air, aerosol, ozone):
    """(64, 256, 4): rows altitude 0..100 km, columns cos zenith -1..1."""
    lut = np.empty((LUT_HEIGHT, LUT_WIDTH, 4))
    for y in range(LUT_HEIGHT):
        for x in range(LUT_WIDTH):
            _transmittance(2.0 * x / (LUT_WIDTH - 1) - 1.0, y / (LUT_HEIGHT - 1), air,
                           aerosol, ozone, lut[y, x])
    return lut


@kernel
def _lookup(lut, cos_zenith, normalized_altitude, k):
    """Channel k of the table read bilinearly (clamped) at (cos, altitude)."""
    x = (LUT_WIDTH - 1) * min(max(cos_zenith * 0.5 + 0.5, 0.0), 1.0)
    y = (LUT_HEIGHT - 1) * min(max(normalized_altitude, 0.0), 1.0)
    x1, y1 = int(x), int(y)
    x2, y2 = min(x1 + 1, LUT_WIDTH - 1), min(y1 + 1, LUT_HEIGHT - 1)
    fx, fy = x - x1, y - y1
    bottom = lut[y1, x1, k] + fx * (lut[y1, x2, k] - lut[y1, x1, k])
    top = lut[y2, x1, k] + fx * (lut[y2, x2, k] - lut[y2, x1, k])
    return bottom + fy * (top - bottom)


@kernel
def _inscattering(lut, sun_x, sun_z, ox, oy, oz, dx, dy, dz, length, air, aerosol,
                  ozone, out):
    """out[0:4]: radiance scattered towards o along unit d over `length` km, the sun
    along (sun_x, 0, sun_z) (see the module doc)."""
    c = -(dx * sun_x + dz * sun_z)
    phase_m = 3.0 / (16.0 * math.pi) * (1.0 + c * c)
    den = 1.0 + AEROSOL_G * AEROSOL_G + 2.0 * AEROSOL_G * c
    phase_a = (1.0 - AEROSOL_G * AEROSOL_G) / (4.0 * math.pi * den * math.sqrt(den))
    dt = length / INSCATTERING_STEPS
    coef = np.empty(12)
    through = np.ones(4)
    for k in range(4):
        out[k] = 0.0
    for i in range(INSCATTERING_STEPS):
        t = (i + 0.5) * dt
        x, y, z = ox + dx * t, oy + dy * t, oz + dz * t
        dist = math.sqrt(x * x + y * y + z * z)
        h = max(dist - EARTH_RADIUS, 0.0)
        alt = h / ATMOSPHERE_THICKNESS
        cos_sun = (x * sun_x + z * sun_z) / dist
        _coefficients(h, air, aerosol, ozone, coef)
        ratio = min(EARTH_RADIUS / dist, 1.0)
        omega = 2.0 * math.pi * (1.0 - math.sqrt(1.0 - ratio * ratio))
        ground_w = omega / (4.0 * math.pi) * GROUND_ALBEDO / math.pi * cos_sun
        fit = 1.0 / (1.0 + 5.0 * math.exp(-17.92 * cos_sun))
        for k in range(4):
            to_sun = _lookup(lut, cos_sun, alt, k)
            # second-order light from the ground, and the fitted multiple scattering
            ground = (ground_w * _lookup(lut, cos_sun, 0.0, k) * _lookup(lut, 1.0, 0.0, k)
                      / _lookup(lut, 1.0, alt, k))
            ms = MULTIPLE_SCATTERING_TINT[k] * fit + ground
            source = SUN_SPECTRAL_IRRADIANCE[k] * (coef[k] * (phase_m * to_sun + ms)
                                                   + coef[4 + k] * (phase_a * to_sun + ms))
            ext = coef[8 + k]
            step = math.exp(-dt * ext)
            out[k] += through[k] * (source - source * step) / max(ext, 1e-7)
            through[k] *= step


@kernel
def _sky_half(lut, width, height, sun_x, sun_z, oz, air, aerosol, ozone):
    """XYZ (height, width // 2, 3) of the table's half towards azimuth < pi."""
    half = width // 2
    out = np.empty((height, half, 3))
    spectrum = np.empty(4)
    for row in range(height):
        l = 2.0 * (row + 0.5) / height - 1.0
        elev = math.copysign(l * l, l) * (math.pi / 2)
        for col in range(half):
            az = 2.0 * math.pi * (col + 0.5) / width
            dx, dy = math.cos(elev) * math.cos(az), math.cos(elev) * math.sin(az)
            dz = math.sin(elev)
            ground = ray_sphere(0.0, 0.0, oz, dx, dy, dz, EARTH_RADIUS)
            length = ground if ground >= 0.0 else ray_sphere(0.0, 0.0, oz, dx, dy, dz,
                                                              ATMOSPHERE_RADIUS)
            _inscattering(lut, sun_x, sun_z, 0.0, 0.0, oz, dx, dy, dz, length, air,
                          aerosol, ozone, spectrum)
            for j in range(3):
                v = 0.0
                for k in range(4):
                    v += spectrum[k] * SPECTRAL_TO_XYZ[k, j]
                out[row, col, j] = v
    return out


def _altitude_km(altitude):
    return min(max(float(altitude), 1.0), 99999.0) / 1000.0


def _sun(elevation):
    """The sun's (x, z) in the table's frame (azimuth pi: -X), as Blender builds it
    from cos(zenith)."""
    c = math.cos(math.pi / 2 - float(elevation))
    return -math.sqrt(max(1.0 - c * c, 0.0)), c


def sky_table(sun_elevation, altitude=100.0, air=1.0, aerosol=1.0, ozone=1.0,
              width=TABLE_WIDTH, height=TABLE_HEIGHT):
    """Cycles' sky image (height, width, 3) in XYZ, row 0 at the bottom (v = 0)."""
    air, aerosol, ozone = float(air), float(aerosol), float(ozone)
    lut = _transmittance_table(air, aerosol, ozone)
    sun_x, sun_z = _sun(sun_elevation)
    xyz = _sky_half(lut, int(width), int(height), sun_x, sun_z,
                    EARTH_RADIUS + _altitude_km(altitude), air, aerosol, ozone)
    half = width // 2
    table = np.empty((height, width, 3))
    table[:, :half] = xyz
    table[:, width - half:] = xyz[:, ::-1]
    return table


def sun_pixels(sun_elevation, sun_size, altitude=100.0, air=1.0, aerosol=1.0, ozone=1.0):
    """The sun disc's XYZ radiance at its lowest and at its highest point."""
    half = 0.5 * float(sun_size)
    solid_angle = 2.0 * math.pi * (1.0 - math.cos(half))
    alt = _altitude_km(altitude) / ATMOSPHERE_THICKNESS
    pixels = []
    for elevation in (float(sun_elevation) - half, float(sun_elevation) + half):
        t = np.empty(4)
        _transmittance(_sun(elevation)[1], alt, float(air), float(aerosol), float(ozone), t)
        pixels.append((SUN_SPECTRAL_IRRADIANCE * t / solid_angle) @ SPECTRAL_TO_XYZ)
    return pixels[0], pixels[1]


def earth_intersection_angle(altitude):
    """How far below the horizon the ground's edge lies, seen from `altitude` metres."""
    return np.pi / 2 - np.arcsin(EARTH_RADIUS / (EARTH_RADIUS + float(altitude) / 1000.0))
