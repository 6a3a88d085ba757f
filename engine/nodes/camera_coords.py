"""The Texture Coordinate node's Camera and Window outputs: a point in the render camera's
space and in its frame, from the packed camera vector (engine.kernels.camera_rays
.pack_camera; an empty vector: no camera, both zero).

Camera is Cycles' camera space: x to the right, y up and z along the view direction (the
camera object's local space with z flipped, so depth in front of the camera is
positive). Window is Cycles' normalised device coordinates: (0, 0) at the bottom-left
corner of the frame, (1, 1) at the top-right, shift included, z = 0; a perspective
camera projects the point through its eye, an orthographic one along its axis."""
from __future__ import annotations

from ..kernels.camera_rays import (C_HALF_X, C_HALF_Y, C_PERSP, C_POS, C_ROT, C_SHIFT_X,
                                   C_SHIFT_Y, N_CAM)
from ..kernels.jit import kernel


@kernel(allocates=False)
def camera_local(cam, px, py, pz):
    """The point in the camera object's local space (its rotation is orthonormal)."""
    r = cam[C_ROT:C_ROT + 9]
    x, y, z = px - cam[C_POS], py - cam[C_POS + 1], pz - cam[C_POS + 2]
    return (r[0] * x + r[3] * y + r[6] * z, r[1] * x + r[4] * y + r[7] * z,
            r[2] * x + r[5] * y + r[8] * z)


@kernel(allocates=False)
def camera_space(cam, px, py, pz):
    """Camera coordinates of a world point (zeros without a camera)."""
    if cam.shape[0] < N_CAM:
        return 0.0, 0.0, 0.0
    x, y, z = camera_local(cam, px, py, pz)
    return x, y, -z


@kernel(allocates=False)
def window(cam, px, py, pz):
    """Window coordinates of a world point (zeros without a camera, or for a point in
    the plane of a perspective camera's eye)."""
    if cam.shape[0] < N_CAM:
        return 0.0, 0.0
    x, y, z = camera_local(cam, px, py, pz)
    if cam[C_PERSP] != 0.0:
        if z == 0.0:
            return 0.0, 0.0
        x, y = x / -z, y / -z
    return ((x - cam[C_SHIFT_X] + cam[C_HALF_X]) / (2.0 * cam[C_HALF_X]),
            (y - cam[C_SHIFT_Y] + cam[C_HALF_Y]) / (2.0 * cam[C_HALF_Y]))
