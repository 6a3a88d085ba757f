"""What the scene holds that DRT does not render yet, named once in Blender's report so
that nothing is dropped silently: point clouds and the grids of a smoke simulation's
domain. The rest of the scene renders. (Volume objects render: export.volume_objects;
hair: export.hair.)"""
from __future__ import annotations

# object types DRT cannot draw yet, as their kind in the warning
LEFT_OUT_TYPES = {"POINTCLOUD": "point clouds"}


class LeftOut:
    """Collects what an export leaves out: kind -> object names, in the order found."""

    def __init__(self):
        self.found: dict[str, list[str]] = {}

    def note(self, kind: str, name: str) -> None:
        names = self.found.setdefault(kind, [])
        if name not in names:
            names.append(name)

    def note_object(self, obj) -> None:
        """An object of one of LEFT_OUT_TYPES."""
        self.note(LEFT_OUT_TYPES[obj.type], obj.name)

    def note_smoke_domain(self, obj) -> None:
        """A mesh that is a Fluid modifier's gas domain (a smoke or fire simulation):
        Cycles renders its cached grids; DRT does not read them yet, so its volume
        would be a uniform fog in the domain's box."""
        for mod in getattr(obj, "modifiers", ()):
            if (mod.type == "FLUID" and mod.show_render and mod.fluid_type == "DOMAIN"
                    and getattr(mod.domain_settings, "domain_type", "") == "GAS"):
                self.note("smoke simulation grids (the domain renders its material "
                          "without them)", obj.name)

    def message(self) -> str | None:
        """One warning naming everything left out, or None."""
        if not self.found:
            return None
        parts = [f"{kind} ({', '.join(repr(n) for n in names)})"
                 for kind, names in self.found.items()]
        return ("DRT: not rendered yet, left out of the image: " + "; ".join(parts)
                + ". The rest of the scene renders.")
