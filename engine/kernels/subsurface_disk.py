"""Christensen-Burley subsurface scattering, found by disk sampling as Cycles finds it
(closure/bssrdf.h, integrator/subsurface_disk.h; King, Kulla, Conty and Fajardo 2013,
"BSSRDF Importance Sampling"; the profile: Christensen and Burley 2015, "Approximate
Reflectance Profiles for Efficient Subsurface Scattering").

No walk and no entry refraction: light that enters at p leaves at a point of the same
object at distance r from p, with the radial density per colour channel

    R_d(r) = (exp(-r / d) + exp(-r / (3 d))) / (4 d)      (integrates to 1 over r >= 0)

truncated at r = 16 d (TRUNCATE, of which the CDF is TRUNCATE_CDF) and renormalised, d
the channel's Radius x Scale over 4 pi (Cycles' scale to the mean free path). The exit
is sampled by Cycles' disk: an axis (the surface's geometric normal with probability
1/2, either tangent with 1/4), a channel (uniformly among those with a radius), a
radius r_disk on the disk about that axis from the channel's profile, and a probe
ray across the sphere of radius 16 d along the axis, which meets the object's surface
at every exit candidate. Each candidate weighs R_d(r) / pdf(r_disk) (the channels'
average density) by the power heuristic over the three axes; one candidate is kept by
resampling in proportion to its weight's channel average. Cycles resamples among at
most four candidates drawn at random; here every candidate is in the reservoir: the
same expectation, no more variance.

On a plane the expected weight is exactly 1 per channel (tests/test_subsurface_disk.py):
the lobe's weight (base colour x Subsurface Weight under the layers above it) is the
surface's whole subsurface reflectance, as Cycles' albedo is.
"""
from __future__ import annotations

import math

from ..embree.rays import new_ray_record
from ..sampling.hashing import stream_uniform
from .frame import basis, dot
from .bsdf.subsurface_lobe import MIN_RADIUS     # Cycles' BSSRDF_MIN_RADIUS
from .jit import kernel
from .subsurface import local_hit
from .surface import rebuild_at_time

TRUNCATE = 16.0                       # Cycles' BURLEY_TRUNCATE, in units of d
TRUNCATE_CDF = 0.9963790093708328     # the profile's CDF there
MAX_CANDIDATES = 64                   # surfaces of the object one probe ray may cross
PICK = 8                              # the walk stream's first number for the resampling


@kernel(allocates=False)
def profile_radius(radius):
    """d of one channel: Radius x Scale over 4 pi (0 below MIN_RADIUS: no profile)."""
    return radius * 0.25 / math.pi if radius >= MIN_RADIUS else 0.0


@kernel(allocates=False)
def scaled_root(xi):
    """r / d at which the untruncated profile's CDF, 1 - exp(-r/d) / 4 - 3 exp(-r/3d) / 4,
    is xi: Newton's method from Cycles' fitted first guess."""
    r = math.exp(xi * xi * 2.4) - 1.0 if xi <= 0.9 else 15.0
    for _ in range(10):
        e3 = math.exp(-r / 3.0)
        e1 = e3 * e3 * e3
        f = 1.0 - 0.25 * e1 - 0.75 * e3 - xi
        df = 0.25 * e1 + 0.25 * e3
        if abs(f) < 1e-6 or df == 0.0:
            break
        r = max(r - f / df, 0.0)
    return r


@kernel(allocates=False)
def sample_radius(d, xi):
    """(r, h): a radius from channel d's truncated profile for uniform xi, and the half
    chord of the truncation sphere there (h^2 + r^2 = (16 d)^2)."""
    rm = TRUNCATE * d
    r = scaled_root(xi * TRUNCATE_CDF) * d
    return r, math.sqrt(max(rm * rm - r * r, 0.0))


@kernel(allocates=False)
def density(d, r):
    """The truncated profile's density over r of channel d (0 at r = 0, beyond 16 d, and
    where the channel has no radius)."""
    if r == 0.0 or not r < TRUNCATE * d:
        return 0.0
    e3 = math.exp(-r / (3.0 * d))
    return (e3 * e3 * e3 + e3) / (4.0 * d) / TRUNCATE_CDF


@kernel(allocates=False)
def disk_pdf(d0, d1, d2, r):
    """The density of r over the channels the disk picks among (those with a radius)."""
    n = (d0 > 0.0) + (d1 > 0.0) + (d2 > 0.0)
    if n == 0:
        return 0.0
    return (density(d0, r) + density(d1, r) + density(d2, r)) / n


@kernel(allocates=False)
def _pick_channel(d0, d1, d2, xi):
    """The channel xi picks uniformly among those with a radius, and xi reused."""
    n = (d0 > 0.0) + (d1 > 0.0) + (d2 > 0.0)
    xi = xi * n
    seen = 0
    for c in range(3):
        d = d0 if c == 0 else (d1 if c == 1 else d2)
        if d > 0.0:
            if xi < seen + 1 or seen + 1 == n:
                return d, min(xi - seen, 0.99999994)
            seen += 1
    return 0.0, xi


@kernel(allocates=False)
def _axis(u):
    """The probe's axis, 0 (the geometric normal g) with probability 1/2, 1 or 2 (the
    tangents t, b) with 1/4 each (Cycles' disk_N), and u reused."""
    if u < 0.5:
        return 0, 2.0 * u
    if u < 0.75:
        return 1, 4.0 * (u - 0.5)
    return 2, 4.0 * (u - 0.75)


@kernel(allocates=False)
def find_exit(rays, rec, geometry, key, time, mesh, inst, front, px, py, pz, gx, gy, gz,
              radius, u1, u2):
    """The exit of light entering mesh `mesh` (placed as inst, -1: not instanced) at p,
    its geometric normal there g facing the ray that arrived (front: from the surface's
    outside), radius: Radius x Scale per channel. u1, u2: the disk's numbers; the
    resampling draws from stream `key` (the walk's). Returns (left, prim, inst, u, v,
    nx, ny, nz, weight r, g, b): the exit hit, the normal the exit is seen along (its
    geometric normal on the side the entry was seen from) and the weight to multiply
    the path's throughput by."""
    d0, d1, d2 = profile_radius(radius[0]), profile_radius(radius[1]), \
        profile_radius(radius[2])
    if not max(d0, max(d1, d2)) > 0.0:
        return False, -1, -1, 0.0, 0.0, gx, gy, gz, 0.0, 0.0, 0.0
    tx, ty, tz, bx, by, bz = basis(gx, gy, gz)
    axis, v = _axis(u2)
    if axis == 0:        # the probe's axis a and the disk's plane (s, c)
        ax, ay, az, sx, sy, sz, cx, cy, cz = gx, gy, gz, tx, ty, tz, bx, by, bz
    elif axis == 1:
        ax, ay, az, sx, sy, sz, cx, cy, cz = tx, ty, tz, gx, gy, gz, bx, by, bz
    else:
        ax, ay, az, sx, sy, sz, cx, cy, cz = bx, by, bz, tx, ty, tz, gx, gy, gz
    d, xi = _pick_channel(d0, d1, d2, u1)
    r_disk, h = sample_radius(d, xi)
    phi = 2.0 * math.pi * v
    ex, ey = r_disk * math.cos(phi), r_disk * math.sin(phi)
    ox = px + ax * h + ex * sx + ey * cx
    oy = py + ay * h + ex * sy + ey * cy
    oz = pz + az * h + ex * sz + ey * cz
    pdf_disk = disk_pdf(d0, d1, d2, r_disk)
    if not pdf_disk > 0.0:
        return False, -1, -1, 0.0, 0.0, gx, gy, gz, 0.0, 0.0, 0.0
    side = 1.0 if front else -1.0
    total = 0.0
    keep = (False, -1, -1, 0.0, 0.0, gx, gy, gz, 0.0, 0.0, 0.0)
    keep_w = 0.0
    tnear, skip = 0.0, -1
    for j in range(MAX_CANDIDATES):
        prim, placed, t, hu, hv = local_hit(rays, rec, mesh, inst, ox, oy, oz, -ax, -ay,
                                            -az, 2.0 * h, time, skip, tnear)
        if prim < 0:
            break
        # on past it (the triangle across an edge the probe meets is the same point)
        tnear, skip = t + max(t * 1e-6, 1e-30), prim
        # the candidate's geometric normal, as the surface's outside is seen from the
        # entry's side
        _, _, _, fx, fy, fz, _, _, _, hit_front, _ = rebuild_at_time(
            geometry, prim, placed, hu, hv, -ax, -ay, -az, time)
        s = side if hit_front else -side
        nx, ny, nz = fx * s, fy * s, fz * s
        # the densities of reaching it along each axis (up to the disk's own, common)
        pg = 0.5 * abs(dot(gx, gy, gz, nx, ny, nz))
        pt = 0.25 * abs(dot(tx, ty, tz, nx, ny, nz))
        pb = 0.25 * abs(dot(bx, by, bz, nx, ny, nz))
        pa = pg if axis == 0 else (pt if axis == 1 else pb)
        denom = pg * pg + pt * pt + pb * pb
        if not denom > 0.0:
            continue
        mis = pa / denom                  # the power heuristic over 1 / its own density
        qx, qy, qz = ox - ax * t, oy - ay * t, oz - az * t
        r = math.sqrt((qx - px) ** 2 + (qy - py) ** 2 + (qz - pz) ** 2)
        w0 = density(d0, r) / pdf_disk * mis
        w1 = density(d1, r) / pdf_disk * mis
        w2 = density(d2, r) / pdf_disk * mis
        w = (w0 + w1 + w2) / 3.0
        if not w > 0.0:
            continue
        total += w
        if stream_uniform(key, 0, PICK + j) * total < w:
            keep = (True, prim, placed, hu, hv, nx, ny, nz, w0, w1, w2)
            keep_w = w
    if not keep_w > 0.0:
        return False, -1, -1, 0.0, 0.0, gx, gy, gz, 0.0, 0.0, 0.0
    f = total / keep_w
    left, prim, placed, hu, hv, nx, ny, nz, w0, w1, w2 = keep
    return left, prim, placed, hu, hv, nx, ny, nz, w0 * f, w1 * f, w2 * f


@kernel
def exit_batch(rays, geometry, keys, mesh, front, start, normal, radius, uv, out):
    """`find_exit` at one entry point once per key (numbers uv[i]), for tests: out (n, 8)
    gets (left, weight r, g, b, exit triangle, the exit's normal) per sample."""
    rec = new_ray_record(rays[0])
    for i in range(keys.shape[0]):
        left, prim, _, _, _, nx, ny, nz, w0, w1, w2 = find_exit(
            rays, rec, geometry, keys[i], 0.0, mesh, -1, front, start[0], start[1],
            start[2], normal[0], normal[1], normal[2], (radius[0], radius[1], radius[2]),
            uv[i, 0], uv[i, 1])
        out[i, 0] = 1.0 if left else 0.0
        out[i, 1], out[i, 2], out[i, 3] = w0, w1, w2
        out[i, 4] = prim
        out[i, 5], out[i, 6], out[i, 7] = nx, ny, nz
