"""The material parameter row the Principled kernels read: column constants and
`pack_materials`, which turns a `MaterialTable` into one float64 row per material.

A row holds each material's plain (un-textured) values; where a material is textured the
integrator overwrites P_BASE / P_METALLIC / P_ROUGHNESS in a per-hit copy of the row, and
Filter Glossy may set P_FILTER_ALPHA there (0 in the packed rows), so `principled.setup`
reads everything from the row and nothing from the table.
"""
from __future__ import annotations

import numpy as np

P_BASE = 0               # 3 columns: base colour r, g, b
P_METALLIC = 3
P_ROUGHNESS = 4
P_IOR = 5
P_TRANSMISSION = 6
P_SPEC_LEVEL = 7         # specular_ior_level
P_METAL_COLOR = 8        # 3 columns: the metal lobe's F0 when P_HAS_METAL_COLOR is 1
P_HAS_METAL_COLOR = 11   # 0 / 1
P_GLASS_COLOR = 12       # 3 columns: the refraction tint when P_HAS_GLASS_COLOR is 1
P_HAS_GLASS_COLOR = 15   # 0 / 1
P_GLOSSY_MODEL = 16      # GLOSSY_GGX, GLOSSY_BLINN_PHONG, GLOSSY_MULTI_GGX or GLOSSY_BECKMANN
P_FILTER_ALPHA = 17      # per hit, 0 in the material rows: Filter Glossy's smallest GGX
#                          alpha for the microfacet lobes (see principled.setup)
# The lobes beyond Principled's base (layers.py): read only where P_LAYERS is 1
P_LAYERS = 18            # 0 / 1: any of the columns below is in use
P_COAT_WEIGHT = 19
P_COAT_ROUGHNESS = 20
P_COAT_IOR = 21
P_COAT_TINT = 22         # 3 columns
P_SHEEN_WEIGHT = 25
P_SHEEN_ROUGHNESS = 26
P_SHEEN_TINT = 27        # 3 columns
P_TRANSLUCENT = 30       # 3 columns: the Translucent BSDF's colour (weight included)
P_REFRACT_ONLY = 33      # 0 / 1: the glass lobe refracts only (Refraction BSDF)
P_SHEEN_LAYERED = 34     # 0 / 1: the sheen dims the lobes below it (Principled's)
P_BUMP_CORRECTION = 35   # 0 / 1: Cycles' Bump Map Correction for a bent normal
#                          (engine.nodes.shading.program_normal, bump_shadowing)
P_METAL_CONSTANT = 36    # 0 / 1: the metal lobe reflects its F0 at every angle (a
#                          Glossy BSDF, Cycles' Fresnel-less closure), not Schlick's
P_SPEC_TINT = 37         # 3 columns: Specular Tint, the metal lobe's F82 tint (1: none)
# Subsurface scattering (subsurface_lobe.py; engine/kernels/subsurface.py walks it)
P_SSS_WEIGHT = 40        # the share of the diffuse base that scatters below the surface
P_SSS_RADIUS = 41        # 3 columns: mean free path per channel (Radius x Scale), scene units
P_SSS_ANISOTROPY = 44    # Henyey-Greenstein g inside
P_SSS_IOR = 45           # the entry's refraction IOR
P_SSS_ALPHA = 46         # the entry's GGX alpha; < 0: the hit's roughness^2 (Principled)
P_SSS_METHOD = 47        # SSS_RANDOM_WALK, SSS_SKIN (Random Walk (Skin): Cycles' other
#                          radius and entry) or SSS_BURLEY (Christensen-Burley's disk)
P_SETS_NORMAL = 48       # 0 / 1: the program's normal becomes the surface's (Cycles' Set
#                          Normal: the Displacement socket's bump), so lobes are not
#                          shadowed against the smooth normal it bends
P_HOLDOUT = 49           # the share of hits that are a Holdout shader (a hole for the
#                          camera, black to other rays); 1 for a Holdout alone
# Cycles' Hair BSDF node (hair.py), beside the other lobes: read only where P_LAYERS is 1
P_HAIR = 50              # 0 / 1: the integrator writes the per-hit hair columns
#                          (engine.kernels.hair_tangent)
P_HAIR_R = 51            # 3 columns: the Reflection component's colour (weight included)
P_HAIR_R_OFFSET = 54     # its Offset as Cycles keeps it (minus the node's), radians
P_HAIR_R_ROUGH = 55      # 2 columns: its RoughnessU, RoughnessV
P_HAIR_TT = 57           # 3 columns: the Transmission component's colour
P_HAIR_TT_OFFSET = 60
P_HAIR_TT_ROUGH = 61     # 2 columns
P_HAIR_T = 63            # per hit, 3 columns: the fibre's tangent in the shading frame
#                          (a strand's direction, a triangle's second edge: Cycles' dPdv)
P_HAIR_CURVE = 66        # per hit, 0 / 1: the hit is on a strand (the Offset applies)
# The Principled Hair BSDF, Chiang model (hair_chiang.py): read only where P_LAYERS is 1
P_CHIANG = 67            # 3 columns: the closure's weight colour (black: none)
P_CHIANG_MODE = 70       # hair_chiang.ABSORPTION, MELANIN or COLOR
P_CHIANG_COLOR = 71      # 3 columns: Absorption Coefficient, Tint or Color, by the mode
P_CHIANG_MELANIN = 74    # 2 columns: Melanin, Melanin Redness
P_CHIANG_ROUGH = 76      # 3 columns: Roughness, Radial Roughness, Coat
P_CHIANG_IOR = 79
P_CHIANG_OFFSET = 80     # the node's Offset, radians
P_CHIANG_RANDOM = 81     # 3 columns: Random Color, Random Roughness, Random (per hit: a
#                          strand's own Random where P_CHIANG_OWN_RANDOM is 1)
P_CHIANG_OWN_RANDOM = 84  # 0 / 1: Random is unlinked (Cycles reads the strand's)
P_CHIANG_T = 85          # per hit, 3 columns: the fibre's tangent in the shading frame
#                          (Cycles' dPdu: a strand's direction, a triangle's p1 - p0)
P_CHIANG_NG = 88         # per hit, 3 columns: the geometric normal in the shading frame
#                          (either side; for h, where across the fibre the view meets it)
P_DIFFUSE_ROUGHNESS = 91  # Oren-Nayar sigma of the diffuse lobe, 0 to 1 (0: Lambert)
P_GLASS_REFLECT = 92     # 3 columns: the glass lobe's reflection tint (a Glass or Refraction
#                          BSDF's Color, as Cycles' reflection_tint; white for Principled)
# Anisotropic reflection (anisotropic.py): the metal and specular lobes
P_ANISO_KIND = 95        # ANISO_NONE, ANISO_PRINCIPLED (Principled, Metallic) or ANISO_GLOSSY:
#                          how Anisotropic / Anisotropy maps to the two alphas
P_ANISO = 96             # the node's Anisotropic (Principled, Metallic) or Anisotropy (Glossy)
P_ANISO_ROT = 97         # its Rotation, in turns
P_TANGENT = 98           # per hit, 3 columns: the tangent (the node's Tangent input), local
#                          to the shading frame (0: none, the lobe stays isotropic)
P_COAT_N = 101           # per hit, 3 columns: the coat's normal in the shading frame (the
#                          surface's own, or its Coat Normal, where a program bends the
#                          frame: Cycles' coat keeps it); 0: the frame's
P_THIN_FILM = 104        # Thin Film Thickness (nm; at most thin_film.CUTOFF: none)
P_THIN_FILM_IOR = 105    # Thin Film IOR
P_EMISSION_DIM = 106     # the row of L[EMIT_DIM] that dims its emission (a Principled's
#                          under its coat and sheen: layered_emission.py), or -1: none
NPARAM = 107

GLOSSY_GGX = 0
GLOSSY_BLINN_PHONG = 1
GLOSSY_MULTI_GGX = 2     # GGX with Cycles' multiple-scattering compensation
GLOSSY_BECKMANN = 3      # Beckmann (beckmann.py), never compensated, as in Cycles
ANISO_NONE = 0           # P_ANISO_KIND
ANISO_PRINCIPLED = 1
ANISO_GLOSSY = 2
SSS_RANDOM_WALK = 0      # P_SSS_METHOD: Cycles' subsurface methods
SSS_SKIN = 1
SSS_BURLEY = 2


def pack_materials(table) -> np.ndarray:
    """(M, NPARAM) float64: the plain value of every parameter of every material of the
    `engine.bsdf.material_table.MaterialTable` `table`."""
    m = len(table.metallic)
    rows = np.zeros((m, NPARAM), dtype=np.float64)
    rows[:, P_BASE:P_BASE + 3] = table.base_color
    rows[:, P_METALLIC] = table.metallic
    rows[:, P_ROUGHNESS] = table.roughness
    rows[:, P_IOR] = table.ior
    rows[:, P_TRANSMISSION] = table.transmission
    rows[:, P_SPEC_LEVEL] = table.specular_ior_level
    rows[:, P_METAL_COLOR:P_METAL_COLOR + 3] = table.metal_color
    rows[:, P_HAS_METAL_COLOR] = table.has_metal_color
    rows[:, P_GLASS_COLOR:P_GLASS_COLOR + 3] = table.glass_color
    rows[:, P_HAS_GLASS_COLOR] = table.has_glass_color
    rows[:, P_GLASS_REFLECT:P_GLASS_REFLECT + 3] = table.glass_reflection_tint
    rows[:, P_GLOSSY_MODEL] = np.select(
        [table.blinn_phong, table.multiscatter, table.beckmann],
        [GLOSSY_BLINN_PHONG, GLOSSY_MULTI_GGX, GLOSSY_BECKMANN], GLOSSY_GGX)
    rows[:, P_COAT_WEIGHT] = table.coat_weight
    rows[:, P_COAT_ROUGHNESS] = table.coat_roughness
    rows[:, P_COAT_IOR] = table.coat_ior
    rows[:, P_COAT_TINT:P_COAT_TINT + 3] = table.coat_tint
    rows[:, P_SHEEN_WEIGHT] = table.sheen_weight
    rows[:, P_SHEEN_ROUGHNESS] = table.sheen_roughness
    rows[:, P_SHEEN_TINT:P_SHEEN_TINT + 3] = table.sheen_tint
    rows[:, P_TRANSLUCENT:P_TRANSLUCENT + 3] = table.translucent_color
    rows[:, P_REFRACT_ONLY] = table.refraction_only
    rows[:, P_SHEEN_LAYERED] = table.sheen_layered
    rows[:, P_BUMP_CORRECTION] = table.bump_correction
    rows[:, P_SETS_NORMAL] = table.sets_normal
    rows[:, P_HOLDOUT] = table.holdout_weight
    rows[:, P_LAYERS] = table.layered
    dimmed = np.asarray(getattr(table, "emission_dimmed", np.zeros(m, bool)), bool)
    rows[:, P_EMISSION_DIM] = np.where(dimmed, np.cumsum(dimmed) - 1, -1)
    rows[:, P_SSS_WEIGHT] = table.subsurface_weight
    rows[:, P_SSS_RADIUS:P_SSS_RADIUS + 3] = table.subsurface_radius
    rows[:, P_SSS_ANISOTROPY] = table.subsurface_anisotropy
    rows[:, P_SSS_IOR] = table.subsurface_ior
    rows[:, P_SSS_ALPHA] = table.subsurface_alpha
    rows[:, P_SSS_METHOD] = table.subsurface_method_code
    rows[:, P_METAL_CONSTANT] = table.metal_constant
    rows[:, P_SPEC_TINT:P_SPEC_TINT + 3] = table.specular_tint
    rows[:, P_HAIR] = table.hair
    rows[:, P_DIFFUSE_ROUGHNESS] = table.diffuse_roughness
    rows[:, P_HAIR_R:P_HAIR_R + 3] = table.hair_reflection
    rows[:, P_HAIR_R_OFFSET] = -table.hair_reflection_offset
    rows[:, P_HAIR_R_ROUGH:P_HAIR_R_ROUGH + 2] = table.hair_reflection_roughness
    rows[:, P_HAIR_TT:P_HAIR_TT + 3] = table.hair_transmission
    rows[:, P_HAIR_TT_OFFSET] = -table.hair_transmission_offset
    rows[:, P_HAIR_TT_ROUGH:P_HAIR_TT_ROUGH + 2] = table.hair_transmission_roughness
    rows[:, P_CHIANG:P_CHIANG + 3] = table.chiang_weight
    rows[:, P_CHIANG_MODE] = table.chiang_mode
    rows[:, P_CHIANG_COLOR:P_CHIANG_COLOR + 3] = table.chiang_colour
    rows[:, P_CHIANG_MELANIN:P_CHIANG_MELANIN + 2] = table.chiang_melanin
    rows[:, P_CHIANG_ROUGH:P_CHIANG_ROUGH + 3] = table.chiang_roughness
    rows[:, P_CHIANG_IOR] = table.chiang_ior
    rows[:, P_CHIANG_OFFSET] = table.chiang_offset
    rows[:, P_CHIANG_RANDOM:P_CHIANG_RANDOM + 3] = table.chiang_random
    rows[:, P_CHIANG_OWN_RANDOM] = table.chiang_own_random
    rows[:, P_ANISO_KIND] = table.anisotropy_kind
    rows[:, P_ANISO] = table.anisotropy
    rows[:, P_ANISO_ROT] = table.anisotropic_rotation
    rows[:, P_THIN_FILM] = table.thin_film_thickness
    rows[:, P_THIN_FILM_IOR] = table.thin_film_ior
    return rows
