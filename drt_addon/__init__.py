"""DRT: a distribution ray tracer for Blender (registration of the add-on's classes).

Submodules that need bpy are imported inside register(), so that the batch renderer can
check its arguments before paying for `import bpy`.
"""
_registered = False


def register():
    global _registered
    if _registered:
        return
    import bpy

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
