"""The DRT Blender extension's package root (the folder that holds blender_manifest.toml).

Blender 4.2+ installs it as an extension (blender_manifest.toml) and ignores `bl_info`.
Older Blender (Debian's 3.4 package, for example) loads the same folder as a legacy
add-on from `<scripts>/addons/drt`, which needs `bl_info` (docs/batch.md).
"""
bl_info = {
    "name": "DRT",
    "description": "Distribution ray tracer with readable Monte Carlo estimators",
    "author": "DRT developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "category": "Render",
}

from .drt_addon import register, unregister  # noqa: E402,F401
