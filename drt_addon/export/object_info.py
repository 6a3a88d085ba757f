"""What shader nodes read of an object instance (engine.scene.ObjectInfo): its colour,
pass index and texture space, worked out once per source object (`object_values`), and
its random number, one per instance (`random_id`, `random_of`)."""
from __future__ import annotations

import numpy as np

from ..engine_link import engine
from .matrices import to_numpy

_UNIT = np.float32(1.0 / 0xFFFFFFFF)
_U32 = 0xFFFFFFFF


def _rot(x: int, k: int) -> int:
    return ((x << k) | (x >> (32 - k))) & _U32


# lookup3's final mix: (target, source, rotation) for x ^= y; x -= rot(y, k), on (a, b, c)
_FINAL = ((2, 1, 14), (0, 2, 11), (1, 0, 25), (2, 1, 16), (0, 2, 4), (1, 0, 14), (2, 1, 24))


def hash_uint2(kx: int, ky: int) -> int:
    """Cycles' hash_uint2 (util/hash.h: Jenkins' lookup3 final mix of two words)."""
    start = (0xDEADBEEF + (2 << 2) + 13) & _U32
    abc = [(start + kx) & _U32, (start + ky) & _U32, start]
    for x, y, k in _FINAL:
        abc[x] ^= abc[y]
        abc[x] = (abc[x] - _rot(abc[y], k)) & _U32
    return abc[2]


def hash_string(text: str) -> int:
    """Cycles' hash_string (util/hash.h): i = 37 i + byte, over the UTF-8 bytes."""
    i = 0
    for byte in text.encode("utf-8"):
        i = (i * 37 + byte) & _U32
    return i


def random_id(inst, obj) -> int:
    """The random id Cycles gives a depsgraph object instance: Blender's own for an
    instance (particles, collection instances, Geometry Nodes); for an object that is not
    an instance, which Blender gives id 0, hash_uint2(hash_string(name), 0), so that
    every object has its own Object Info Random (measured against Cycles 5.0: the
    Randoms of six objects of LoveCandles.blend)."""
    if getattr(inst, "is_instance", False):
        return int(getattr(inst, "random_id", 0))
    return hash_uint2(hash_string(obj.name), 0)


def random_of(random_ids) -> np.ndarray:
    """Object Info's Random of instances with these random ids, as Cycles computes it:
    the id over 2^32 - 1, in float32."""
    ids = np.asarray(random_ids, dtype=np.int64).reshape(-1) & 0xFFFFFFFF
    return (ids.astype(np.float32) * _UNIT).astype(np.float64)


def object_values(obj) -> tuple:
    """(Object Info's Color, pass index, (texture space location, size)) of an object;
    the texture space is its data's (auto: the mesh's bounding box)."""
    data = getattr(obj, "data", None)
    loc = tuple(getattr(data, "texspace_location", (0.0, 0.0, 0.0)))
    size = tuple(getattr(data, "texspace_size", (1.0, 1.0, 1.0)))
    return (tuple(float(c) for c in tuple(obj.color)[:3]), int(getattr(obj, "pass_index", 0)),
            (loc, size))


def object_info(inst, obj, matrix_world) -> "engine.ObjectInfo":
    """Object Info's Color, Random and pass index, the transform and the texture space of
    one instance."""
    color, pass_index, (loc, size) = object_values(obj)
    random = float(random_of([random_id(inst, obj)])[0])
    return engine.ObjectInfo(np.asarray(to_numpy(matrix_world), np.float64), color, random,
                             pass_index, loc, size)
