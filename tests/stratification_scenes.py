"""Scenes where stratification matters: an area-light penumbra and a defocused edge."""
import numpy as np

from engine import AreaLight, Camera, Material, Scene, World
from engine_scenes import quad


def penumbra_scene(size=24):
    mats = [Material("white", (0.8, 0.8, 0.8), specular_ior_level=0.0)]
    meshes = [quad((0, 0, 0), (2, 0, 0), (0, 2, 0), "floor"),
              quad((-1.0, 0, 0.6), (1.0, 0, 0), (0, 2, 0), "blocker")]
    m = np.eye(4)
    m[:3, 3] = (0, 0, 2.0)
    lights = [AreaLight(m, (40.0, 40.0, 40.0), "SQUARE", 1.0, 1.0)]
    cam_m = np.eye(4)
    cam_m[:3, 3] = (0, 0, 0.3)                 # under the blocker, looking down at the floor
    cam = Camera(cam_m, kind="ORTHO", ortho_scale=0.8, clip_start=1e-3)
    return Scene(cam, size, size, meshes, mats, lights, World((0, 0, 0)))


def defocus_scene(size=24):
    mats = [Material("glow", (0, 0, 0), specular_ior_level=0.0, emission=(1.0, 1.0, 1.0))]
    meshes = [quad((-1.0, 0, -4.0), (1.0, 0, 0), (0, 1.0, 0), "edge", 0)]  # covers x < 0
    cam = Camera(np.eye(4), lens=50.0, aperture_radius=0.03, focus_distance=2.0,
                 clip_start=1e-3)
    return Scene(cam, size, size, meshes, mats, [], World((0, 0, 0)))
