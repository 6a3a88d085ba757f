"""Shims for Blender before 4.2, where DRT loads as a legacy add-on (Debian's Blender 3.4
package; docs/batch.md). Each is guarded by `bpy.app.version`, so Blender 4.2+ (and the
bpy module) never takes them, or by a fact of the running process that is false there.
"""
from __future__ import annotations

import bpy

# Principled BSDF sockets renamed in Blender 4.0: the 4.0+ name -> the name before.
# (3.x's Specular, Clearcoat and Sheen are read as 4.0's Specular IOR Level, Coat Weight
# and Sheen Weight.) Sheen Tint, a float before 4.0 (a colour since), reads as absent: 4.0's
# default, white.
_PRINCIPLED_BEFORE_4_0 = {
    "Subsurface Weight": "Subsurface", "Specular IOR Level": "Specular",
    "Transmission Weight": "Transmission", "Coat Weight": "Clearcoat",
    "Coat Roughness": "Clearcoat Roughness", "Coat Normal": "Clearcoat Normal",
    "Sheen Weight": "Sheen", "Emission Color": "Emission",
}
_PRINCIPLED_RETYPED_IN_4_0 = {"Sheen Tint"}
RENAMED_SOCKETS = bpy.app.version < (4, 0, 0)
# Mesh corner normals are computed on demand since 4.1; before, calc_normals_split() fills
# them (loop_triangles.split_normals reads zeros without it).
SPLIT_NORMALS_ON_DEMAND = bpy.app.version >= (4, 1, 0)


def node_input(node, name: str):
    """`node.inputs.get(name)` by the socket's Blender 4.0+ name, in any Blender."""
    if not (RENAMED_SOCKETS and node.bl_idname == "ShaderNodeBsdfPrincipled"):
        return node.inputs.get(name)
    if name in _PRINCIPLED_RETYPED_IN_4_0:
        return None
    return node.inputs.get(_PRINCIPLED_BEFORE_4_0.get(name, name))


def prepare_corner_normals(mesh) -> None:
    """Make `mesh.loop_triangles.split_normals` valid (a no-op from Blender 4.1)."""
    if not SPLIT_NORMALS_ON_DEMAND:
        mesh.calc_normals_split()


# The index, environment and AO passes' names: Blender 5.0 calls Cycles' IndexOB, IndexMA,
# Env and AO passes "Object Index", "Material Index", "Environment" and "Ambient
# Occlusion" (the compositor's Render Layers sockets follow the names).
OBJECT_INDEX_PASS, MATERIAL_INDEX_PASS, ENVIRONMENT_PASS, AO_PASS = (
    ("Object Index", "Material Index", "Environment", "Ambient Occlusion")
    if bpy.app.version >= (5, 0, 0) else ("IndexOB", "IndexMA", "Env", "AO"))

# Blender 4.2+ takes a render pass's pixels as one flat buffer; 3.4 wants one row per pixel
# (pixels, channels). Which release between changed it is not known here, so before 4.2 the
# flat form is tried first.
FLAT_PASS_PIXELS = bpy.app.version >= (4, 2, 0)


def set_pass_pixels(render_pass, pixels) -> None:
    """`render_pass.rect.foreach_set` of a flat float32 buffer, in any Blender."""
    if FLAT_PASS_PIXELS:
        render_pass.rect.foreach_set(pixels)
        return
    try:
        render_pass.rect.foreach_set(pixels)
    except TypeError:
        render_pass.rect.foreach_set(pixels.reshape(-1, render_pass.channels))
