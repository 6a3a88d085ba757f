"""DRT's tracer: distribution ray tracing and path tracing on NumPy and Embree.

Never imports bpy. The input is an `engine.scene.Scene`, the output an `engine.film.Film`.
"""
from .curves import HairCurves
from .film import Film
from .principled_hair import PrincipledHair
from .render import RenderContext, render
from .render_stats import RenderStats
from .scene import (AreaLight, Camera, Instances, Material, ObjectInfo, PointLight, Scene,
                    SunLight, TriangleMesh, Volume, World)
from .settings import RenderSettings
from . import visibility  # noqa: E402  (the Ray Visibility bits, for exporters)
from . import sky_texture  # noqa: E402  (Blender's Sky Texture node, for exporters)

__all__ = ["AreaLight", "Camera", "Film", "HairCurves", "Instances", "Material", "ObjectInfo",
           "PointLight", "PrincipledHair", "RenderContext", "RenderSettings", "RenderStats", "Scene", "SunLight",
           "TriangleMesh", "Volume", "World", "render"]
