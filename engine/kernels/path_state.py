"""The records the path kernels share: each path's state through the bounces, and the
scene as the vertex kernels read it. Fields are arrays updated in place (path state)
or read only (the scene); a kernel reads `paths.beta[p, 0]` where it once took `beta`."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np


class PathState(NamedTuple):
    """Per path (n rows; `stacks` has no rows in a scene without media, `alpha` none on
    an opaque film)."""
    key: np.ndarray        # (n,) uint64 random stream (engine.sampling.dispatch)
    index: np.ndarray      # (n,) int64 sample index in its pixel
    beta: np.ndarray       # (n, 3) throughput
    counts: np.ndarray     # (n, 3) int64 bounces by lobe kind: diffuse, glossy, transmission
    bounce: np.ndarray     # (n,) int64 bounces (not crossings of volume boundaries)
    vbounce: np.ndarray    # (n,) int64 scatterings in media
    ray_bits: np.ndarray   # (n,) int64 the kind of the current ray (engine.visibility)
    min_pdf: np.ndarray    # (n,) smallest BSDF pdf so far (Filter Glossy)
    cont: np.ndarray       # (n,) the roulette's verdict for the vertex the ray finds
    prev_pdf: np.ndarray   # (n,) the pdf the current ray was sampled with (inf: specular)
    prev_pos: np.ndarray   # (n, 7) the last vertex as a light sample's receiver
    time: np.ndarray       # (n,) shutter time (zeros when nothing moves)
    alpha: np.ndarray      # (n,) film coverage, or no rows on an opaque film
    stacks: np.ndarray     # (n, STACK) int32 volume stacks, or no rows
    used: np.ndarray       # (n,) int64 transparent bounces
    cone: np.ndarray       # (n, 2) ray cone: footprint at the ray's origin and spread


class TracedScene(NamedTuple):
    """What the vertex kernels read of the scene (path_vertex.shade's docstring says what
    each holds), and the counter of shader program runs in heterogeneous media."""
    geometry: tuple
    params: np.ndarray
    emission: np.ndarray
    textures: tuple
    tables: tuple
    lights: tuple
    world: np.ndarray
    vol: np.ndarray
    het_count: np.ndarray


def new_paths(key, index, time, alpha, stacks, cone) -> PathState:
    """The state of len(key) paths leaving the camera: throughput 1, no bounce, camera
    rays (engine.visibility.CAMERA) that count as specular (prev_pdf inf), with their
    shutter times, film coverage, volume stacks and ray cones."""
    from .. import visibility
    n = len(key)
    return PathState(key, np.ascontiguousarray(index, np.int64), np.ones((n, 3)),
                     np.zeros((n, 3), np.int64), np.zeros(n, np.int64),
                     np.zeros(n, np.int64), np.full(n, visibility.CAMERA, np.int64),
                     np.full(n, np.inf), np.ones(n), np.full(n, np.inf), np.zeros((n, 7)),
                     time, alpha, stacks, np.zeros(n, np.int64), cone)
