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


def cornell_box(width=64, height=64, light_kind="area", light_size=0.5) -> Scene:
    """A unit-ish Cornell box (2 m cube centred on x=0,y=0, floor z=0) with one light
    (its radiance kept the same whatever its size)."""
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
        power = 60.0 * (light_size / 0.5) ** 2
        lights = [AreaLight(m, (power,) * 3, "SQUARE", light_size, light_size)]
    else:
        lights = [PointLight((0, 0, 1.8), (60.0, 60.0, 60.0))]
    cam = Camera(look_at((0, -3.9, 1.0), (0, 0, 1.0)), lens=35.0)
    return Scene(cam, width, height, meshes, mats, lights, World((0, 0, 0)))


def uv_sphere(center, radius, n_theta=24, n_phi=48, name="sphere", material=0) -> TriangleMesh:
    """A closed triangulated sphere."""
    c = np.asarray(center, dtype=np.float64)
    th = np.linspace(0, np.pi, n_theta + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, n_phi, endpoint=False)
    T, P = np.meshgrid(th, ph, indexing="ij")
    ring = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    pts = np.concatenate([[[0, 0, 1]], ring, [[0, 0, -1]]]) * radius + c
    tris = []
    for j in range(n_phi):                                  # caps
        j1 = (j + 1) % n_phi
        tris.append([0, 1 + j, 1 + j1])
        last = 1 + (n_theta - 2) * n_phi
        tris.append([len(pts) - 1, last + j1, last + j])
    for i in range(n_theta - 2):                            # bands
        for j in range(n_phi):
            j1 = (j + 1) % n_phi
            a, b = 1 + i * n_phi + j, 1 + i * n_phi + j1
            c2, d = a + n_phi, b + n_phi
            tris += [[a, c2, b], [b, c2, d]]
    tris = np.array(tris)
    return TriangleMesh(name, pts, tris, np.full(len(tris), material))


def scaled(scene: Scene, s: float) -> Scene:
    """The same scene with every length multiplied by s (light powers by s^2, so every
    radiance, and hence the image, stays the same)."""
    import copy
    out = copy.deepcopy(scene)
    for m in out.meshes:
        if m.instances is not None:       # object space stays; the places scale
            m.instances.matrices[:, :3, :] *= s
            continue
        m.positions = m.positions * s
    for l in out.lights:
        if isinstance(l, AreaLight):
            l.matrix = l.matrix.copy()
            l.matrix[:3, 3] *= s
            l.size_x *= s
            l.size_y *= s
            l.strength = tuple(np.asarray(l.strength) * s * s)
        elif isinstance(l, PointLight):
            l.position = tuple(np.asarray(l.position) * s)
            l.radius *= s
            l.strength = tuple(np.asarray(l.strength) * s * s)
    out.camera.matrix = out.camera.matrix.copy()
    out.camera.matrix[:3, 3] *= s
    out.camera.clip_start *= s
    out.camera.clip_end *= s
    out.camera.focus_distance *= s
    out.camera.aperture_radius *= s
    return out


def translated(scene: Scene, offset) -> Scene:
    """The same scene moved by `offset` (geometry, lights and camera): the same image."""
    import copy
    out = copy.deepcopy(scene)
    t = np.asarray(offset, dtype=np.float64)
    for m in out.meshes:
        if m.instances is not None:
            m.instances.matrices[:, :3, 3] += t
            continue
        m.positions = m.positions + t
    for l in out.lights:
        if isinstance(l, AreaLight):
            l.matrix = l.matrix.copy()
            l.matrix[:3, 3] += t
        elif isinstance(l, PointLight):
            l.position = tuple(np.asarray(l.position) + t)
    out.camera.matrix = out.camera.matrix.copy()
    out.camera.matrix[:3, 3] += t
    return out


def instanced_boxes(width=24, height=24, light_size=1.0) -> Scene:
    """The Cornell box whose two boxes are two places of one unit cube
    (engine.scene.Instances): the tall one scaled and turned 90 degrees about z, the
    short one scaled; the same boxes as `cornell_box`'s."""
    import copy
    from engine.scene import Instances
    scene = cornell_box(width, height, light_size=light_size)
    out = copy.deepcopy(scene)
    cube = box((-0.5, -0.5, 0.0), (0.5, 0.5, 1.0), "cube", 0)
    tall, short = np.eye(4), np.eye(4)
    tall[:3, :3] = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]) \
        @ np.diag([0.6, 0.55, 1.2])
    tall[:3, 3] = (-0.325, 0.2, 0.0)
    short[:3, :3] = np.diag([0.55, 0.55, 0.6])
    short[:3, 3] = (0.375, -0.325, 0.0)
    cube.instances = Instances(np.array([tall, short]))
    out.meshes = [m for m in out.meshes if m.name not in ("tall", "short")] + [cube]
    return out

