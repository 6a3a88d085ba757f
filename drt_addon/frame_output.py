"""Writing a rendered frame to its file: the format, and never a partial file.

Formats: the extension of `-o` decides (PNG, OpenEXR, JPEG, TIFF); without `-o`, or with
an `-o` that has no extension, the file's own output format is used when it is a still
format, and PNG when the file's output is a video (with a message saying so). PNG, JPEG
and TIFF go through the scene's colour management (view transform, look, exposure), EXR
is scene-linear; everything else about the format (bit depth, compression, multilayer
EXR with the enabled passes) is the file's own setting.

Every file is first written under a temporary name in the same folder and then renamed
onto its final name (`os.replace`, atomic on one file system), so an interrupted job
leaves either the whole old file, the whole new one, or a `.drt-tmp` file to ignore,
never a truncated frame under the final name (which `--skip-existing` would trust).
"""
from __future__ import annotations

import os

import numpy as np

FORMATS = {".png": "PNG", ".exr": "OPEN_EXR", ".jpg": "JPEG", ".jpeg": "JPEG",
           ".tif": "TIFF", ".tiff": "TIFF"}
# Blender's still formats and the extension Blender gives each.
STILL_EXTENSIONS = {
    "PNG": ".png", "JPEG": ".jpg", "JPEG2000": ".jp2", "TARGA": ".tga", "TARGA_RAW": ".tga",
    "BMP": ".bmp", "IRIS": ".rgb", "CINEON": ".cin", "DPX": ".dpx", "OPEN_EXR": ".exr",
    "OPEN_EXR_MULTILAYER": ".exr", "HDR": ".hdr", "TIFF": ".tif", "WEBP": ".webp",
}
TEMP_MARK = ".drt-tmp"


def is_still(image_settings) -> bool:
    """Whether the file's output is a still image format (not FFMPEG or an AVI)."""
    media = getattr(image_settings, "media_type", "IMAGE")
    return media in ("IMAGE", "MULTI_LAYER_IMAGE") and \
        image_settings.file_format in STILL_EXTENSIONS


def choose_format(image_settings, extension: str | None) -> tuple[str, str, str | None]:
    """(file_format, extension, note) for frames written with these settings and an `-o`
    extension (None or "" when `-o` has none or is not given). note is a message for
    the user when the file's own output cannot be used (a video)."""
    own = image_settings.file_format
    if extension:
        fmt = FORMATS[extension.lower()]
        if fmt == "OPEN_EXR" and own == "OPEN_EXR_MULTILAYER":
            fmt = own                  # the file asks for its passes in one EXR: keep it
        return fmt, extension, None
    if is_still(image_settings):
        return own, STILL_EXTENSIONS[own], None
    return "PNG", ".png", (f"the file's output is a video ({own}); DRT renders frames, so "
                           "it writes PNG images instead (encode them afterwards, or pass "
                           "-o with .exr)")


def set_still_format(settings, file_format: str) -> None:
    """Point the scene's output settings (in memory only; the file on disk is not
    written) at a still image format. Since Blender 5.0 a file whose output is a video
    has `media_type` VIDEO, which offers only FFMPEG as file format (and MULTI_LAYER_IMAGE
    only multilayer EXR): switch the media type first."""
    media = "MULTI_LAYER_IMAGE" if file_format == "OPEN_EXR_MULTILAYER" else "IMAGE"
    if getattr(settings, "media_type", media) != media:
        settings.media_type = media
    if settings.file_format != file_format:
        settings.file_format = file_format
        if file_format == "OPEN_EXR":
            settings.color_depth = "32"


def temp_path(final_path: str) -> str:
    """A name in the final file's folder, keeping its extension (Blender writes a path as
    given) and unique to this process."""
    folder, name = os.path.split(final_path)
    stem, ext = os.path.splitext(name)
    return os.path.join(folder, f".{stem}{TEMP_MARK}{os.getpid()}{ext}")


def save_atomically(save, final_path: str) -> None:
    """Call save(temporary path), then rename the written file onto final_path. On any
    failure the temporary file is removed and the error re-raised."""
    os.makedirs(os.path.dirname(os.path.abspath(final_path)), exist_ok=True)
    tmp = temp_path(final_path)
    try:
        save(tmp)
        if not os.path.exists(tmp):
            raise RuntimeError("Blender wrote no file")
        os.replace(tmp, final_path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def save_render_result(bpy, scene, final_path: str) -> None:
    """Blender's Render Result (every pass, the compositor's output) to final_path in the
    scene's output format."""
    image = bpy.data.images.get("Render Result")
    if image is None:
        raise RuntimeError("Blender produced no image")
    save_atomically(lambda tmp: image.save_render(filepath=tmp, scene=scene), final_path)


def frame_rgba(mean: np.ndarray, alpha: np.ndarray, region, crop: bool) -> np.ndarray:
    """A film's (h, w, 3) premultiplied mean and (h, w) alpha, top row first, as the
    bottom-up RGBA float32 image Blender's Render Result would hold: the render border's
    rectangle placed in the transparent full frame unless cropped to it."""
    h, w = alpha.shape
    rect = np.empty((h, w, 4), dtype=np.float32)
    rect[..., :3] = mean[::-1]
    rect[..., 3] = alpha[::-1]
    if crop or region.is_full_frame:
        return rect
    full = np.zeros((region.full_height, region.full_width, 4), dtype=np.float32)
    full[region.y:region.y + h, region.x:region.x + w] = rect
    return full


def save_pixels(bpy, scene, rgba: np.ndarray, final_path: str) -> None:
    """A bottom-up (h, w, 4) scene-linear premultiplied float image written as Blender
    writes a render (save_render: the scene's colour management and output format), so
    the file matches the one the RenderEngine's Render Result gives for the same pixels."""
    h, w, _ = rgba.shape
    image = bpy.data.images.new("DRT batch frame", w, h, alpha=True, float_buffer=True)
    try:
        image.pixels.foreach_set(np.ascontiguousarray(rgba, dtype=np.float32).reshape(-1))
        save_atomically(lambda tmp: image.save_render(filepath=tmp, scene=scene), final_path)
    finally:
        bpy.data.images.remove(image)
