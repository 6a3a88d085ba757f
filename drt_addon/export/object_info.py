"""What shader nodes read of an object instance (engine.scene.ObjectInfo): its colour,
pass index and texture space, worked out once per source object (`object_values`), and
its random number, one per instance (`random_of`)."""
from __future__ import annotations

import numpy as np

from ..engine_link import engine
from .matrices import to_numpy

_UNIT = np.float32(1.0 / 0xFFFFFFFF)


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
    random = float(random_of([int(getattr(inst, "random_id", 0))])[0])
    return engine.ObjectInfo(np.asarray(to_numpy(matrix_world), np.float64), color, random,
                             pass_index, loc, size)
