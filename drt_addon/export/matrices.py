"""Blender matrices to NumPy, in float64."""
import numpy as np


def to_numpy(matrix) -> np.ndarray:
    return np.array([list(row) for row in matrix], dtype=np.float64)
