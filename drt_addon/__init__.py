"""DRT: a distribution ray tracer for Blender (registration of the add-on's classes).

Submodules that need bpy are imported inside register(), so that the batch renderer can
check its arguments before paying for `import bpy`.
"""
import os
import sys

_registered = False


def _use_extension_numba_cache(bpy) -> None:
    """Point Numba's on-disk kernel cache at this extension's user folder
    (<user extensions>/.user/<repo>/drt/numba_cache): the installed extension's own folder
    may be read-only and is wiped on every update. A user's NUMBA_CACHE_DIR wins. Outside
    an extension (source checkout, legacy add-on) extension_path_user raises and nothing is
    set and engine/kernels/kernel_cache.py picks a cache folder itself.

    Must run before the tracer (and so the kernels' @kernel decorators, which pick the
    cache location) is imported. Numba reads NUMBA_CACHE_DIR once, when numba.core.config
    is first imported; if something imported numba earlier in this Blender session,
    reload_config() re-reads the NUMBA_* environment (it only re-processes it when the
    variables changed since the last read)."""
    # __package__ is "bl_ext.<repo>.drt.drt_addon"; the extension's package is its parent.
    extension = __package__.rpartition(".")[0]
    try:
        folder = bpy.utils.extension_path_user(extension, path="numba_cache", create=True)
    except (ValueError, AttributeError):  # not an extension / Blender before 4.2
        return
    if not folder:  # the folder could not be created (a read-only user directory)
        return
    os.environ.setdefault("NUMBA_CACHE_DIR", folder)
    config = sys.modules.get("numba.core.config")
    if config is not None and config.CACHE_DIR != os.environ["NUMBA_CACHE_DIR"]:
        config.reload_config()


def register():
    global _registered
    if _registered:
        return
    import bpy

    _use_extension_numba_cache(bpy)
    from . import properties, render_engine, ui
    properties.register()
    bpy.utils.register_class(render_engine.DRTRenderEngine)
    ui.register()
    _registered = True


def unregister():
    global _registered
    if not _registered:
        return
    import bpy

    from . import properties, render_engine, ui
    ui.unregister()
    bpy.utils.unregister_class(render_engine.DRTRenderEngine)
    properties.unregister()
    _registered = False
