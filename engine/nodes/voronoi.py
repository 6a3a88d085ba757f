"""Blender's Voronoi texture (Cycles' svm/voronoi.h) in 1 to 4 dimensions.

Space is cut into unit cells; each cell holds one point, jittered from the cell's
corner by Randomness times a hash of the cell's integer coordinates (hash.py: the float
hash in 1D, PCG on the integers in 2D-4D, as Blender 5), and has a colour hashed the
same way. Features (FEATURES): the distance to the closest point
(F1), the second closest (F2), a smooth blend of the distances to the points of the
5^n neighbourhood (Smooth F1), the distance to the closest cell edge, and the radius of
the largest sphere around the closest point that touches no other (N-Sphere Radius).
Distance metrics (METRICS): Euclidean, Manhattan, Chebychev, Minkowski (Exponent);
1D always measures |a - b|. F1, F2 and Smooth F1 and the edge distance are fractal
(Detail, Roughness, Lacunarity, as Noise's fBM, summed with lerps), and Normalize
divides by the largest possible distance.

A point is (dim, x, y, z, w): its first `dim` coordinates are used (a 1D point is x).
Loops run over every dimension with the unused ones' range empty, so one routine serves
every dimension, in Cycles' order (x fastest), which Smooth F1's blend depends on.
"""
from __future__ import annotations

import math

from ..kernels.jit import kernel
from .hash import hash_float1_to_float3, hash_float_to_float, hash_int2_to_float2, \
    hash_int3_to_float3, hash_int4_to_float4

FEATURES = ("F1", "F2", "SMOOTH_F1", "DISTANCE_TO_EDGE", "N_SPHERE_RADIUS")
F1, F2, SMOOTH_F1, DISTANCE_TO_EDGE, N_SPHERE_RADIUS = range(5)
METRICS = ("EUCLIDEAN", "MANHATTAN", "CHEBYCHEV", "MINKOWSKI")
EUCLIDEAN, MANHATTAN, CHEBYCHEV, MINKOWSKI = range(4)
FLT_MAX = 3.4028234663852886e38


@kernel(allocates=False)
def cell_point(dim, x, y, z, w):
    """The jitter in [0, 1]^dim of the cell at integer coordinates (x, y, z, w) (floats):
    1D hashes the float cell, 2D-4D their integers (PCG)."""
    if dim == 1:
        return hash_float_to_float(x), 0.0, 0.0, 0.0
    if dim == 2:
        a, b = hash_int2_to_float2(int(x), int(y))
        return a, b, 0.0, 0.0
    if dim == 3:
        a, b, c = hash_int3_to_float3(int(x), int(y), int(z))
        return a, b, c, 0.0
    return hash_int4_to_float4(int(x), int(y), int(z), int(w))


@kernel(allocates=False)
def neighbour_point(dim, randomness, cx, cy, cz, cw, i, j, k, u):
    """The point of the cell at offset (i, j, k, u) from the cell (cx, cy, cz, cw),
    relative to that cell's corner."""
    jx, jy, jz, jw = cell_point(dim, cx + i, cy + j, cz + k, cw + u)
    return i + jx * randomness, j + jy * randomness, k + jz * randomness, u + jw * randomness


@kernel(allocates=False)
def cell_color(dim, x, y, z, w):
    """The colour of the cell at integer coordinates (x, y, z, w)."""
    if dim == 1:
        return hash_float1_to_float3(x)
    if dim == 2:
        return hash_int3_to_float3(int(x), int(y), 0)
    if dim == 3:
        return hash_int3_to_float3(int(x), int(y), int(z))
    a, b, c, _ = hash_int4_to_float4(int(x), int(y), int(z), int(w))
    return a, b, c


@kernel(allocates=False)
def distance(dim, metric, exponent, dx, dy, dz, dw):
    """The length of (dx, dy, dz, dw)'s first dim components under `metric`."""
    if dim == 1:
        return abs(dx)
    ax, ay, az, aw = abs(dx), abs(dy), abs(dz), abs(dw)
    if metric == MANHATTAN:
        return ax + ay + az + aw
    if metric == CHEBYCHEV:
        return max(max(ax, ay), max(az, aw))
    if metric == MINKOWSKI:
        s = ax ** exponent + ay ** exponent
        if dim > 2:
            s += az ** exponent
        if dim > 3:
            s += aw ** exponent
        return s ** (1.0 / exponent)
    return math.sqrt(ax * ax + ay * ay + az * az + aw * aw)


@kernel(allocates=False)
def reach(dim, axis, r):
    """The neighbourhood's extent along `axis`: r for a used axis, else 0."""
    return r if axis < dim else 0


@kernel(allocates=False)
def smoothstep01(x):
    if x < 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    return (3.0 - 2.0 * x) * (x * x)


@kernel(allocates=False)
def octave(dim, feature, metric, exponent, randomness, smoothness, x, y, z, w):
    """One octave of F1, F2 or Smooth F1 at a point: (distance, r, g, b, px, py, pz,
    pw), the position in the point's coordinates."""
    cx, cy, cz, cw = math.floor(x), math.floor(y), math.floor(z), math.floor(w)
    lx, ly, lz, lw = x - cx, y - cy, z - cz, w - cw
    smooth = feature == SMOOTH_F1 and smoothness != 0.0
    r = 2 if smooth else 1
    d1 = FLT_MAX
    d2 = FLT_MAX
    o1 = (0.0, 0.0, 0.0, 0.0)
    o2 = (0.0, 0.0, 0.0, 0.0)
    p1 = (0.0, 0.0, 0.0, 0.0)
    p2 = (0.0, 0.0, 0.0, 0.0)
    sd = 0.0
    sr = sg = sb = 0.0
    spx = spy = spz = spw = 0.0
    h = -1.0
    for u in range(-reach(dim, 3, r), reach(dim, 3, r) + 1):
        for k in range(-reach(dim, 2, r), reach(dim, 2, r) + 1):
            for j in range(-reach(dim, 1, r), reach(dim, 1, r) + 1):
                for i in range(-r, r + 1):
                    px, py, pz, pw = neighbour_point(dim, randomness, cx, cy, cz, cw, i, j,
                                                     k, u)
                    d = distance(dim, metric, exponent, px - lx, py - ly, pz - lz, pw - lw)
                    if smooth:
                        h = 1.0 if h == -1.0 else smoothstep01(
                            0.5 + 0.5 * (sd - d) / smoothness)
                        correction = smoothness * h * (1.0 - h)
                        sd = sd + (d - sd) * h - correction
                        correction /= 1.0 + 3.0 * smoothness
                        cr, cg, cb = cell_color(dim, cx + i, cy + j, cz + k, cw + u)
                        sr = sr + (cr - sr) * h - correction
                        sg = sg + (cg - sg) * h - correction
                        sb = sb + (cb - sb) * h - correction
                        spx = spx + (px - spx) * h - correction
                        spy = spy + (py - spy) * h - correction
                        spz = spz + (pz - spz) * h - correction
                        spw = spw + (pw - spw) * h - correction
                    elif d < d1:
                        d2, o2, p2 = d1, o1, p1
                        d1, o1, p1 = d, (float(i), float(j), float(k), float(u)), \
                            (px, py, pz, pw)
                    elif d < d2:
                        d2, o2, p2 = d, (float(i), float(j), float(k), float(u)), \
                            (px, py, pz, pw)
    if smooth:                               # (the unused coordinates took corrections)
        return (sd, sr, sg, sb, cx + spx, cy + spy if dim > 1 else 0.0,
                cz + spz if dim > 2 else 0.0, cw + spw if dim > 3 else 0.0)
    if feature == F2:
        d1, o1, p1 = d2, o2, p2
    cr, cg, cb = cell_color(dim, cx + o1[0], cy + o1[1], cz + o1[2], cw + o1[3])
    return d1, cr, cg, cb, cx + p1[0], cy + p1[1], cz + p1[2], cw + p1[3]


@kernel(allocates=False)
def edge_1d(randomness, x):
    c = math.floor(x)
    lx = x - c
    mid = hash_float_to_float(c) * randomness
    left = -1.0 + hash_float_to_float(c - 1.0) * randomness
    right = 1.0 + hash_float_to_float(c + 1.0) * randomness
    return min(abs((mid + left) / 2.0 - lx), abs((mid + right) / 2.0 - lx))


@kernel(allocates=False)
def distance_to_edge(dim, randomness, x, y, z, w):
    """One octave of Distance to Edge."""
    if dim == 1:
        return edge_1d(randomness, x)
    cx, cy, cz, cw = math.floor(x), math.floor(y), math.floor(z), math.floor(w)
    lx, ly, lz, lw = x - cx, y - cy, z - cz, w - cw
    best = FLT_MAX
    vx = vy = vz = vw = 0.0
    for rep in range(2):
        if rep == 1:
            best = FLT_MAX
        for u in range(-reach(dim, 3, 1), reach(dim, 3, 1) + 1):
            for k in range(-reach(dim, 2, 1), reach(dim, 2, 1) + 1):
                for j in range(-1, 2):
                    for i in range(-1, 2):
                        tx, ty, tz, tw = neighbour_point(dim, randomness, cx, cy, cz, cw, i,
                                                         j, k, u)
                        tx, ty, tz, tw = tx - lx, ty - ly, tz - lz, tw - lw
                        if rep == 0:
                            d = tx * tx + ty * ty + tz * tz + tw * tw
                            if d < best:
                                best = d
                                vx, vy, vz, vw = tx, ty, tz, tw
                            continue
                        ex, ey, ez, ew = tx - vx, ty - vy, tz - vz, tw - vw
                        e2 = ex * ex + ey * ey + ez * ez + ew * ew
                        if e2 > 0.0001:
                            n = 1.0 / math.sqrt(e2)
                            d = ((vx + tx) * ex + (vy + ty) * ey + (vz + tz) * ez
                                 + (vw + tw) * ew) * 0.5 * n
                            best = min(best, d)
    return best


@kernel(allocates=False)
def n_sphere_radius(dim, randomness, x, y, z, w):
    cx, cy, cz, cw = math.floor(x), math.floor(y), math.floor(z), math.floor(w)
    lx, ly, lz, lw = x - cx, y - cy, z - cz, w - cw
    best = FLT_MAX
    ox = oy = oz = ow = 0
    qx = qy = qz = qw = 0.0
    for u in range(-reach(dim, 3, 1), reach(dim, 3, 1) + 1):
        for k in range(-reach(dim, 2, 1), reach(dim, 2, 1) + 1):
            for j in range(-reach(dim, 1, 1), reach(dim, 1, 1) + 1):
                for i in range(-1, 2):
                    px, py, pz, pw = neighbour_point(dim, randomness, cx, cy, cz, cw, i, j,
                                                     k, u)
                    d = distance(dim, EUCLIDEAN, 1.0, px - lx, py - ly, pz - lz, pw - lw)
                    if d < best:
                        best = d
                        qx, qy, qz, qw = px, py, pz, pw
                        ox, oy, oz, ow = i, j, k, u
    best = FLT_MAX
    sx = sy = sz = sw = 0.0
    for u in range(-reach(dim, 3, 1), reach(dim, 3, 1) + 1):
        for k in range(-reach(dim, 2, 1), reach(dim, 2, 1) + 1):
            for j in range(-reach(dim, 1, 1), reach(dim, 1, 1) + 1):
                for i in range(-1, 2):
                    if i == 0 and j == 0 and k == 0 and u == 0:
                        continue
                    px, py, pz, pw = neighbour_point(dim, randomness, cx, cy, cz, cw, i + ox,
                                                     j + oy, k + oz, u + ow)
                    d = distance(dim, EUCLIDEAN, 1.0, qx - px, qy - py, qz - pz, qw - pw)
                    if d < best:
                        best = d
                        sx, sy, sz, sw = px, py, pz, pw
    return distance(dim, EUCLIDEAN, 1.0, sx - qx, sy - qy, sz - qz, sw - qw) / 2.0


@kernel(allocates=False)
def lerp(a, b, t):
    return a + t * (b - a)


@kernel(allocates=False)
def fractal_features(dim, feature, metric, exponent, randomness, smoothness, detail,
                     roughness, lacunarity, x, y, z, w):
    """F1 / F2 / Smooth F1 summed over octaves: (distance, r, g, b, px, py, pz, pw, the
    sum of the amplitudes)."""
    amp = 1.0
    max_amp = 0.0
    scale = 1.0
    d = cr = cg = cb = 0.0
    px = py = pz = pw = 0.0
    rem = detail - math.floor(detail)
    for i in range(int(math.ceil(detail)) + 1):
        od, r, g, b, qx, qy, qz, qw = octave(dim, feature, metric, exponent, randomness,
                                             smoothness, x * scale, y * scale, z * scale,
                                             w * scale)
        if detail == 0.0 or roughness == 0.0:
            return od, r, g, b, qx, qy, qz, qw, 1.0
        if i <= detail:
            max_amp += amp
            d, cr, cg, cb = d + od * amp, cr + r * amp, cg + g * amp, cb + b * amp
            px, py = lerp(px, qx / scale, amp), lerp(py, qy / scale, amp)
            pz, pw = lerp(pz, qz / scale, amp), lerp(pw, qw / scale, amp)
            scale *= lacunarity
            amp *= roughness
        elif rem != 0.0:
            max_amp = lerp(max_amp, max_amp + amp, rem)
            d = lerp(d, d + od * amp, rem)
            cr, cg, cb = (lerp(cr, cr + r * amp, rem), lerp(cg, cg + g * amp, rem),
                          lerp(cb, cb + b * amp, rem))
            px = lerp(px, lerp(px, qx / scale, amp), rem)
            py = lerp(py, lerp(py, qy / scale, amp), rem)
            pz = lerp(pz, lerp(pz, qz / scale, amp), rem)
            pw = lerp(pw, lerp(pw, qw / scale, amp), rem)
    return d, cr, cg, cb, px, py, pz, pw, max_amp


@kernel(allocates=False)
def fractal_edge(dim, randomness, detail, roughness, lacunarity, max_distance, normalize,
                 x, y, z, w):
    amp = 1.0
    max_amp = max_distance
    scale = 1.0
    d = 8.0
    rem = detail - math.floor(detail)
    for i in range(int(math.ceil(detail)) + 1):
        od = distance_to_edge(dim, randomness, x * scale, y * scale, z * scale, w * scale)
        if detail == 0.0 or roughness == 0.0:
            d = od
            break
        if i <= detail:
            max_amp = lerp(max_amp, max_distance / scale, amp)
            d = lerp(d, min(d, od / scale), amp)
            scale *= lacunarity
            amp *= roughness
        elif rem != 0.0:
            max_amp = lerp(max_amp, lerp(max_amp, max_distance / scale, amp), rem)
            d = lerp(d, min(d, lerp(d, min(d, od / scale), amp)), rem)
    return d / max_amp if normalize else d


@kernel(allocates=False)
def voronoi_texture(dim, feature, metric, normalize, x, y, z, w, scale, detail, roughness,
                    lacunarity, smoothness, exponent, randomness):
    """The Voronoi Texture node at a point already multiplied by `scale`: (Distance, r,
    g, b, px, py, pz, pw, Radius), the position in the point's own coordinates (divided
    back by scale). Outputs a feature does not compute are 0."""
    y = y if dim > 1 else 0.0                # the unused coordinates: 0
    z = z if dim > 2 else 0.0
    w = w if dim > 3 else 0.0
    detail = min(max(detail, 0.0), 15.0)
    roughness = min(max(roughness, 0.0), 1.0)
    randomness = min(max(randomness, 0.0), 1.0)
    smoothness = min(max(smoothness / 2.0, 0.0), 0.5)
    reach_max = 0.5 + 0.5 * randomness
    if feature == DISTANCE_TO_EDGE:
        d = fractal_edge(dim, randomness, detail, roughness, lacunarity, reach_max, normalize,
                         x, y, z, w)
        return d, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    if feature == N_SPHERE_RADIUS:
        radius = n_sphere_radius(dim, randomness, x, y, z, w)
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, radius
    d, r, g, b, px, py, pz, pw, max_amp = fractal_features(
        dim, feature, metric, exponent, randomness, smoothness, detail, roughness, lacunarity,
        x, y, z, w)
    if normalize:
        max_distance = distance(dim, metric, exponent, reach_max,
                                reach_max if dim > 1 else 0.0, reach_max if dim > 2 else 0.0,
                                reach_max if dim > 3 else 0.0)
        if feature == F2:
            max_distance *= 2.0
        d /= max_amp * max_distance
        r, g, b = r / max_amp, g / max_amp, b / max_amp
    inv = 1.0 / scale if scale != 0.0 else 0.0
    return d, r, g, b, px * inv, py * inv, pz * inv, pw * inv, 0.0
