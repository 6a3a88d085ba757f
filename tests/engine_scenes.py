"""Small scenes built directly as engine scene descriptions (no Blender needed)."""
from __future__ import annotations

import numpy as np

from engine.scene import AreaLight, Camera, Material, PointLight, Scene, TriangleMesh, World


def look_at(eye, target, up=(0.0, 0.0, 1.0)) -> np.ndarray:
    """A camera-to-world matrix looking from eye to target (camera -Z forward, +Y up)."""
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
    back = eye - target
    back /= np.linalg.norm(back)
    right = np.cross(up, back)
    if np.linalg.norm(right) < 1e-9:
        right = np.cross((0.0, 1.0, 0.0), back)
    right /= np.linalg.norm(right)
    true_up = np.cross(back, right)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, true_up, back, eye
    return m


def quad(center, ex, ey, name="quad", material=0) -> TriangleMesh:
    """A parallelogram centre +- ex +- ey; front side along ex x ey."""
    c, ex, ey = (np.asarray(v, dtype=np.float64) for v in (center, ex, ey))
    p = np.array([c - ex - ey, c + ex - ey, c + ex + ey, c - ex + ey])
    return TriangleMesh(name, p, np.array([[0, 1, 2], [0, 2, 3]]), np.full(2, material))


def box(lo, hi, name="box", material=0) -> TriangleMesh:
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    p = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
                  [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]])
    t = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                  [2, 3, 7], [2, 7, 6], [1, 2, 6], [1, 6, 5], [3, 0, 4], [3, 4, 7]])
    return TriangleMesh(name, p, t, np.full(len(t), material))


def cornell_box(width=64, height=64, light_kind="area") -> Scene:
    """A unit-ish Cornell box (2 m cube centred on x=0,y=0, floor z=0) with one light."""
    mats = [Material("white", (0.73, 0.73, 0.73), specular_ior_level=0.0),
            Material("red", (0.65, 0.05, 0.05), specular_ior_level=0.0),
            Material("green", (0.12, 0.45, 0.15), specular_ior_level=0.0)]
    meshes = [
        quad((0, 0, 0), (1, 0, 0), (0, 1, 0), "floor", 0),
        quad((0, 0, 2), (0, 1, 0), (1, 0, 0), "ceiling", 0),
        quad((0, 1, 1), (0, 0, 1), (1, 0, 0), "back", 0),
        quad((-1, 0, 1), (0, 1, 0), (0, 0, 1), "left", 1),
        quad((1, 0, 1), (0, 0, 1), (0, 1, 0), "right", 2),
        box((-0.6, -0.1, 0), (-0.05, 0.5, 1.2), "tall", 0),
        box((0.1, -0.6, 0), (0.65, -0.05, 0.6), "short", 0),
    ]
    if light_kind == "area":
        m = np.eye(4)
        m[:3, 3] = (0, 0, 1.98)
        lights = [AreaLight(m, (60.0, 60.0, 60.0), "SQUARE", 0.5, 0.5)]
    else:
        lights = [PointLight((0, 0, 1.8), (60.0, 60.0, 60.0))]
    cam = Camera(look_at((0, -3.9, 1.0), (0, 0, 1.0)), lens=35.0)
    return Scene(cam, width, height, meshes, mats, lights, World((0, 0, 0)))
