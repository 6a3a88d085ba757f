"""Ray visibility, as Blender's Object Properties > Visibility > Ray Visibility sets it for
objects and lamps: which kinds of rays see a surface or a lamp.

A bit per ray kind; a mesh or a lamp carries the mask of the kinds that see it:
- CAMERA: rays from the camera (and their continuations through transparent layers and
  through surfaces invisible to the camera);
- DIFFUSE, GLOSSY, TRANSMISSION: rays leaving a surface by a lobe of that kind (the
  BSDF's diffuse, reflection and refraction lobes; a smooth mirror counts as glossy);
- SHADOW: shadow rays of next-event estimation. An object without it casts no shadow;
  a lamp without it (Blender's light "Cast Shadow" off) lights through everything.

Meaning, as in Cycles:
- a ray skips every surface whose object lacks the ray's bit (it is not there for it),
  and every lamp that lacks it: it goes on behind them;
- next-event estimation towards a lamp (or emissive object) lacking DIFFUSE, GLOSSY or
  TRANSMISSION evaluates the BSDF without the lobes of those kinds, and its multiple
  importance sampling weight counts only the lobes that could have hit it.
"""
from __future__ import annotations

CAMERA = 1
DIFFUSE = 2
GLOSSY = 4
TRANSMISSION = 8
SHADOW = 16
ALL = CAMERA | DIFFUSE | GLOSSY | TRANSMISSION | SHADOW

# the bit of a ray leaving by a lobe of kind 0 (diffuse), 1 (glossy), 2 (transmission)
LOBE_BITS = (DIFFUSE, GLOSSY, TRANSMISSION)


def from_flags(camera=True, diffuse=True, glossy=True, transmission=True,
               shadow=True) -> int:
    """The mask of Blender's five check boxes."""
    return ((CAMERA if camera else 0) | (DIFFUSE if diffuse else 0)
            | (GLOSSY if glossy else 0) | (TRANSMISSION if transmission else 0)
            | (SHADOW if shadow else 0))


def describe(mask: int) -> str:
    """'camera, glossy' style list of the kinds a mask lacks (for warnings and reprs)."""
    names = ("camera", "diffuse", "glossy", "transmission", "shadow")
    return ", ".join(n for i, n in enumerate(names) if not mask & (1 << i))
