"""What shader nodes read of an object instance (engine.scene.ObjectInfo), exported only
for meshes whose materials run shader programs."""
from __future__ import annotations

import numpy as np

from ..engine_link import engine
from .matrices import to_numpy


def object_info(inst, obj, matrix_world) -> "engine.ObjectInfo":
    """Object Info's Color, Random (Cycles: the instance's random id over 2^32 - 1) and
    pass index; the transform; the mesh's texture space (auto: its bounding box)."""
    data = getattr(obj, "data", None)
    loc = tuple(getattr(data, "texspace_location", (0.0, 0.0, 0.0)))
    size = tuple(getattr(data, "texspace_size", (1.0, 1.0, 1.0)))
    rid = int(getattr(inst, "random_id", 0)) & 0xFFFFFFFF
    return engine.ObjectInfo(np.asarray(to_numpy(matrix_world), np.float64),
                             tuple(float(c) for c in tuple(obj.color)[:3]),
                             float(np.float32(rid) * np.float32(1.0 / 0xFFFFFFFF)),
                             int(getattr(obj, "pass_index", 0)), loc, size)
