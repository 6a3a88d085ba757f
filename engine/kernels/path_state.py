"""The records the path kernels share: each path's state through the bounces, and the
scene as the vertex kernels read it. Fields are arrays updated in place (path state)
or read only (the scene); a kernel reads `paths.beta[p, 0]` where it once took `beta`."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np


class PathState(NamedTuple):
    """Per path (n rows; `stacks` has no rows in a scene without media, `alpha` none on
    an opaque film). What the vertex kernels make of the fields:
      - ray_bits (engine.visibility: CAMERA, then the bit of the lobe the ray left by)
        decides the lamps the ray sees; next-event estimation evaluates only the lobes a
        light is seen by and skips the shadow ray of a light that casts no shadow;
      - min_pdf: Filter Glossy (engine.kernels.prepare_closures);
      - cont (path_weights.roulette): 1 none, q survived with probability q, 0 the path
        ends at the vertex its ray finds, after the emission found there;
      - used and cone are what shader programs read of the path (the cone, a footprint
        at the ray's origin and a spread, engine.nodes.differentials, moves on to the
        next ray's origin);
      - bounce counts bounces (a wavefront's depth also counts crossings of volume
        boundaries); stacks: the volume stack (engine.kernels.volume), of which the
        shadow queue keeps each shadow ray's copy."""
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
    """What the vertex kernels read of the scene:
      - geometry: (vertex positions, each triangle's corners as rows of them, the static
        scene's centre, material, corner_normals, holdout, corner_uvs, moving objects,
        triangle objects, object table, corner tangents, corner colours, camera,
        terminator cutoffs) of every triangle (corner normals, holdout, UVs, objects,
        tangents, colours and cutoffs may be empty; see `surface.surface_at` and
        engine.nodes.shading);
      - textures: the packed textures and shader programs (engine.nodes.pack.
        pack_shading); a material with a program runs it at each hit, and its outputs
        replace the parameters they drive;
      - vol: the volume table; het_count: a (1,) int64 counter of the shader program
        runs inside heterogeneous media."""
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
