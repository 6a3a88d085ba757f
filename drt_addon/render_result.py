"""DRT's images written into Blender's render result (for drt_addon.render_engine):
top-down arrays as Blender's flat bottom-up buffers, the extra passes a view layer asks
for, and the Cryptomatte passes with their metadata, each also kept in the render's
record (`record`: render_engine.last_render)."""
from __future__ import annotations

from importlib import import_module

import numpy as np

from . import light_passes, shadow_catcher
from .blender_compat import (AO_PASS, ENVIRONMENT_PASS, MATERIAL_INDEX_PASS,
                             OBJECT_INDEX_PASS, set_pass_pixels)
from .render_passes import (CRYPTOMATTE, FIRST_HIT, cryptomatte_passes, enabled_passes,
                            shader_aov_passes)


def bottom_up(image: np.ndarray) -> np.ndarray:
    """(h, w[, c]) top-down image to Blender's flat bottom-up float32 buffer."""
    return np.ascontiguousarray(image[::-1], dtype=np.float32).reshape(-1)


def rgba_bottom_up(image: np.ndarray, alpha: np.ndarray | None = None) -> np.ndarray:
    """(h, w, 3) top-down float image (premultiplied) and (h, w) alpha to Blender's flat
    bottom-up RGBA float32."""
    h, w, _ = image.shape
    out = np.empty((h, w, 4), dtype=np.float32)
    out[..., :3] = image[::-1]
    out[..., 3] = 1.0 if alpha is None else alpha[::-1]
    return out.reshape(-1)


def write_cryptomatte(render_engine, result, layer, ctx, view_layer, record):
    """The Cryptomatte passes the view layer asks for, and their metadata."""
    wanted = cryptomatte_passes(view_layer)
    if not wanted:
        return
    render_engine.update_stats("", "DRT: Cryptomatte")
    from .engine_link import engine
    aov = import_module(engine.__name__ + ".aov")
    crypto = import_module(engine.__name__ + ".cryptomatte")
    depth = int(view_layer.pass_cryptomatte_depth)
    layers = aov.cryptomatte(ctx, list(wanted), depth)
    for kind, names in wanted.items():
        ids, coverage = layers[kind]
        for i, name in enumerate(names):
            rgba = np.zeros(ids.shape[:2] + (4,), np.float32)
            for j in range(2):
                if 2 * i + j < depth:
                    rgba[..., 2 * j] = ids[..., 2 * i + j]
                    rgba[..., 2 * j + 1] = coverage[..., 2 * i + j]
            if layer.passes.get(name) is not None:
                set_pass_pixels(layer.passes[name], bottom_up(rgba))
            record["passes"][name] = rgba
        fields = crypto.metadata(f"{view_layer.name}.Crypto{CRYPTOMATTE[kind]}",
                                 layers["names"][kind])
        for key, value in fields.items():
            result.stamp_data_add_field(key, value)
        record["metadata"].update(fields)


def write_passes(render_engine, layer, ctx, film, view_layer, description, first_hit,
                 vectors, record):
    """The extra passes the view layer asks for and its render result holds (light passes,
    first-hit passes, shader AOVs, Shadow Catcher, DRT Noise, Vector: `vectors()` makes
    it when asked)."""
    wanted = [name for name in enabled_passes(view_layer)
              if layer.passes.get(name) is not None]
    aovs = [row for row in shader_aov_passes(view_layer)
            if layer.passes.get(row[0]) is not None]
    lights = [name for name in (light_passes.enabled(view_layer)
                                + light_passes.group_passes(view_layer))
              if layer.passes.get(name) is not None]
    if not wanted and not aovs and not lights:
        return
    images = light_passes.images(film, description.light_groups, lights)
    if ENVIRONMENT_PASS in wanted:
        images[ENVIRONMENT_PASS] = light_passes.environment(film)
    wanted += lights
    if any(n in wanted for n in FIRST_HIT):
        render_engine.update_stats("", "DRT: first-hit passes")
        first, _ = first_hit()
        images.update({"Depth": first.depth, "Normal": first.normal,
                       "Denoising Albedo": first.albedo,
                       "Denoising Normal": first.camera_normal(description.camera.matrix),
                       "Mist": first.mist, "Position": first.position, "UV": first.uv,
                       OBJECT_INDEX_PASS: first.object_index,
                       MATERIAL_INDEX_PASS: first.material_index,
                       AO_PASS: first.ambient_occlusion})
    if aovs:
        render_engine.update_stats("", "DRT: shader AOVs")
        first, _ = first_hit()
        for name, channels, _, _ in aovs:
            v = first.shader_aovs[name]          # (h, w, 4) RGBA or (h, w, 1)
            images[name] = v[..., 0] if channels == 1 else v
            wanted.append(name)
    if shadow_catcher.PASS in wanted:
        images[shadow_catcher.PASS] = shadow_catcher.shadow_pass(ctx, film)
    if "DRT Noise" in wanted:
        images["DRT Noise"] = np.sqrt(film.variance_of_mean())
    if "Vector" in wanted:
        render_engine.update_stats("", "DRT: Vector pass")
        images["Vector"] = vectors()
    for name in wanted:
        set_pass_pixels(layer.passes[name], bottom_up(images[name]))
        record["passes"][name] = images[name]
