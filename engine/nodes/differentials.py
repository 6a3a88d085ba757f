"""Ray differentials at a hit, as Cycles keeps them: compact ones (a cone).

Cycles gives every ray a footprint radius dP at its origin and a spread dD (the change
of its direction per pixel); a hit at distance t sees dP + t dD (its compact sd->dP).
Camera rays start with the change of the normalised direction over one pixel (mean of
x and y) as their spread, and a perspective camera's footprint grows from zero at the
eye (the rays start at the near clip plane, so their origin's is the spread times the
distance to it); an orthographic camera's is the pixel size, with no spread. A bounce
keeps the spread and starts from the footprint of the hit it leaves: the footprint of a
path grows with the length of the path whatever its bounces (Cycles' approximation for
bounce rays).

At a hit the footprint becomes two steps on the surface, dPdx and dPdy: the
orthonormal tangents of the geometric normal (`orthonormals`) scaled by it
(differential_from_compact). Every hit row field that varies along the surface changes
over those steps; `fill_differentials` writes the changes (context.H_DX, H_DY) that
the Bump node's offset evaluations add."""
from __future__ import annotations

import math

import numpy as np

from ..kernels.camera_rays import C_CLIP_START, C_H, C_HALF_X, C_HALF_Y, C_PERSP, C_ROT, \
    C_W, N_CAM
from ..kernels.jit import kernel
from .camera_coords import window
from .context import (H_CAMERA, H_COLOR, H_DX, H_DY, H_FOOTPRINT, H_GENERATED, H_NG,
                      H_OBJECT, H_P, H_UNDISPLACED, H_UV, H_WINDOW, N_DIFF, N_UNDISPLACED,
                      O_TEX_SIZE, O_TO_OBJECT, to_world_direction)


@kernel(allocates=False)
def _step(ax, ay, az, bx, by, bz):
    ln = math.sqrt(ax * ax + ay * ay + az * az)
    lx = ax / ln - bx
    ly = ay / ln - by
    lz = az / ln - bz
    return math.sqrt(lx * lx + ly * ly + lz * lz)


@kernel(allocates=False)
def camera_cone(cam, dx, dy, dz):
    """(footprint at the ray's origin, spread) of a camera ray of world direction d
    (unit) starting at the near clip plane; (0, 0) without a camera."""
    if cam.shape[0] < N_CAM:
        return 0.0, 0.0
    step_x = 2.0 * cam[C_HALF_X] / cam[C_W]
    step_y = 2.0 * cam[C_HALF_Y] / cam[C_H]
    if cam[C_PERSP] == 0.0:
        return step_x, 0.0                    # Cycles: both steps are the x step
    r = cam[C_ROT:C_ROT + 9]
    cx = r[0] * dx + r[3] * dy + r[6] * dz
    cy = r[1] * dx + r[4] * dy + r[7] * dz
    cz = r[2] * dx + r[5] * dy + r[8] * dz
    if not cz < 0.0:
        return 0.0, 0.0
    px, py = cx / -cz, cy / -cz              # on the plane z = -1
    ln = math.sqrt(px * px + py * py + 1.0)
    ux, uy, uz = px / ln, py / ln, -1.0 / ln
    spread = 0.5 * (_step(px + step_x, py, -1.0, ux, uy, uz)
                    + _step(px, py + step_y, -1.0, ux, uy, uz))
    return cam[C_CLIP_START] / -cz * spread, spread


@kernel
def camera_cones(cam, dirs):
    """`camera_cone` of each ray: (n, 2) [footprint at the origin, spread]."""
    out = np.zeros((dirs.shape[0], 2))
    for i in range(dirs.shape[0]):
        out[i, 0], out[i, 1] = camera_cone(cam, dirs[i, 0], dirs[i, 1], dirs[i, 2])
    return out


@kernel(allocates=False)
def cone_at(cone, p, t):
    """The footprint of path p's ray at distance t (cone: (n, 2) per path)."""
    return cone[p, 0] + cone[p, 1] * t


@kernel(allocates=False)
def cone_moves(cone, p, t):
    """Path p's next ray starts where its ray hit, at distance t."""
    cone[p, 0] += cone[p, 1] * t


@kernel(allocates=False)
def _barycentric_step(e1x, e1y, e1z, e2x, e2y, e2z, sx, sy, sz):
    """(b1, b2) with e1 b1 + e2 b2 the projection of the step s onto the triangle's plane
    (edges e1, e2)."""
    a11 = e1x * e1x + e1y * e1y + e1z * e1z
    a12 = e1x * e2x + e1y * e2y + e1z * e2z
    a22 = e2x * e2x + e2y * e2y + e2z * e2z
    r1 = e1x * sx + e1y * sy + e1z * sz
    r2 = e2x * sx + e2y * sy + e2z * sz
    det = a11 * a22 - a12 * a12
    if det == 0.0:
        return 0.0, 0.0
    return (a22 * r1 - a12 * r2) / det, (a11 * r2 - a12 * r1) / det


@kernel(allocates=False)
def _corner_step(corners, prim, k, b1, b2):
    """The change of a per-corner attribute (column k) over barycentric steps b1, b2."""
    c = corners[prim]
    return (c[1, k] - c[0, k]) * b1 + (c[2, k] - c[0, k]) * b2


@kernel(allocates=False)
def _fill_step(hit, block, geometry, prim, obj, placed, camera, sx, sy, sz):
    """One block of differentials (H_DX or H_DY): the change of each field over the
    surface step s."""
    positions, corners = geometry[0], geometry[1]
    corner_uvs, objects, colors = geometry[6], geometry[9], geometry[11]
    hit[block + H_P], hit[block + H_P + 1], hit[block + H_P + 2] = sx, sy, sz
    p0, p1, p2 = positions[corners[prim, 0]], positions[corners[prim, 1]], \
        positions[corners[prim, 2]]
    e1x, e1y, e1z = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    e2x, e2y, e2z = p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]
    if placed:                  # an instance's edges, into the world
        e1x, e1y, e1z = to_world_direction(objects[obj], e1x, e1y, e1z)
        e2x, e2y, e2z = to_world_direction(objects[obj], e2x, e2y, e2z)
    b1, b2 = _barycentric_step(e1x, e1y, e1z, e2x, e2y, e2z, sx, sy, sz)
    if corner_uvs.shape[0] > 0:
        hit[block + H_UV] = _corner_step(corner_uvs, prim, 0, b1, b2)
        hit[block + H_UV + 1] = _corner_step(corner_uvs, prim, 1, b1, b2)
    if colors.shape[0] > 0:
        for k in range(4):
            hit[block + H_COLOR + k] = _corner_step(colors, prim, k, b1, b2)
    has_object = obj >= 0 and obj < objects.shape[0]
    if has_object:
        o = objects[obj]
        for k in range(3):
            d = (o[O_TO_OBJECT + 4 * k] * sx + o[O_TO_OBJECT + 4 * k + 1] * sy
                 + o[O_TO_OBJECT + 4 * k + 2] * sz)
            hit[block + H_OBJECT + k] = d
            hit[block + H_GENERATED + k] = d / (2.0 * o[O_TEX_SIZE + k])
    else:
        for k, d in enumerate((sx, sy, sz)):
            hit[block + H_OBJECT + k] = d
            hit[block + H_GENERATED + k] = 0.5 * d
    # the undisplaced surface's steps (H_UNDISPLACED): the same barycentric steps on the
    # corners before displacement (Cycles' attribute differentials); the hit's own steps
    # where the triangle is not displaced
    step = H_UNDISPLACED + (6 if block == H_DX else 9)
    undisplaced = geometry[14]
    if undisplaced.shape[0] > 0 and not math.isnan(undisplaced[prim, 0, 0]):
        ox = _corner_step(undisplaced, prim, 0, b1, b2)
        oy = _corner_step(undisplaced, prim, 1, b1, b2)
        oz = _corner_step(undisplaced, prim, 2, b1, b2)
        wx, wy, wz = ox, oy, oz
        if has_object:
            wx, wy, wz = to_world_direction(objects[obj], ox, oy, oz)
        for k, (w, d) in enumerate(((wx, ox), (wy, oy), (wz, oz))):
            hit[step + k] = w
            hit[block + H_GENERATED + k] = (d / (2.0 * objects[obj][O_TEX_SIZE + k])
                                            if has_object else 0.5 * d)
    else:
        for k in range(3):
            hit[step + k] = hit[block + H_P + k]
    if camera.shape[0] >= N_CAM:
        r = camera[C_ROT:C_ROT + 9]
        hit[block + H_CAMERA] = r[0] * sx + r[3] * sy + r[6] * sz
        hit[block + H_CAMERA + 1] = r[1] * sx + r[4] * sy + r[7] * sz
        hit[block + H_CAMERA + 2] = -(r[2] * sx + r[5] * sy + r[8] * sz)
        px, py, pz = hit[H_P], hit[H_P + 1], hit[H_P + 2]
        wx, wy = window(camera, px + sx, py + sy, pz + sz)
        hit[block + H_WINDOW] = wx - hit[H_WINDOW]
        hit[block + H_WINDOW + 1] = wy - hit[H_WINDOW + 1]


@kernel(allocates=False)
def orthonormals(nx, ny, nz):
    """Cycles' make_orthonormals as Blender 5.0 has it: a = (1, 1, 1) x n (or
    (-1, 1, 1) x n when the components are equal), normalised, and b = n x a. (Not the
    shading frame of engine.kernels.frame: the steps' directions decide which pixels of
    a sharp height edge the offset evaluations cross, and this one matches Cycles'.)"""
    if nx != ny or nx != nz:
        ax, ay, az = nz - ny, nx - nz, ny - nx
    else:
        ax, ay, az = nz - ny, nx + nz, -ny - nx
    ln = math.sqrt(ax * ax + ay * ay + az * az)
    ax, ay, az = ax / ln, ay / ln, az / ln
    return ax, ay, az, ny * az - nz * ay, nz * ax - nx * az, nx * ay - ny * ax


@kernel(allocates=False)
def fill_differentials(hit, geometry, prim, obj, placed, camera):
    """The differentials of hit row `hit` (its fields and footprint written) on triangle
    prim of object row obj (-1: none); placed: the triangle is an instance's, in object
    space, placed by obj's matrix; camera: the packed render camera (empty: none).
    All zero without a footprint."""
    for k in range(N_DIFF):
        hit[H_DX + k] = 0.0
        hit[H_DY + k] = 0.0
    for k in range(6, N_UNDISPLACED):
        hit[H_UNDISPLACED + k] = 0.0
    f = hit[H_FOOTPRINT]
    if not f > 0.0:
        return
    tx, ty, tz, bx, by, bz = orthonormals(hit[H_NG], hit[H_NG + 1], hit[H_NG + 2])
    _fill_step(hit, H_DX, geometry, prim, obj, placed, camera, tx * f, ty * f, tz * f)
    _fill_step(hit, H_DY, geometry, prim, obj, placed, camera, bx * f, by * f, bz * f)
