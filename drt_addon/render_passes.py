"""The render passes DRT writes besides Combined: which the view layer asks for, their
channels, and the first-hit passes (engine.aov) computed once per render for the passes
and the denoiser. drt_addon.render_engine writes them into Blender's render result.

Render passes, declared in `update_render_passes` and written when enabled in the view
layer (Properties > View Layer > Passes):
- Depth (`use_pass_z`): distance along the camera's view axis to the first hit, as
  Cycles' Z pass; 1e10 where nothing is hit.
- Normal (`use_pass_normal`): world-space shading normal of the first hit.
- Denoising Normal and Denoising Albedo (`view_layer.drt.use_pass_denoising_data`):
  camera-space normal and diffuse albedo, the inputs of the compositor's Denoise node.
- DRT Noise (`view_layer.drt.use_pass_noise`): per pixel and channel, the standard error
  of the pixel's mean radiance (sqrt of engine.film.Film.variance_of_mean); inf where a
  pixel has fewer than two samples.
- Mist (`use_pass_mist`): Cycles' mist of the first hit, by World > Mist Pass.
- Position (`use_pass_position`): world-space position of the first hit.
- UV (`use_pass_uv`): u, v of the first hit (the active UV map unless a material names
  one) and its coverage, as Cycles' UV pass.
- Object Index and Material Index (`use_pass_object_index`, `use_pass_material_index`;
  named IndexOB and IndexMA before Blender 5.0, as Cycles names them): the Pass Index of the object and of the material the
  pixel's first camera sample hits, as Cycles writes them (sample 0 alone).
- Environment (`use_pass_environment`; Env before Blender 5.0): the world as camera rays
  see it, through transparent surfaces, on a transparent film too, as Cycles' Environment
  pass: from the path tracer's own samples (drt_addon.light_passes).
- Ambient Occlusion (`use_pass_ambient_occlusion`; AO before Blender 5.0): Cycles' AO
  pass, from the first hits (engine.ambient_occlusion).
- Vector (`use_pass_vector`): Cycles' motion vectors for Vector Blur, from the pixel
  centres' surfaces one frame before and after (engine.motion_vectors); zeros with
  motion blur on, as Cycles writes it.
- Shader AOVs (View Layer > Shader AOV): what the materials' AOV Output nodes say at
  the first hits, a Color AOV as RGB and the share of samples that wrote it, a Value
  AOV as one value (engine.shader_aovs).
- Cryptomatte Object, Material and Asset (`use_pass_cryptomatte_*`, Levels:
  `pass_cryptomatte_depth`): CryptoObject00, 01, ... as Cycles writes them, (id,
  coverage) pairs of the names each pixel shows, with the manifest in the render
  result's metadata, so that Blender's Cryptomatte node picks mattes by name
  (engine.cryptomatte).
- Shadow Catcher (Cycles' `use_pass_shadow_catcher`): what the other objects do to the
  shadow catcher objects, 1 where nothing does; Combined is then the matte alone, as
  Cycles writes them (drt_addon.shadow_catcher, engine.shadow_catcher).
- Noisy Image (when Render > Denoise and the view layer's Denoising are on, Cycles'
  settings): the render before denoising; Combined is then denoised (drt_addon.denoise).
Depth, Normal, Mist, Position, UV, the index passes, AO, Cryptomatte and the denoising
passes come from engine.aov (a first-hit query on the same camera samples), not from the path
tracer."""
from __future__ import annotations

from importlib import import_module

import numpy as np

from . import shadow_catcher
from .blender_compat import AO_PASS, ENVIRONMENT_PASS, MATERIAL_INDEX_PASS, OBJECT_INDEX_PASS
from .shadow_catcher import PASS as SHADOW_CATCHER_PASS


# (name, channels, channel ids, type) of each pass DRT can write, and when it is enabled.
PASSES = {
    "Depth": (1, "Z", "VALUE", lambda vl: vl.use_pass_z),
    "Normal": (3, "XYZ", "VECTOR", lambda vl: vl.use_pass_normal),
    "Denoising Normal": (3, "XYZ", "VECTOR", lambda vl: _drt_layer(vl, "use_pass_denoising_data")),
    "Denoising Albedo": (3, "RGB", "COLOR", lambda vl: _drt_layer(vl, "use_pass_denoising_data")),
    "DRT Noise": (3, "RGB", "COLOR", lambda vl: _drt_layer(vl, "use_pass_noise")),
    "Mist": (1, "Z", "VALUE", lambda vl: vl.use_pass_mist),
    "Position": (3, "XYZ", "VECTOR", lambda vl: vl.use_pass_position),
    "UV": (3, "UVA", "VECTOR", lambda vl: vl.use_pass_uv),
    OBJECT_INDEX_PASS: (1, "X", "VALUE", lambda vl: vl.use_pass_object_index),
    MATERIAL_INDEX_PASS: (1, "X", "VALUE", lambda vl: vl.use_pass_material_index),
    ENVIRONMENT_PASS: (3, "RGB", "COLOR", lambda vl: vl.use_pass_environment),
    AO_PASS: (3, "RGB", "COLOR", lambda vl: vl.use_pass_ambient_occlusion),
    "Vector": (4, "XYZW", "VECTOR", lambda vl: vl.use_pass_vector),
    SHADOW_CATCHER_PASS: (3, "RGB", "COLOR", shadow_catcher.pass_on),
}
FIRST_HIT = ("Depth", "Normal", "Denoising Normal", "Denoising Albedo", "Mist", "Position",
             "UV", OBJECT_INDEX_PASS, MATERIAL_INDEX_PASS, AO_PASS)


CRYPTOMATTE = {"object": "Object", "material": "Material", "asset": "Asset"}


def cryptomatte_passes(view_layer) -> dict:
    """{kind: its pass names} of the Cryptomatte layers the view layer asks for: Levels
    names, two to a pass (CryptoObject00, CryptoObject01, ...), as Cycles names them."""
    depth = int(getattr(view_layer, "pass_cryptomatte_depth", 6))
    return {kind: [f"Crypto{label}{i:02d}" for i in range((depth + 1) // 2)]
            for kind, label in CRYPTOMATTE.items()
            if getattr(view_layer, f"use_pass_cryptomatte_{kind}", False)}


def _ambient_occlusion(engine, world):
    """World > Ambient Occlusion > Distance (Cycles' 10 m without a world) as
    engine.ambient_occlusion.AmbientOcclusion."""
    ao = import_module(engine.__name__ + ".ambient_occlusion")
    light = getattr(world, "light_settings", None)
    if light is None:
        return ao.AmbientOcclusion()
    return ao.AmbientOcclusion(distance=max(0.0, float(light.distance)))


def _mist(aov, world):
    """World > Mist Pass (Blender's defaults without a world) as engine.aov.Mist."""
    m = getattr(world, "mist_settings", None)
    if m is None:
        return aov.Mist()
    exponent = {"QUADRATIC": 2.0, "LINEAR": 1.0, "INVERSE_QUADRATIC": 0.5}.get(m.falloff, 2.0)
    return aov.Mist(float(m.start), float(m.depth), exponent)


class FirstHit:
    """engine.aov's first-hit passes of a render, computed on the first call (for the
    passes, or for the denoiser's albedo and normal) and kept: (passes, camera matrix).
    The AO pass is computed with them when `ambient_occlusion` is set (its own rays),
    and the shader AOV passes `aovs` (shader_aov_passes' rows)."""

    def __init__(self, ctx, world, description, ambient_occlusion=False, aovs=()):
        self.ctx, self.world, self.description, self.passes = ctx, world, description, None
        self.ambient_occlusion = ambient_occlusion
        self.aovs = aovs            # shader_aov_passes' rows

    def __call__(self):
        if self.passes is None:
            from .engine_link import engine
            aov = import_module(engine.__name__ + ".aov")   # in either package layout
            ao = _ambient_occlusion(engine, self.world) if self.ambient_occlusion else None
            kinds = import_module(engine.__name__ + ".shader_aovs")
            aovs = [kinds.AovPass(name, kind) for name, _, _, kind in self.aovs]
            self.passes = aov.first_hit_passes(self.ctx, mist=_mist(aov, self.world), ao=ao,
                                               aov_passes=aovs)
        return self.passes, self.description.camera.matrix


def vector_pass(render_engine, depsgraph, settings, region):
    """Cycles' Vector pass (engine.motion_vectors), (h, w, 4) top-down: zeros with motion
    blur on, as Cycles writes it; else from the scene exported once more with motion over
    the frames f - 1 to f + 1 (Blender's frame is moved and restored by the export)."""
    from .engine_link import engine
    from .export import Reporter, export_scene
    from .export.motion import MotionSettings
    scene = depsgraph.scene
    if scene.render.use_motion_blur:
        return np.zeros((region.height, region.width, 4))
    shutter = MotionSettings(int(scene.frame_current), float(scene.frame_subframe), 2.0,
                             "CENTER")
    description = export_scene(depsgraph, Reporter(None), region=region,
                               render_engine=render_engine, motion=shutter)
    vectors = import_module(engine.__name__ + ".motion_vectors")
    ctx = engine.RenderContext(description, settings)
    try:
        return vectors.vector_pass(ctx)
    finally:
        ctx.close()


def shader_aov_passes(view_layer) -> list:
    """(name, channels, channel ids, type) of the view layer's valid shader AOVs, as
    Cycles registers them: a Color AOV as RGBA, a Value AOV as one value."""
    out = []
    for aov in getattr(view_layer, "aovs", ()):
        if aov.is_valid and aov.name:
            out.append((aov.name, 4, "RGBA", "COLOR") if aov.type == "COLOR"
                       else (aov.name, 1, "X", "VALUE"))
    return out


def _drt_layer(view_layer, name) -> bool:
    settings = getattr(view_layer, "drt", None)
    return bool(getattr(settings, name, False))


def enabled_passes(view_layer) -> list:
    return [name for name, (*_, enabled) in PASSES.items() if enabled(view_layer)]
