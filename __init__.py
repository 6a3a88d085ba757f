"""The DRT Blender extension's package root (the folder that holds blender_manifest.toml)."""
from .drt_addon import register, unregister  # noqa: F401
