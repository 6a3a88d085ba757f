"""View Layer > Override: the material every object renders with, and the world.

Cycles reads the material override when it collects an object's shaders: each material
slot of every object renders with the override material, and an object without slots
too. So a clay render (a grey override) keeps every object's geometry, visibility and
lamps, and only the surfaces change. Every reader of an object's materials goes through
`slot_materials`, so the mesh export asks for the UVs, tangents and colour attributes
that the override's nodes read, not those of the object's own materials.

The world override replaces the scene's World: its surface, its volume and its mist.
"""
from __future__ import annotations


def material_override(view_layer):
    """The view layer's override material, or None."""
    return getattr(view_layer, "material_override", None) if view_layer is not None else None


def slot_materials(obj, override=None) -> list:
    """The material of each of `obj`'s slots (None for an empty slot); with an override,
    the override in each slot, and one slot for an object that has none."""
    slots = getattr(obj, "material_slots", ())
    if override is not None:
        return [override] * max(len(slots), 1)
    return [slot.material for slot in slots]


def render_world(scene, view_layer):
    """The World the view layer renders with: its override, else the scene's (or None)."""
    return getattr(view_layer, "world_override", None) or scene.world
