"""First-hit render passes (AOVs): depth, normal, albedo, position, mist and UV of what
each pixel sees.

They are computed by a separate, cheap query on a RenderContext (camera rays and one
intersection each, no shading), with Cycles' meanings:
- depth: the hit's distance along the camera's view axis (camera-space z, Cycles'
  `camera_z_depth`, which is what Blender's compositor expects of a Z pass), of the ray
  through the pixel centre and the centre of the lens; DEPTH_MISS (Cycles' 1e10) where
  that ray hits nothing;
- normal: the world-space shading normal, turned towards the camera ray (Cycles flips
  back faces the same way), averaged over the pixel's first `samples` camera samples
  (the same sub-pixel, lens and time samples the radiance used); zero where a sample hit
  nothing, so edge pixels are weighted by coverage as in Cycles;
- albedo: the diffuse albedo of the Principled BSDF hit, base colour x (1 - metallic) x
  (1 - transmission), averaged the same way (what Cycles writes to Denoising Albedo for
  a rough surface); base colour and metallic as the path tracer shades them there, from
  textures and shader programs (`hit_albedo`);
- position: the world-space hit point, averaged the same way (Cycles' Position);
- uv: (u, v, 1) of the hit's texture coordinates (the mesh's UVs, (0, 0) without any),
  averaged the same way, so the third channel is the pixel's coverage (Cycles' UV);
- mist: Cycles' Mist, averaged the same way: of the hit's distance d from the camera
  (along the view axis for an orthographic one), clamp((d - start) / depth, 0, 1) raised
  to the falloff exponent (`Mist`: World > Mist Pass), 1 where a sample hits nothing;
- object_index, material_index: the Pass Index of the object and of the material that
  the pixel's first camera sample hits (0 where it hits nothing), not averaged: Cycles
  writes its Object Index and Material Index passes from sample 0 alone;
- ambient_occlusion, when asked for: Cycles' AO pass from the same hits
  (engine.ambient_occlusion);
- shader_aovs, when asked for: the view layer's AOV passes, what the materials' AOV
  Output nodes say at the same hits (engine.shader_aovs).
Emitting lights (area and sphere lights) are not surfaces here: rays see through them.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .ambient_occlusion import occlusion
from .camera import CameraModel
from .shader_aovs import aov_values
from .render import camera_rays

DEPTH_MISS = 1.0e10
AOV_SAMPLES = 16


@dataclass(frozen=True)
class Mist:
    """World > Mist Pass: where the mist starts and its depth (metres), and the falloff
    exponent (Blender's Quadratic 2, Linear 1, Inverse Quadratic 0.5)."""
    start: float = 5.0
    depth: float = 25.0
    falloff: float = 2.0

    def of(self, distance: np.ndarray) -> np.ndarray:
        inv = 1.0 / self.depth if self.depth > 0.0 else 0.0
        m = np.clip((distance - self.start) * inv, 0.0, 1.0)
        if self.falloff == 1.0:
            return m
        if self.falloff == 2.0:
            return m * m
        if self.falloff == 0.5:
            return np.sqrt(m)
        return m ** self.falloff


@dataclass
class FirstHitPasses:
    depth: np.ndarray            # (h, w) float64
    normal: np.ndarray           # (h, w, 3) float64, world space
    albedo: np.ndarray           # (h, w, 3) float64
    samples: int                 # camera samples averaged per pixel
    position: np.ndarray = None  # (h, w, 3) float64, world space
    mist: np.ndarray = None      # (h, w) float64 in [0, 1]
    uv: np.ndarray = None        # (h, w, 3) float64: u, v, coverage
    object_index: np.ndarray = None    # (h, w) float64
    material_index: np.ndarray = None  # (h, w) float64
    ambient_occlusion: np.ndarray = None  # (h, w, 3) float64, when asked for
    shader_aovs: dict = None     # {AOV name: (h, w, 4) RGBA or (h, w, 1)}, when asked for

    def camera_normal(self, camera_matrix) -> np.ndarray:
        """The normal pass in camera space (x right, y up, z towards the viewer), as
        Cycles writes Denoising Normal."""
        m = np.asarray(camera_matrix, dtype=np.float64)[:3, :3]
        rot = m / np.linalg.norm(m, axis=0)
        return self.normal @ rot          # rows: n_world . column_i = (R^T n)_i


def _intersect(ctx, o, d, tmax, time):
    if time is None:
        return ctx.accel.intersect(o, d, tmax)
    return ctx.accel.intersect(o, d, tmax, time=time)


def _build(ctx, hits, index, o, d, time):
    return ctx.surfaces.build(hits, index, d, time=time, origins=o)


def _corner_lerp(corners: np.ndarray, prim: np.ndarray, bary: np.ndarray) -> np.ndarray:
    """Per-corner values (T, 3, c) at barycentrics (u, v) of triangles prim: (n, c)."""
    c = corners[prim].astype(np.float64)
    u, v = bary[:, 0:1], bary[:, 1:2]
    return (1.0 - u - v) * c[:, 0] + u * c[:, 1] + v * c[:, 2]


def first_hit_rows(ctx, si) -> np.ndarray:
    """(n, engine.nodes.context.N_HIT) the hit rows shader programs read at first hits
    `si` of camera rays, as the path tracer fills them there (the hit's position,
    normals, UV, object, tangent and colour attribute: engine.nodes.shading.program_hit)."""
    from .nodes.context import H_MAP_NORMAL, hit_rows
    from .visibility import CAMERA
    g = ctx.integrator.geometry
    tri_object, objects, tangents, colors = g[8], g[9], g[10], g[11]
    n = len(si.material)
    prim = si.prim
    bary = si.bary if si.bary is not None else np.zeros((n, 2))
    inst = si.inst if si.inst is not None else np.full(n, -1, np.int64)
    obj = np.where(inst >= 0, inst, tri_object[prim] if len(tri_object) else -1)
    frame = None
    if len(tangents):            # the Normal Map's object-space frame (program_hit's)
        from .nodes.tangent_frame import object_frames
        frame = object_frames(tangents, g[4], objects, np.asarray(prim, np.int64),
                              np.asarray(inst, np.int64), np.asarray(obj, np.int64),
                              np.ascontiguousarray(bary, np.float64))
    rows = hit_rows(si.position, si.shading_normal, si.geometric_normal, si.direction,
                    si.uv, si.front_facing, ray=CAMERA, objects=objects, obj=obj,
                    tangent=None if frame is None else frame[:, :4],
                    color=_corner_lerp(colors, prim, bary) if len(colors) else None)
    if frame is not None:
        rows[:, H_MAP_NORMAL:H_MAP_NORMAL + 3] = frame[:, 4:7]
    return rows


def hit_albedo(ctx, si, hits=None) -> np.ndarray:
    """(n, 3) diffuse albedo at first hits `si`: base colour x (1 - metallic) x
    (1 - transmission), base colour and metallic read as the path tracer reads them at
    a camera hit (textures, and shader programs on the hits' `first_hit_rows`, `hits`
    when the caller has them)."""
    mats = ctx.materials
    m = si.material
    transmits = 1.0 - np.clip(mats.transmission[m], 0.0, 1.0)
    if not any(name in mats.programmed or mats.textured.get(name, np.zeros(1)).any()
               for name in ("base_color", "metallic")):
        return mats.base_color[m] * ((1.0 - np.clip(mats.metallic[m], 0.0, 1.0))
                                     * transmits)[:, None]
    hits = first_hit_rows(ctx, si) if hits is None else hits
    base = mats.lookup("base_color", m, si.uv, hits)
    metallic = mats.lookup("metallic", m, si.uv, hits)
    return base * ((1.0 - np.clip(metallic, 0.0, 1.0)) * transmits)[:, None]


def sample_hits(ctx, k: int, chunk: int = 1 << 16):
    """The first hits of the first k camera samples of every pixel, a chunk at a time:
    (pixel and sample index of each sample, the samples that hit something, their
    engine.surface.SurfaceHit or None when none did, the rays' directions, the samples'
    shutter times or None when nothing moves)."""
    n_pix = ctx.scene.width * ctx.scene.height
    per_chunk = max(1, chunk // k)
    for start in range(0, n_pix, per_chunk):
        pixels = np.arange(start, min(start + per_chunk, n_pix), dtype=np.int64)
        pixel = np.repeat(pixels, k)
        index = np.tile(np.arange(k, dtype=np.int64), len(pixels))
        rays, time = camera_rays(ctx, pixel, index)
        hits = _intersect(ctx, rays.origins, rays.directions, rays.tmax, time)
        hit = np.nonzero(hits.hit)[0]
        si = _build(ctx, hits, hit, rays.origins, rays.directions, time) if hit.size else None
        yield pixel, index, hit, si, rays.directions, time


def cryptomatte(ctx, kinds, depth: int, samples: int = AOV_SAMPLES) -> dict:
    """{kind: (ids, coverage)} of the Cryptomatte layers `kinds` (engine.cryptomatte:
    'object', 'material', 'asset'), each (h, w, depth) float32, from the first
    min(samples, settings.samples) camera samples of each pixel; and the names each kind
    met, under the key "names"."""
    from .cryptomatte import HitNames, ranked
    names = HitNames(ctx)
    k = int(max(1, min(samples, ctx.settings.samples)))
    w, h = ctx.scene.width, ctx.scene.height
    found = {kind: ([], []) for kind in kinds}
    for pixel, _, hit, si, _, _ in sample_hits(ctx, k):
        if si is None:
            continue
        for kind in kinds:
            found[kind][0].append(pixel[hit])
            found[kind][1].append(names.of(kind, si.prim, si.inst, si.material))
    out = {}
    for kind, (pixels, ids) in found.items():
        i, c = ranked(np.concatenate(pixels) if pixels else np.zeros(0, np.int64),
                      np.concatenate(ids) if ids else np.zeros(0, np.float32), w * h, k,
                      depth)
        out[kind] = (i.reshape(h, w, depth), c.reshape(h, w, depth))
    out["names"] = names.names
    return out


def _add(total: np.ndarray, pixel: np.ndarray, values: np.ndarray) -> None:
    """total (n_pix, c) += the per-sample `values` (m, c) of pixels `pixel` (m,)."""
    for c in range(total.shape[1]):
        total[:, c] += np.bincount(pixel, weights=values[:, c], minlength=len(total))


def first_hit_passes(ctx, samples: int = AOV_SAMPLES, chunk: int = 1 << 16,
                     mist: Mist = Mist(), ao=None, aov_passes=()) -> FirstHitPasses:
    """Depth, normal, albedo, position, mist and UV passes for the scene of `ctx` (an
    engine.RenderContext); with `ao` (an engine.ambient_occlusion.AmbientOcclusion) the
    Ambient Occlusion pass too, and the shader AOV passes `aov_passes`
    (engine.shader_aovs.AovPass)."""
    scene = ctx.scene
    width, height = scene.width, scene.height
    n_pix = width * height
    k = int(max(1, min(samples, ctx.settings.samples)))

    # Depth: the pinhole ray through each pixel centre (the lens centre for a thin lens).
    pinhole = CameraModel(replace(scene.camera, aperture_radius=0.0), width, height,
                          scene.pixel_aspect)
    cam = np.asarray(scene.camera.matrix, dtype=np.float64)
    view_axis = -cam[:3, 2] / np.linalg.norm(cam[:3, 2])
    depth = np.full(n_pix, DEPTH_MISS)
    for start in range(0, n_pix, chunk):
        pix = np.arange(start, min(start + chunk, n_pix))
        xy = np.stack([pix % width + 0.5, pix // width + 0.5], axis=1).astype(np.float64)
        # with motion blur, the scene at the shutter's middle (the frame itself)
        middle = np.full(len(pix), 0.5) if ctx.has_motion else None
        rays = pinhole.generate(xy, time=middle)
        hits = _intersect(ctx, rays.origins, rays.directions, rays.tmax, middle)
        hit = np.nonzero(hits.hit)[0]
        if hit.size:
            p = rays.origins[hit] + rays.directions[hit] * hits.t[hit, None]
            depth[pix[hit]] = (p - cam[:3, 3]) @ view_axis

    # Normal, albedo, position and mist: the mean over the first k camera samples of each
    # pixel (a sample that hits nothing adds 0, and 1 to the mist).
    normal = np.zeros((n_pix, 3))
    albedo = np.zeros((n_pix, 3))
    position = np.zeros((n_pix, 3))
    uv = np.zeros((n_pix, 3))
    mist_sum = np.full(n_pix, float(k))           # a sample that hits nothing adds 1
    object_index, material_index = np.zeros(n_pix), np.zeros(n_pix)
    material_pass = np.array([float(getattr(m, "pass_index", 0)) for m in scene.materials]
                             or [0.0])
    ortho = scene.camera.kind == "ORTHO"
    occluded = np.zeros((n_pix, 3)) if ao is not None else None
    aov_sums = {p.name: np.zeros((n_pix, p.width)) for p in aov_passes}
    m = ao.rays_per_sample(ctx.settings.samples, k) if ao is not None else 0
    for pixel, index, hit, si, directions, time in sample_hits(ctx, k, max(1, chunk // m)
                                                               if m else chunk):
        if si is None:
            continue
        if ao is not None:
            _add(occluded, pixel[hit], occlusion(ctx, ao, pixel[hit], index[hit], si,
                                                 None if time is None else time[hit], m))
        rows = first_hit_rows(ctx, si) if aov_passes else None    # once for both
        if aov_passes:
            for name, v in aov_values(scene.materials, aov_passes, si.material,
                                      rows).items():
                _add(aov_sums[name], pixel[hit], v)
        _add(normal, pixel[hit], si.shading_normal)
        _add(albedo, pixel[hit], hit_albedo(ctx, si, rows))
        _add(position, pixel[hit], si.position)
        uv[:, 2] += np.bincount(pixel[hit], minlength=n_pix)
        if si.uv is not None:
            _add(uv[:, :2], pixel[hit], si.uv)
        first = index[hit] == 0            # the pixels' sample 0: the index passes
        object_index[pixel[hit][first]] = ctx.surfaces.pass_indices(si.prim[first],
                                                                    si.inst[first])
        material_index[pixel[hit][first]] = material_pass[
            np.minimum(si.material[first], len(material_pass) - 1)]
        offset = si.position - cam[:3, 3]
        distance = offset @ view_axis if ortho else np.linalg.norm(offset, axis=1)
        mist_sum -= np.bincount(pixel[hit], weights=1.0 - mist.of(distance), minlength=n_pix)
    shape = (height, width, 3)
    return FirstHitPasses(depth.reshape(height, width), (normal / k).reshape(shape),
                          (albedo / k).reshape(shape), k, (position / k).reshape(shape),
                          (mist_sum / k).reshape(height, width), (uv / k).reshape(shape),
                          object_index.reshape(height, width),
                          material_index.reshape(height, width),
                          None if ao is None else (occluded / k).reshape(shape),
                          {name: (v / k).reshape(height, width, -1)
                           for name, v in aov_sums.items()} if aov_passes else None)
