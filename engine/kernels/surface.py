"""Surface interactions rebuilt in float64 from Embree's hit: the compiled form of
`engine.surface`, for static triangles (`rebuild`), and for triangles of instanced meshes
placed by their instance and of moving objects placed at the ray's time
(`rebuild_at_time`). See that module for why hit points come from barycentrics; where
rays leaving them start: engine.kernels.ray_origin."""
from __future__ import annotations

import math

import numpy as np

from .curve_hit import curve_surface, is_curve
from .frame import cross, dot
from .jit import kernel
from .motion import I_KIND, I_NVERTS, I_STEPS, I_VERT0, RIGID, adjugate_columns, object_of, \
    rigid_at, step_of
from ..nodes.context import O_TO_OBJECT, O_TO_WORLD


@kernel(allocates=False)
def rebuild(positions, corners, center, corner_normals, prim, u, v, dx, dy, dz):
    """The hit of a ray with direction d on static triangle `prim` at barycentrics (u, v):
    its corners are rows corners[prim] of positions (engine.surface.SurfaceBuilder), its
    unit normal and error scale computed here as SurfaceBuilder computes them (the
    scale relative to the static scene's centre `center`).
    corner_normals is (T, 3, 3) float32, or empty for flat shading everywhere.
    Returns (position, geometric normal facing the ray, shading normal on that side,
    front_facing, error scale)."""
    w = 1.0 - u - v
    i0, i1, i2 = corners[prim, 0], corners[prim, 1], corners[prim, 2]
    p0x, p0y, p0z = positions[i0, 0], positions[i0, 1], positions[i0, 2]
    p1x, p1y, p1z = positions[i1, 0], positions[i1, 1], positions[i1, 2]
    p2x, p2y, p2z = positions[i2, 0], positions[i2, 1], positions[i2, 2]
    px = w * p0x + u * p1x + v * p2x
    py = w * p0y + u * p1y + v * p2y
    pz = w * p0z + u * p1z + v * p2z
    gx, gy, gz = unit_normal(p0x, p0y, p0z, p1x, p1y, p1z, p2x, p2y, p2z)
    front = dot(gx, gy, gz, dx, dy, dz) < 0.0
    sign = 1.0 if front else -1.0
    fx, fy, fz = gx * sign, gy * sign, gz * sign
    sx, sy, sz = fx, fy, fz
    if corner_normals.shape[0] > 0:
        c = corner_normals
        nx = w * np.float64(c[prim, 0, 0]) + u * np.float64(c[prim, 1, 0]) + v * np.float64(c[prim, 2, 0])
        ny = w * np.float64(c[prim, 0, 1]) + u * np.float64(c[prim, 1, 1]) + v * np.float64(c[prim, 2, 1])
        nz = w * np.float64(c[prim, 0, 2]) + u * np.float64(c[prim, 1, 2]) + v * np.float64(c[prim, 2, 2])
        ln = math.sqrt(nx * nx + ny * ny + nz * nz)
        if ln > 1e-12:
            nx, ny, nz = nx / ln, ny / ln, nz / ln
        else:
            nx, ny, nz = gx, gy, gz
        nx, ny, nz = nx * sign, ny * sign, nz * sign
        # a shading normal bent past the geometric one is replaced by it
        if dot(nx, ny, nz, fx, fy, fz) > 0.0:
            sx, sy, sz = nx, ny, nz
    # the triangle's scale, relative to the static scene's centre (engine.surface), bounds
    # the hit point's
    cx, cy, cz = center[0], center[1], center[2]
    scale = max(abs(p0x - cx), abs(p0y - cy), abs(p0z - cz), abs(p1x - cx), abs(p1y - cy),
                abs(p1z - cz), abs(p2x - cx), abs(p2y - cy), abs(p2z - cz))
    return px, py, pz, fx, fy, fz, sx, sy, sz, front, scale


@kernel(inline="always")
def unit_normal(p0x, p0y, p0z, p1x, p1y, p1z, p2x, p2y, p2z):
    """The unit normal of triangle (p0, p1, p2), (0, 0, 1) when it has no area
    (engine.surface's, in the same operations)."""
    gx, gy, gz = cross(p1x - p0x, p1y - p0y, p1z - p0z, p2x - p0x, p2y - p0y, p2z - p0z)
    ln = math.sqrt(gx * gx + gy * gy + gz * gz)
    if ln > 0.0:
        return gx / ln, gy / ln, gz / ln
    return 0.0, 0.0, 1.0


@kernel(allocates=False)
def rebuild_at_time(geometry, prim, inst, u, v, dx, dy, dz, time):
    """`rebuild` for any triangle, static, instanced or moving, hit at shutter time
    `time`. geometry: (positions, corners, center, material, corner_normals, holdout,
    corner_uvs, M, triangle objects, object table, ...) in the accelerator's triangle
    order, M its moving objects (engine.kernels.motion.PackedMotion; triangles from
    M.prim_start[0] on move). inst: the hit's place, its row of the object table, for
    a triangle of an instanced mesh (engine.instancing; -1 otherwise): its object-space
    vertices are placed by the row's matrix, its corner normals by the inverse-transpose.
    A moving triangle is placed as engine.accel's moving objects are traced: a rigid
    object's vertices by its transform at `time`, its corner normals by that transform's
    inverse-transpose; a deforming object's vertices interpolated between the time steps
    around `time`."""
    positions, corners, center, corner_normals, M = (geometry[0], geometry[1], geometry[2],
                                                     geometry[4], geometry[7])
    if prim < M.prim_start[0]:
        if inst < 0:
            return rebuild(positions, corners, center, corner_normals, prim, u, v, dx, dy,
                           dz)
        return _rebuild_placed(positions, corners, center, corner_normals, geometry[9][inst],
                               prim, u, v, dx, dy, dz)
    obj = object_of(M, prim)
    info, verts, tris = M.info, M.verts, M.tris
    local = prim - M.prim_start[0]
    i0, i1, i2 = tris[local, 0], tris[local, 1], tris[local, 2]
    rigid = info[obj, I_KIND] == RIGID
    base = info[obj, I_VERT0]
    a00, a01, a02, a10, a11, a12, a20, a21, a22 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0
    tx, ty, tz = 0.0, 0.0, 0.0
    n00, n01, n02, n10, n11, n12, n20, n21, n22 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0
    if rigid:
        a00, a01, a02, a10, a11, a12, a20, a21, a22, tx, ty, tz = rigid_at(
            info, M.step_trans, M.step_quat, M.step_upper, obj, time)
        # the normal matrix, the inverse-transpose: columns r_j / det
        r0x, r0y, r0z, r1x, r1y, r1z, r2x, r2y, r2z, det = adjugate_columns(
            a00, a01, a02, a10, a11, a12, a20, a21, a22)
        n00, n10, n20 = r0x / det, r0y / det, r0z / det
        n01, n11, n21 = r1x / det, r1y / det, r1z / det
        n02, n12, n22 = r2x / det, r2y / det, r2z / det
        p0x, p0y, p0z = _place(verts, base + i0, a00, a01, a02, a10, a11, a12, a20,
                               a21, a22, tx, ty, tz)
        p1x, p1y, p1z = _place(verts, base + i1, a00, a01, a02, a10, a11, a12, a20,
                               a21, a22, tx, ty, tz)
        p2x, p2y, p2z = _place(verts, base + i2, a00, a01, a02, a10, a11, a12, a20,
                               a21, a22, tx, ty, tz)
    else:
        step, f = step_of(info[obj, I_STEPS], time)
        a = base + step * info[obj, I_NVERTS]
        b = a + info[obj, I_NVERTS] if info[obj, I_STEPS] > 1 else a
        p0x, p0y, p0z = _between(verts, a + i0, b + i0, f)
        p1x, p1y, p1z = _between(verts, a + i1, b + i1, f)
        p2x, p2y, p2z = _between(verts, a + i2, b + i2, f)
    px, py, pz, fx, fy, fz, sx, sy, sz, front = _placed_hit(
        p0x, p0y, p0z, p1x, p1y, p1z, p2x, p2y, p2z, corner_normals, prim, rigid,
        n00, n01, n02, n10, n11, n12, n20, n21, n22, u, v, dx, dy, dz, False)
    tri = max(abs(p0x), abs(p0y), abs(p0z), abs(p1x), abs(p1y), abs(p1z),
              abs(p2x), abs(p2y), abs(p2z))
    scale = max(max(abs(px), abs(py), abs(pz)), tri)
    return px, py, pz, fx, fy, fz, sx, sy, sz, front, scale


@kernel(allocates=False)
def surface_at(geometry, prim, inst, u, v, ox, oy, oz, t, dx, dy, dz, time):
    """The hit of the ray o + t d on primitive `prim` at (u, v): a triangle's
    (`rebuild_at_time`, which needs only d) or a hair strand's (engine.kernels.curve_hit,
    geometry[15], whose point comes from the ray). Returns (position, geometric normal
    facing the ray, shading normal, front_facing, error scale)."""
    C = geometry[15]
    if is_curve(C, prim):
        return curve_surface(C, geometry[2], prim, u, ox, oy, oz, t, dx, dy, dz)
    return rebuild_at_time(geometry, prim, inst, u, v, dx, dy, dz, time)


@kernel(inline="always")
def _between(verts, a, b, f):
    """Vertex row a moved the fraction f of the way to row b (one deformation step to the
    next), as Embree interpolates it."""
    return (verts[a, 0] + f * (verts[b, 0] - verts[a, 0]),
            verts[a, 1] + f * (verts[b, 1] - verts[a, 1]),
            verts[a, 2] + f * (verts[b, 2] - verts[a, 2]))


@kernel(allocates=False)
def _rebuild_placed(positions, corners, center, corner_normals, o, prim, u, v, dx, dy, dz):
    """`rebuild` for triangle prim of an instanced mesh (object-space rows of positions)
    at the place of object row o (engine.nodes.context: O_TO_WORLD its matrix, O_TO_OBJECT
    the inverse, whose transpose places normals). The error scale bounds both the world
    corners' distance from `center` and the float32 error of the object-space corners
    Embree intersects, carried into the world by the matrix. A mirroring place
    (determinant < 0) turns the placed triangle's winding over; its geometric normal is
    turned back, so that front faces stay the side the mesh's normals point to (Cycles'
    negative-scale objects)."""
    a00, a01, a02, tx = o[O_TO_WORLD], o[O_TO_WORLD + 1], o[O_TO_WORLD + 2], o[O_TO_WORLD + 3]
    a10, a11, a12, ty = o[O_TO_WORLD + 4], o[O_TO_WORLD + 5], o[O_TO_WORLD + 6], \
        o[O_TO_WORLD + 7]
    a20, a21, a22, tz = o[O_TO_WORLD + 8], o[O_TO_WORLD + 9], o[O_TO_WORLD + 10], \
        o[O_TO_WORLD + 11]
    w0 = O_TO_OBJECT
    n00, n01, n02 = o[w0], o[w0 + 4], o[w0 + 8]
    n10, n11, n12 = o[w0 + 1], o[w0 + 5], o[w0 + 9]
    n20, n21, n22 = o[w0 + 2], o[w0 + 6], o[w0 + 10]
    i0, i1, i2 = corners[prim, 0], corners[prim, 1], corners[prim, 2]
    p0x, p0y, p0z = _place(positions, i0, a00, a01, a02, a10, a11, a12, a20, a21, a22,
                           tx, ty, tz)
    p1x, p1y, p1z = _place(positions, i1, a00, a01, a02, a10, a11, a12, a20, a21, a22,
                           tx, ty, tz)
    p2x, p2y, p2z = _place(positions, i2, a00, a01, a02, a10, a11, a12, a20, a21, a22,
                           tx, ty, tz)
    det = a00 * (a11 * a22 - a12 * a21) - a01 * (a10 * a22 - a12 * a20) \
        + a02 * (a10 * a21 - a11 * a20)
    px, py, pz, fx, fy, fz, sx, sy, sz, front = _placed_hit(
        p0x, p0y, p0z, p1x, p1y, p1z, p2x, p2y, p2z, corner_normals, prim, True,
        n00, n01, n02, n10, n11, n12, n20, n21, n22, u, v, dx, dy, dz, det < 0.0)
    cx, cy, cz = center[0], center[1], center[2]
    scale = max(abs(p0x - cx), abs(p0y - cy), abs(p0z - cz), abs(p1x - cx), abs(p1y - cy),
                abs(p1z - cz), abs(p2x - cx), abs(p2y - cy), abs(p2z - cz))
    local = 0.0
    for k in range(3):
        local = max(local, abs(positions[i0, k]), abs(positions[i1, k]), abs(positions[i2, k]))
    norm = max(abs(a00) + abs(a01) + abs(a02), abs(a10) + abs(a11) + abs(a12),
               abs(a20) + abs(a21) + abs(a22))
    return px, py, pz, fx, fy, fz, sx, sy, sz, front, max(scale, local * norm)


@kernel(allocates=False)
def _placed_hit(p0x, p0y, p0z, p1x, p1y, p1z, p2x, p2y, p2z, corner_normals, prim, placed,
                n00, n01, n02, n10, n11, n12, n20, n21, n22, u, v, dx, dy, dz, flip):
    """The hit at barycentrics (u, v) of the triangle whose corners p0..p2 were placed in
    the world; its corner normals go through the normal matrix n when `placed`; flip:
    the placement mirrored the winding (the geometric normal is turned back).
    Returns (position, geometric normal facing the ray, shading normal, front)."""
    gx, gy, gz = unit_normal(p0x, p0y, p0z, p1x, p1y, p1z, p2x, p2y, p2z)
    if flip:
        gx, gy, gz = -gx, -gy, -gz
    w = 1.0 - u - v
    px = w * p0x + u * p1x + v * p2x
    py = w * p0y + u * p1y + v * p2y
    pz = w * p0z + u * p1z + v * p2z
    front = dot(gx, gy, gz, dx, dy, dz) < 0.0
    sign = 1.0 if front else -1.0
    fx, fy, fz = gx * sign, gy * sign, gz * sign
    sx, sy, sz = fx, fy, fz
    if corner_normals.shape[0] > 0:
        c = corner_normals
        c0x, c0y, c0z = np.float64(c[prim, 0, 0]), np.float64(c[prim, 0, 1]), np.float64(c[prim, 0, 2])
        c1x, c1y, c1z = np.float64(c[prim, 1, 0]), np.float64(c[prim, 1, 1]), np.float64(c[prim, 1, 2])
        c2x, c2y, c2z = np.float64(c[prim, 2, 0]), np.float64(c[prim, 2, 1]), np.float64(c[prim, 2, 2])
        if placed:
            c0x, c0y, c0z = (n00 * c0x + n01 * c0y + n02 * c0z, n10 * c0x + n11 * c0y + n12 * c0z,
                             n20 * c0x + n21 * c0y + n22 * c0z)
            c1x, c1y, c1z = (n00 * c1x + n01 * c1y + n02 * c1z, n10 * c1x + n11 * c1y + n12 * c1z,
                             n20 * c1x + n21 * c1y + n22 * c1z)
            c2x, c2y, c2z = (n00 * c2x + n01 * c2y + n02 * c2z, n10 * c2x + n11 * c2y + n12 * c2z,
                             n20 * c2x + n21 * c2y + n22 * c2z)
        nx = w * c0x + u * c1x + v * c2x
        ny = w * c0y + u * c1y + v * c2y
        nz = w * c0z + u * c1z + v * c2z
        ln = math.sqrt(nx * nx + ny * ny + nz * nz)
        if ln > 1e-12:
            nx, ny, nz = nx / ln, ny / ln, nz / ln
        else:
            nx, ny, nz = gx, gy, gz
        nx, ny, nz = nx * sign, ny * sign, nz * sign
        # a shading normal bent past the geometric one is replaced by it
        if dot(nx, ny, nz, fx, fy, fz) > 0.0:
            sx, sy, sz = nx, ny, nz
    return px, py, pz, fx, fy, fz, sx, sy, sz, front


@kernel(allocates=False)
def rebuild_batch(geometry, prim, inst, u, v, o, t, d, time, position, geometric, shading,
                  front, scale):
    """`surface_at` for n hits of the rays o + t d (time may be empty: 0): writes the hit
    points, the geometric and shading normals facing the rays (n, 3), front (n,) and the
    error scales (n,). What engine.surface.SurfaceBuilder.build returns, compiled once."""
    timed = time.shape[0] > 0
    for i in range(prim.shape[0]):
        px, py, pz, gx, gy, gz, sx, sy, sz, fr, sc = surface_at(
            geometry, prim[i], inst[i], u[i], v[i], o[i, 0], o[i, 1], o[i, 2], t[i],
            d[i, 0], d[i, 1], d[i, 2], time[i] if timed else 0.0)
        position[i, 0], position[i, 1], position[i, 2] = px, py, pz
        geometric[i, 0], geometric[i, 1], geometric[i, 2] = gx, gy, gz
        shading[i, 0], shading[i, 1], shading[i, 2] = sx, sy, sz
        front[i], scale[i] = fr, sc


@kernel(inline="always")
def _place(verts, row, a00, a01, a02, a10, a11, a12, a20, a21, a22, tx, ty, tz):
    """Vertex `row` placed in the world through the affine map."""
    x, y, z = verts[row, 0], verts[row, 1], verts[row, 2]
    return (a00 * x + a01 * y + a02 * z + tx, a10 * x + a11 * y + a12 * z + ty,
            a20 * x + a21 * y + a22 * z + tz)


@kernel(allocates=False)
def hit_uv(corner_uvs, prim, u, v):
    """Texture coordinates at barycentrics (u, v) of triangle prim, from its corner UVs
    (T, 3, 2) float32; (0, 0) when the scene has none (Cycles' missing UV map)."""
    if corner_uvs.shape[0] == 0:
        return 0.0, 0.0
    w = 1.0 - u - v
    c = corner_uvs
    return (w * np.float64(c[prim, 0, 0]) + u * np.float64(c[prim, 1, 0]) + v * np.float64(c[prim, 2, 0]),
            w * np.float64(c[prim, 0, 1]) + u * np.float64(c[prim, 1, 1]) + v * np.float64(c[prim, 2, 1]))
