"""Hair: a mesh's particle hair and hair Curves objects, as strands (engine.curves), read
as Cycles syncs them (intern/cycles/blender/curves.cpp).

Particle hair (a Particle System modifier enabled for the render, Hair, Render As Path):
- the strands are the parents, or the children when the system has children;
- each has 2^steps + 1 keys (Path > Steps: render steps in a render, viewport steps in
  the viewport; a spiral kink adds its extra steps), read with `co_hair`;
- its radius runs from Hair Shape's root to tip diameter x Radius Scale / 2 along the
  strand's length, shaped by Strand Shape, and Close Tip makes the last key's 0;
- its material is the settings' Material slot of the emitter;
- its texture coordinate is its root's UV on the emitter (when a material reads UVs).
Curves objects: their points and the "radius" attribute (0.005 m where it is missing),
all with the object's first material. Both are placed by the object's transform, the
radius scaled by the transform's uniform scale (the cube root of its determinant), as
Cycles applies transforms to hair.

What Cycles draws differently and DRT does not yet: the Curves > Shape "Ribbons"
(render.hair_type STRIP; DRT draws 3D curves and says so), poly-type Curves objects
(Cycles draws them as round linear segments, DRT as the smooth spline through the same
points), and hair motion blur (strands are still, at the frame).
"""
from __future__ import annotations

import itertools

import numpy as np

from ..engine_link import engine

CLOSE_TIP_RADIUS = 0.0
CURVES_DEFAULT_RADIUS = 0.005     # Cycles' radius of a Curves point without one (metres)


def hair_systems(obj, render: bool = True):
    """(modifier, particle system) of each of the mesh's systems drawn as strands: Hair,
    Render As Path, its modifier enabled for renders (or for the viewport)."""
    for mod in getattr(obj, "modifiers", ()):
        if mod.type != "PARTICLE_SYSTEM":
            continue
        if not (mod.show_render if render else mod.show_viewport):
            continue
        settings = mod.particle_system.settings
        if settings.type == "HAIR" and settings.render_type == "PATH":
            yield mod, mod.particle_system


def shape_radius(shape: float, root: float, tip: float, along: np.ndarray) -> np.ndarray:
    """The radius at the fractions `along` of a strand's length (Strand Shape: 0 linear,
    < 0 thicker, > 0 thinner towards the tip), as Cycles shapes it."""
    r = 1.0 - np.clip(along, 0.0, 1.0)
    if shape < 0.0:
        r = r ** (1.0 + shape)
    elif shape > 0.0:
        r = r ** (1.0 / (1.0 - shape))
    return r * (root - tip) + tip


def _uniform_scale(matrix: np.ndarray) -> float:
    return float(abs(np.linalg.det(matrix[:3, :3])) ** (1.0 / 3.0))


def _place(points: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def particle_hair(obj, matrix, slots: list, render: bool = True, uv_map=None,
                  name: str = "") -> list:
    """A HairCurves per strand system of mesh `obj` (evaluated), placed by `matrix`
    (4x4, its instance's world transform); slots: the engine material of each of the
    object's slots; uv_map: None (no UVs), '' (the emitter's active render map) or a
    map's name."""
    matrix = np.asarray(matrix, np.float64)
    own = np.asarray(obj.matrix_world, np.float64)
    to_object = np.linalg.inv(own)          # co_hair gives the object's world keys
    scale = _uniform_scale(matrix)
    out, first_index = [], 0          # Cycles numbers the strands of all systems at once
    for mod, psys in hair_systems(obj, render):
        st = psys.settings
        steps = (1 << (st.render_step if render else st.display_step)) + 1
        if st.kink == "SPIRAL":
            steps += st.kink_extra_steps
        parents, children = len(psys.particles), len(psys.child_particles)
        first, count = (parents, children) if st.child_type != "NONE" and children \
            else (0, parents)
        if count == 0:
            continue
        flat = np.fromiter(itertools.chain.from_iterable(
            psys.co_hair(obj, particle_no=i, step=k)
            for i in range(first, first + count) for k in range(steps)),
            np.float64, count * steps * 3)
        local = _place(flat.reshape(-1, 3), to_object).reshape(count, steps, 3)
        # each key's fraction of its strand's length (in object space, as Cycles)
        lengths = np.linalg.norm(np.diff(local, axis=1), axis=2)
        run = np.concatenate([np.zeros((count, 1)), np.cumsum(lengths, axis=1)], axis=1)
        total = run[:, -1:]
        along = np.divide(run, total, out=np.zeros_like(run), where=total > 0)
        half = st.radius_scale * 0.5
        radii = shape_radius(st.shape, half * st.root_radius, half * st.tip_radius, along)
        if st.use_close_tip:
            radii[:, -1] = CLOSE_TIP_RADIUS
        material = slots[min(max(st.material - 1, 0), len(slots) - 1)] if slots else 0
        uvs = None
        if uv_map is not None:
            uvs = _emitter_uvs(obj, mod, psys, first, count, uv_map)
        out.append(engine.HairCurves(
            f"{name or obj.name} ({psys.name})", _place(local.reshape(-1, 3), matrix),
            radii.reshape(-1) * scale, np.arange(count + 1) * steps, materials=material,
            uvs=uvs, intercepts=along.reshape(-1), lengths=total.reshape(-1),
            first_index=first_index))
        first_index += count
    return out


def _emitter_uvs(obj, mod, psys, first: int, count: int, uv_map: str):
    """Each strand's root UV on the emitter (children: from their own place), in the
    requested map; None when the mesh has no UV map."""
    layers = list(getattr(obj.data, "uv_layers", ()))
    if not layers:
        return None
    names = [layer.name for layer in layers]
    if uv_map and uv_map in names:
        index = names.index(uv_map)
    else:
        index = next((k for k, layer in enumerate(layers) if layer.active_render), 0)
    particles = psys.particles
    uvs = np.empty((count, 2))
    for j, i in enumerate(range(first, first + count)):
        # a child is read with the first parent, as Cycles does
        parent = particles[i] if i < len(particles) else particles[0]
        uvs[j] = psys.uv_on_emitter(modifier=mod, particle=parent, particle_no=i,
                                    uv_no=index)
    return uvs


def curves_object(obj, matrix, slots: list, name: str = ""):
    """A Curves object (evaluated) as one HairCurves placed by `matrix`; None when it has
    no curve of two points or more."""
    data = obj.data
    n_points, n_curves = len(data.points), len(data.curves)
    if n_points == 0 or n_curves == 0:
        return None
    position = np.empty(n_points * 3, np.float32)
    data.attributes["position"].data.foreach_get("vector", position)
    offsets = np.empty(n_curves + 1, np.int32)
    data.curve_offset_data.foreach_get("value", offsets)
    radius_attr = data.attributes.get("radius")
    radii = np.full(n_points, CURVES_DEFAULT_RADIUS)
    if radius_attr is not None and radius_attr.domain == "POINT":
        values = np.empty(n_points, np.float32)
        radius_attr.data.foreach_get("value", values)
        radii = values.astype(np.float64)
    keys = position.reshape(-1, 3).astype(np.float64)
    sizes = np.diff(offsets)
    keep = sizes >= 2      # a one-point curve draws nothing (but keeps its index)
    if not keep.any():
        return None
    if not keep.all():
        rows = np.concatenate([np.arange(a, b) for a, b, k in
                               zip(offsets[:-1], offsets[1:], keep) if k])
        keys, radii = keys[rows], radii[rows]
        sizes = sizes[keep]
    matrix = np.asarray(matrix, np.float64)
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    radii = np.maximum(radii, 0.0)
    local = engine.HairCurves(name or obj.name, keys, radii, offsets)  # object space
    return engine.HairCurves(name or obj.name, _place(keys, matrix),
                             radii * _uniform_scale(matrix), offsets,
                             materials=slots[0] if slots else 0,
                             intercepts=local.intercepts, lengths=local.lengths,
                             strand_index=np.nonzero(keep)[0])
