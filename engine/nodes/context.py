"""What a shader program reads of a hit: one float64 row per hit (the H_* layout), and the
object table (the O_* layout) its object columns come from.

Normals follow Cycles' shader setup: on a back-facing hit N and Ng are flipped to face
the incoming ray, and Backfacing is 1. I points back along the ray (Cycles' wi).
Object coordinates are the hit in the object's space (its matrix_world at the frame);
Generated coordinates map the object's texture space (Blender's auto texture space:
the mesh's bounding box) to [0, 1]^3; the Texture Coordinate node's Normal is N in
object space. Moving objects read them at the frame, not at the ray's shutter time.
Camera and Window are the render camera's (camera_coords). The path's bounce counts and
the ray's footprint are the caller's to write (`path_fields`), the changes of the
surface fields over a pixel step engine.nodes.differentials'.
"""
from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import kernel
from .camera_coords import camera_space, window

# ---------------------------------------------------------------- hit row
# The first N_DIFF columns vary along the surface: the row also holds their change over a
# pixel step in x (H_DX + column) and in y (H_DY + column), which the Bump node's offset
# evaluations add (engine.nodes.differentials, engine.nodes.bump).
H_P = 0              # position (3)
H_UV = 3             # UV map (3; w = 0)
H_GENERATED = 6      # generated coordinates (3)
H_OBJECT = 9         # object-space position (3)
H_COLOR = 12         # the color attribute, RGBA (4); 0 where the mesh has none
H_CAMERA = 16        # camera-space position (3), Cycles' camera space
H_WINDOW = 19        # the position in the camera's frame, [0, 1]^2 (3; z = 0)
N_DIFF = 22
H_N = 22             # shading normal, facing the ray (3)
H_NG = 25            # geometric normal, facing the ray (3)
H_I = 28             # towards the ray's origin (3)
H_OBJ_NORMAL = 31    # object-space normal (3)
H_BACKFACING = 34
H_RAY = 35           # engine.visibility bit of the ray (CAMERA, DIFFUSE, ...; SHADOW)
H_DEPTH = 36         # bounces before this hit
H_RAY_LENGTH = 37
H_OBJ_LOCATION = 38  # the object's location (3)
H_OBJ_COLOR = 41     # the object's colour (3)
H_OBJ_RANDOM = 44
H_OBJ_INDEX = 45     # pass index
H_TANGENT = 46       # the UV map's tangent (3), object space, unnormalised (tangent_frame)
H_TANGENT_SIGN = 49  # object-space bitangent sign; 0 where the mesh has no tangents
H_DIFFUSE_DEPTH = 50         # diffuse, glossy, transmission bounces before this hit
H_GLOSSY_DEPTH = 51
H_TRANSMISSION_DEPTH = 52
H_TRANSPARENT_DEPTH = 53     # transparent surfaces passed so far
H_FOOTPRINT = 54     # the ray's footprint at the hit (Cycles' compact sd->dP); 0: none
N_BASE = 55
H_DX = N_BASE        # d(column)/dx of the first N_DIFF columns
H_DY = N_BASE + N_DIFF
# A displaced surface's point before displacement (engine.displacement): its position
# (3) and object-space position (3), then the position's changes over the pixel steps
# in x and in y (3 each); the hit's own where the surface is not displaced. A
# Displacement and Bump material's bump reads them (bump.DISP_ENTER), as Cycles' bump
# evaluation does.
H_UNDISPLACED = N_BASE + 2 * N_DIFF
N_UNDISPLACED = 12
# the object's linear part M (3 x 3, row-major, object -> world; the identity without an
# object), for the nodes that work in object space (engine.nodes.bump)
H_OBJ_MATRIX = H_UNDISPLACED + N_UNDISPLACED
# the Hair Info node's outputs (engine.kernels.curve_hit.strand_info; 0 off hair)
H_HAIR_IS_STRAND = H_OBJ_MATRIX + 9
H_HAIR_INTERCEPT = H_HAIR_IS_STRAND + 1
H_HAIR_LENGTH = H_HAIR_IS_STRAND + 2
H_HAIR_THICKNESS = H_HAIR_IS_STRAND + 3
H_HAIR_RANDOM = H_HAIR_IS_STRAND + 4
H_HAIR_TANGENT_NORMAL = H_HAIR_IS_STRAND + 5   # (3)
# 1 on a face shaded flat whose shading normal is not its own (engine.scene
# TriangleMesh.flat_faces): a Normal Map builds on the geometric normal there
H_FLAT_FACE = H_HAIR_IS_STRAND + 8
# the smooth normal a tangent-space Normal Map builds on (3): object space, interpolated
# and unnormalised (tangent_frame); 0 without tangents or corner normals
H_MAP_NORMAL = H_HAIR_IS_STRAND + 9
N_HIT = H_HAIR_IS_STRAND + 12

# ---------------------------------------------------------------- object table columns
O_TO_OBJECT = 0      # 3 x 4 world -> object, row-major (12)
O_NORMAL = 12        # 3 x 3 row-major: object-space normal = this x world normal (M^T)
O_LOCATION = 21
O_COLOR = 24
O_RANDOM = 27
O_INDEX = 28
O_TEX_LOCATION = 29  # texture space centre (3)
O_TEX_SIZE = 32      # texture space half-size (3)
O_TO_WORLD = 35      # 3 x 4 object -> world, row-major (12): where an instance stands
N_OBJ = 47


def object_rows(matrices, colors, randoms, pass_indices, texspace_location,
                texspace_size):
    """The O_* rows (K, N_OBJ) of K objects: matrices (K, 4, 4) object -> world, colors
    (K, 3), randoms and pass_indices (K,); one texture space (centre, half-size) for all."""
    m = np.asarray(matrices, np.float64).reshape(-1, 4, 4)
    k = len(m)
    rows = np.zeros((k, N_OBJ))
    a = m[:, :3, :3]
    inv = np.empty_like(a)
    det = np.linalg.det(a) if k else np.zeros(0)
    ok = np.abs(det) > 0.0
    inv[ok] = np.linalg.inv(a[ok])
    if (~ok).any():
        inv[~ok] = np.linalg.pinv(a[~ok])
    t = m[:, :3, 3]
    rows[:, O_TO_OBJECT:O_TO_OBJECT + 12] = np.concatenate(
        [inv, -np.einsum("kij,kj->ki", inv, t)[:, :, None]], axis=2).reshape(k, 12)
    rows[:, O_NORMAL:O_NORMAL + 9] = np.transpose(a, (0, 2, 1)).reshape(k, 9)
    rows[:, O_LOCATION:O_LOCATION + 3] = t
    rows[:, O_COLOR:O_COLOR + 3] = np.asarray(colors, np.float64).reshape(k, -1)[:, :3]
    rows[:, O_RANDOM] = np.asarray(randoms, np.float64).reshape(k)
    rows[:, O_INDEX] = np.asarray(pass_indices, np.float64).reshape(k)
    rows[:, O_TEX_LOCATION:O_TEX_LOCATION + 3] = texspace_location
    size = np.asarray(texspace_size, np.float64)
    rows[:, O_TEX_SIZE:O_TEX_SIZE + 3] = np.where(np.abs(size) > 1e-12, size, 1.0)
    rows[:, O_TO_WORLD:O_TO_WORLD + 12] = m[:, :3, :4].reshape(k, 12)
    return rows


def object_row(matrix_world, color=(1.0, 1.0, 1.0), random=0.0, pass_index=0,
               texspace_location=(0.0, 0.0, 0.0), texspace_size=(1.0, 1.0, 1.0)):
    """The O_* row of one object (matrix_world: its 4 x 4 object -> world matrix)."""
    return object_rows(np.asarray(matrix_world, np.float64).reshape(1, 4, 4),
                       np.asarray(color, np.float64)[None, :3], [random], [pass_index],
                       texspace_location, texspace_size)[0]


IDENTITY_OBJECT = object_row(np.eye(4))


@kernel(inline="always")
def mirrors(o):
    """Whether object row o's matrix mirrors (its 3 x 3 has a negative determinant)."""
    w = O_TO_WORLD
    return (o[w] * (o[w + 5] * o[w + 10] - o[w + 6] * o[w + 9])
            - o[w + 1] * (o[w + 4] * o[w + 10] - o[w + 6] * o[w + 8])
            + o[w + 2] * (o[w + 4] * o[w + 9] - o[w + 5] * o[w + 8])) < 0.0


@kernel(inline="always")
def to_world_direction(o, x, y, z):
    """Direction (x, y, z) of object row o's space in the world (its matrix's 3 x 3)."""
    w = O_TO_WORLD
    return (o[w] * x + o[w + 1] * y + o[w + 2] * z, o[w + 4] * x + o[w + 5] * y + o[w + 6] * z,
            o[w + 8] * x + o[w + 9] * y + o[w + 10] * z)


@kernel(allocates=False)
def fill(hit, px, py, pz, nx, ny, nz, gx, gy, gz, dx, dy, dz, u, v, front, ray, depth,
         length, objects, obj, camera, tx, ty, tz, ts, cr, cg, cb, ca):
    """Write one hit row's fields of the hit itself (the path's fields and the
    differentials are the callers', see `path_fields` and engine.nodes.differentials).
    (n, g): shading and geometric normals facing the ray; d: the ray's direction;
    (u, v): its UV; obj: its row in `objects` (-1: the identity object, texture space
    the unit cube around the origin); camera: the packed render camera (empty: none);
    t, ts: tangent and bitangent sign (ts = 0: none); c: the color attribute."""
    hit[H_CAMERA], hit[H_CAMERA + 1], hit[H_CAMERA + 2] = camera_space(camera, px, py, pz)
    hit[H_WINDOW], hit[H_WINDOW + 1] = window(camera, px, py, pz)
    hit[H_WINDOW + 2] = 0.0
    hit[H_TANGENT], hit[H_TANGENT + 1], hit[H_TANGENT + 2] = tx, ty, tz
    hit[H_TANGENT_SIGN] = ts
    hit[H_COLOR], hit[H_COLOR + 1], hit[H_COLOR + 2], hit[H_COLOR + 3] = cr, cg, cb, ca
    hit[H_P], hit[H_P + 1], hit[H_P + 2] = px, py, pz
    hit[H_N], hit[H_N + 1], hit[H_N + 2] = nx, ny, nz
    hit[H_NG], hit[H_NG + 1], hit[H_NG + 2] = gx, gy, gz
    hit[H_I], hit[H_I + 1], hit[H_I + 2] = -dx, -dy, -dz
    hit[H_UV], hit[H_UV + 1], hit[H_UV + 2] = u, v, 0.0
    hit[H_BACKFACING] = 0.0 if front else 1.0
    hit[H_RAY] = ray
    hit[H_DEPTH] = depth
    hit[H_RAY_LENGTH] = length
    if obj >= 0 and obj < objects.shape[0]:
        o = objects[obj]
        for k in range(3):
            hit[H_OBJECT + k] = (o[O_TO_OBJECT + 4 * k] * px + o[O_TO_OBJECT + 4 * k + 1] * py
                                 + o[O_TO_OBJECT + 4 * k + 2] * pz + o[O_TO_OBJECT + 4 * k + 3])
            hit[H_OBJ_NORMAL + k] = (o[O_NORMAL + 3 * k] * nx + o[O_NORMAL + 3 * k + 1] * ny
                                     + o[O_NORMAL + 3 * k + 2] * nz)
            hit[H_GENERATED + k] = ((hit[H_OBJECT + k] - o[O_TEX_LOCATION + k])
                                    / (2.0 * o[O_TEX_SIZE + k]) + 0.5)
            hit[H_OBJ_LOCATION + k] = o[O_LOCATION + k]
            hit[H_OBJ_COLOR + k] = o[O_COLOR + k]
        hit[H_OBJ_RANDOM] = o[O_RANDOM]
        hit[H_OBJ_INDEX] = o[O_INDEX]
        for r in range(3):
            for c in range(3):
                hit[H_OBJ_MATRIX + 3 * r + c] = o[O_TO_WORLD + 4 * r + c]
        ln = math.sqrt(hit[H_OBJ_NORMAL] ** 2 + hit[H_OBJ_NORMAL + 1] ** 2
                       + hit[H_OBJ_NORMAL + 2] ** 2)
        if ln > 0.0:
            for k in range(3):
                hit[H_OBJ_NORMAL + k] /= ln
    else:
        for k, c in enumerate((px, py, pz)):
            hit[H_OBJECT + k] = c
            hit[H_GENERATED + k] = 0.5 * c + 0.5
            hit[H_OBJ_LOCATION + k] = 0.0
            hit[H_OBJ_COLOR + k] = 1.0
        hit[H_OBJ_NORMAL], hit[H_OBJ_NORMAL + 1], hit[H_OBJ_NORMAL + 2] = nx, ny, nz
        hit[H_OBJ_RANDOM] = 0.0
        hit[H_OBJ_INDEX] = 0.0
        for r in range(3):
            for c in range(3):
                hit[H_OBJ_MATRIX + 3 * r + c] = 1.0 if r == c else 0.0
    for k in range(3):
        hit[H_UNDISPLACED + k] = hit[H_P + k]
        hit[H_UNDISPLACED + 3 + k] = hit[H_OBJECT + k]


@kernel(allocates=False)
def set_undisplaced(hit, objects, obj, x, y, z):
    """A displaced surface's hit at its undisplaced object-space point (x, y, z): its
    Generated coordinates from there (as Cycles reads its generated attribute) and the
    undisplaced fields (H_UNDISPLACED; engine.displacement)."""
    if obj >= 0 and obj < objects.shape[0]:
        o = objects[obj]
        for k, c in enumerate((x, y, z)):
            hit[H_GENERATED + k] = (c - o[O_TEX_LOCATION + k]) / (2.0 * o[O_TEX_SIZE + k]) + 0.5
            hit[H_UNDISPLACED + k] = (o[O_TO_WORLD + 4 * k] * x + o[O_TO_WORLD + 4 * k + 1] * y
                                      + o[O_TO_WORLD + 4 * k + 2] * z + o[O_TO_WORLD + 4 * k + 3])
    else:
        for k, c in enumerate((x, y, z)):
            hit[H_GENERATED + k] = 0.5 * c + 0.5
            hit[H_UNDISPLACED + k] = c
    hit[H_UNDISPLACED + 3], hit[H_UNDISPLACED + 4], hit[H_UNDISPLACED + 5] = x, y, z


@kernel(allocates=False)
def path_fields(hit, counts, used, p, footprint):
    """The path's fields of a hit row: path p's diffuse, glossy and transmission bounces
    (counts[p]), its transparent ones (used[p]) and the ray's footprint at the hit."""
    hit[H_DIFFUSE_DEPTH] = counts[p, 0]
    hit[H_GLOSSY_DEPTH] = counts[p, 1]
    hit[H_TRANSMISSION_DEPTH] = counts[p, 2]
    hit[H_TRANSPARENT_DEPTH] = used[p]
    hit[H_FOOTPRINT] = footprint


@kernel
def fill_rows(position, normal, geometric_normal, direction, uv, front, ray, depth, length,
              objects, obj, tangent, color):
    """`fill` for n hits given as arrays: an (n, N_HIT) array of hit rows."""
    n = position.shape[0]
    out = np.zeros((n, N_HIT))
    no_camera = np.zeros(0)
    for i in range(n):
        fill(out[i], position[i, 0], position[i, 1], position[i, 2], normal[i, 0],
             normal[i, 1], normal[i, 2], geometric_normal[i, 0], geometric_normal[i, 1],
             geometric_normal[i, 2], direction[i, 0], direction[i, 1], direction[i, 2],
             uv[i, 0], uv[i, 1], front[i], ray[i], depth[i], length[i], objects, obj[i],
             no_camera, tangent[i, 0], tangent[i, 1], tangent[i, 2], tangent[i, 3],
             color[i, 0], color[i, 1], color[i, 2], color[i, 3])
    return out


def hit_rows(position, normal, geometric_normal=None, direction=None, uv=None, front=None,
             ray=1, depth=0, length=None, objects=None, obj=None,
             tangent=None, color=None) -> np.ndarray:
    """(n, N_HIT) hit rows from arrays (NumPy callers; anything left out takes a neutral
    value: Ng = N, the ray arriving along -N, UV (0, 0), front-facing, a camera ray at
    depth 0 of length 1, the identity object, no tangents, colour 0; tangent: (n, 4)
    tangent and bitangent sign; color: (n, 4) RGBA)."""
    position = np.ascontiguousarray(position, np.float64).reshape(-1, 3)
    n = len(position)
    normal = np.ascontiguousarray(normal, np.float64).reshape(n, 3)

    def arr(a, default, shape, dtype=np.float64):
        if a is None:
            return np.ascontiguousarray(np.broadcast_to(default, shape), dtype)
        return np.ascontiguousarray(np.broadcast_to(np.asarray(a, dtype), shape))

    ng = arr(geometric_normal, normal, (n, 3))
    d = arr(direction, -normal, (n, 3))
    uv2 = arr(uv, 0.0, (n, 2))
    return fill_rows(position, normal, ng, d, uv2, arr(front, True, (n,), np.bool_),
                     arr(ray, ray, (n,)), arr(depth, depth, (n,)), arr(length, 1.0, (n,)),
                     np.ascontiguousarray(objects if objects is not None
                                          else np.zeros((0, N_OBJ)), np.float64),
                     arr(obj, -1, (n,), np.int64), arr(tangent, 0.0, (n, 4)),
                     arr(color, 0.0, (n, 4)))
