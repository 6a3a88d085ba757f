"""What surfaces and media are made of, in the scene description: `Material` (Principled
parameters with Cycles' meanings, textures, shader programs, layers) and `Volume`
(a homogeneous medium)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

@dataclass
class Material:
    """The part of Blender's shader nodes the tracer understands, as Principled parameters
    with Cycles' meanings (see drt_addon/export/materials.py for how nodes map here).

    roughness maps to GGX alpha = roughness**2 as in Cycles. `emission` is radiance
    (colour times strength), no extra 1/pi; like Cycles' Principled BSDF it is emitted by
    the opaque part only (times `alpha` on average).

    Textures: each `*_texture` (an `engine.textures.TextureInput`, None = plain value)
    replaces the plain parameter at every hit by its value at the hit's UV; the plain value
    is then only a summary (the texture's average) for code that needs one number.

    Lobe colours (None = Principled's own rule from `base_color`):
      metal_color  the F0 of the metallic lobe (a Glossy BSDF's colour);
      metal_fresnel  'SCHLICK' (Principled's metal: Schlick's Fresnel from F0) or
                   'CONSTANT' (a Glossy BSDF: F0 at every angle, as Cycles' Glossy has no
                   Fresnel term; compiled path tracer only);
      specular_tint  Principled's Specular Tint (compiled path tracer only): the metal
                   lobe's F82-tint Fresnel (Schlick's, times the tint at about 82 degrees)
                   and the specular layer's and glass lobe's F0 times the tint (fading to
                   white at grazing angles; the glass lets 1 - F through), as in Cycles;
                   white: none;
      glass_color  the tint of each refraction through the glass lobe (Principled uses
                   sqrt(base colour); a Glass BSDF node its colour);
      glass_reflection_tint  the glass lobe's reflection times this (a Glass BSDF node's
                   colour, Cycles' reflection_tint; Principled: white).

    glossy_model: the microfacet model of the specular, metal and glass lobes: 'GGX'
    (single scattering, the default here and Blender's "GGX"), 'MULTI_GGX' (Blender's
    default "Multiscatter GGX": GGX with Cycles' energy compensation for the light the
    single-scattering lobe loses, engine/kernels/bsdf/multiscatter.py) or 'BLINN_PHONG' (the
    lecture's normalised Blinn-Phong lobe in the specular and metal lobes, with the
    exponent n = 2 / alpha^2 - 2 that matches GGX's alpha, Walter et al. 2007; glass
    stays single-scattering GGX) or 'BECKMANN' (the Beckmann distribution in the
    specular, metal and glass lobes, never compensated, as Cycles' Glossy, Glass and
    Refraction BSDF nodes offer it; compiled path tracer only).

    Layers and lobes beyond the base (compiled path tracer only; Cycles' meanings):
      coat_*      Principled's Coat: a GGX dielectric reflection (IOR coat_ior, alpha
                  coat_roughness^2) over everything else, which it dims by its albedo and
                  tints by coat_tint^(path length in the coat);
      sheen_*     Principled's Sheen (Cycles' microfiber sheen, Zeltner et al. 2022) over
                  the coat, dimming what is below by its albedo; sheen_layered False: a
                  Sheen BSDF node's, added beside the rest (weight 1, tint its colour);
      translucent_color   a Translucent BSDF (diffuse transmission), its weight included;
      hair_reflection, hair_transmission   a Hair BSDF node's Reflection and
                  Transmission colours (weight included; black: none), beside the other
                  lobes, with their _roughness (RoughnessU, RoughnessV) and _offset (the
                  node's Offset, radians; it applies on strands only, as in Cycles);
      principled_hair     a Principled Hair BSDF (engine.PrincipledHair, Chiang model),
                  beside the other lobes;
      refraction_only     the glass lobe refracts without reflecting (Refraction BSDF).

    Subsurface scattering (compiled path tracer; Cycles' random walk,
    engine/kernels/subsurface.py): subsurface_weight of the diffuse base (a Principled
    BSDF's Subsurface Weight, 1 for a Subsurface Scattering node) enters the surface with
    the base colour as its albedo and walks inside it as a medium whose mean free path
    per channel is subsurface_radius (Radius x Scale, scene units), with Henyey-Greenstein
    subsurface_anisotropy. It enters by a GGX refraction of IOR subsurface_ior and alpha
    subsurface_alpha (None: roughness^2 at the hit, Principled's rule) and leaves as a
    diffuse surface. subsurface_method: 'RANDOM_WALK' or 'RANDOM_WALK_SKIN' (Cycles' two
    random walks), or 'BURLEY' (Christensen-Burley: no walk and no entry refraction, the
    exit found by Cycles' disk sampling, engine/kernels/subsurface_disk.py).

    bump_correction: Cycles' Material > Settings > Bump Map Correction (on by default),
    for a normal bent by the shader (Normal Map, Bump): its specular lobes on the bent
    normal made a valid reflector for the view, and its diffuse light faded towards the
    smooth surface's terminator (engine.nodes.shading). Off: both on the bent normal as
    it is, the diffuse lobe only refusing light from under the smooth surface.

    alpha: coverage, Cycles' Principled Alpha or 1 - the weight of a Transparent BSDF in
    a Mix Shader. Where alpha < 1 the integrators let rays through with probability
    1 - alpha, tinted by `transparent_color` (the Transparent BSDF's colour), counted
    against the transparent bounce limit.
    """
    name: str = "default"
    base_color: tuple = (0.8, 0.8, 0.8)
    metallic: float = 0.0
    roughness: float = 0.5
    ior: float = 1.5
    transmission: float = 0.0
    specular_ior_level: float = 0.5
    emission: tuple = (0.0, 0.0, 0.0)
    alpha: float = 1.0
    metal_color: Optional[tuple] = None
    metal_fresnel: str = "SCHLICK"
    specular_tint: tuple = (1.0, 1.0, 1.0)
    glass_color: Optional[tuple] = None
    glass_reflection_tint: tuple = (1.0, 1.0, 1.0)
    transparent_color: tuple = (1.0, 1.0, 1.0)
    glossy_model: str = "GGX"
    coat_weight: float = 0.0
    coat_roughness: float = 0.03
    coat_ior: float = 1.5
    coat_tint: tuple = (1.0, 1.0, 1.0)
    sheen_weight: float = 0.0
    sheen_roughness: float = 0.5
    sheen_tint: tuple = (1.0, 1.0, 1.0)
    sheen_layered: bool = True
    translucent_color: tuple = (0.0, 0.0, 0.0)
    hair_reflection: tuple = (0.0, 0.0, 0.0)
    hair_reflection_roughness: tuple = (0.1, 1.0)
    hair_reflection_offset: float = 0.0
    hair_transmission: tuple = (0.0, 0.0, 0.0)
    hair_transmission_roughness: tuple = (0.1, 1.0)
    hair_transmission_offset: float = 0.0
    principled_hair: object = None       # an engine.PrincipledHair (None: none)
    refraction_only: bool = False
    bump_correction: bool = True
    sets_normal: bool = False            # the program's normal becomes the surface's own
    #                                      (Cycles' Set Normal, which the Displacement
    #                                      socket's bump uses): lobes are not shadowed
    #                                      against the smooth normal it bent
    subsurface_weight: float = 0.0
    subsurface_radius: tuple = (1.0, 0.2, 0.1)
    subsurface_anisotropy: float = 0.0
    # Oren-Nayar roughness of the diffuse lobe (Cycles' Diffuse BSDF Roughness, the
    # Principled BSDF's Diffuse Roughness; 0: Lambert), engine/kernels/bsdf/oren_nayar.py
    diffuse_roughness: float = 0.0
    subsurface_ior: float = 1.4
    # Anisotropic reflection of the metal and specular lobes (engine/kernels/bsdf/
    # anisotropic.py): 'NONE', 'PRINCIPLED' (the Principled and Metallic BSDFs' mapping of
    # Anisotropic to the two roughnesses) or 'GLOSSY' (the Glossy BSDF's Anisotropy);
    # the tangent is per hit, the program's "tangent" output (none: isotropic)
    anisotropy_kind: str = "NONE"
    anisotropy: float = 0.0
    anisotropic_rotation: float = 0.0    # in turns, about the normal
    # Principled's Thin Film (engine/kernels/bsdf/thin_film.py) on the specular layer, the
    # metal and the glass: thickness in nm (0: none) and the film's IOR
    thin_film_thickness: float = 0.0
    thin_film_ior: float = 1.33
    subsurface_alpha: Optional[float] = None
    subsurface_method: str = "RANDOM_WALK"
    base_color_texture: Optional[object] = None
    metallic_texture: Optional[object] = None
    roughness_texture: Optional[object] = None
    emission_texture: Optional[object] = None
    alpha_texture: Optional[object] = None
    shader: Optional[object] = None
    mix: Optional[tuple] = None
    volume: Optional[object] = None      # Volume: the medium inside its meshes
    surface: bool = True                 # False: no surface shader, a volume's boundary
    pass_index: int = 0                  # Blender's material Pass Index (IndexMA pass)
    emission_sampling: str = "FRONT_BACK"  # the sides next-event estimation samples of
    #                                       its emissive triangles: 'NONE', 'FRONT', 'BACK'
    #                                       or 'FRONT_BACK' (Material > Settings >
    #                                       Emission Sampling; engine.mesh_lights)
    emission_under_layers: bool = True   # the emission lies under the coat and sheen,
    #                                      which dim it at the angle it is seen from (a
    #                                      Principled BSDF's, as in Cycles' svm/closure.h;
    #                                      engine.kernels.bsdf.layered_emission); False:
    #                                      an Emission shader's, which nothing dims
    holdout: bool = False                # a Holdout shader: a hole in the alpha where the
    #                                      camera sees it, black to every other ray
    holdout_weight: float = 0.0          # a Holdout shader's share of the opaque part (a
    #                                      Mix Shader with a Holdout): that share of the
    #                                      hits is a hole for the camera, black to others
    aovs: Optional[object] = None        # engine.shader_aovs.ShaderAOVs: its AOV Output
    #                                      nodes, for the view layer's AOV passes
    displacement: Optional[object] = None    # engine.displacement.Displacement: moves the
    #                                      vertices of its meshes at export (true displacement)

    TEXTURED = ("base_color", "metallic", "roughness", "emission", "alpha")

    # shader: an engine.nodes.program.ShaderProgram whose outputs (OUTPUTS) replace the
    # parameters they name at every hit (their plain values above are then summaries);
    # it takes precedence over a *_texture of the same parameter.
    # mix: (Material, Material), a Mix Shader whose Fac varies per hit (the program's
    # "mix" output): each hit is shaded by one of the two, the second with probability
    # Fac (an unbiased estimate of Cycles' weighted sum). The parent's own parameters
    # are the mixture at the Fac's average (its summary); its alpha and emission are
    # the hit's.

    def textures(self) -> dict:
        """{parameter name: TextureInput} of the textured parameters."""
        return {k: getattr(self, k + "_texture") for k in self.TEXTURED
                if getattr(self, k + "_texture") is not None}

    def driven(self, name) -> bool:
        """Whether parameter `name` varies per hit (a texture or a program output)."""
        return (getattr(self, name + "_texture", None) is not None
                or (self.shader is not None and name in self.shader.outputs))

    def is_emissive(self) -> bool:
        return max(self.emission) > 0.0 or self.driven("emission")

    def uses_uv(self) -> bool:
        return bool(self.textures()) or self.shader is not None


@dataclass
class Volume:
    """A homogeneous medium, with Cycles' meaning of its coefficients (per metre, RGB):
    absorption sigma_a and scattering sigma_s (extinction sigma_t = sigma_a + sigma_s),
    Henyey-Greenstein `anisotropy` g of the scattering (-1 back, 0 isotropic, 1 forward)
    and `emission`, radiance emitted per metre of path. A material's volume fills the
    inside of its (closed) meshes; the world's fills all space outside them. See
    engine.kernels.volume.

    A material whose shader program has the outputs volume_absorption,
    volume_scattering and volume_emission (engine.nodes.program.OUTPUTS) has a
    heterogeneous volume: the program, run at each point inside the medium, gives its
    coefficients there (engine.kernels.medium_density), and these fields are then
    summaries (its averages).

    `sampling`: how the direct light of its segments picks distances, Cycles' Volume >
    Sampling Method: 'DISTANCE' (by transmittance), 'EQUIANGULAR' (towards the lights'
    positions) or 'MULTIPLE_IMPORTANCE' (both; engine.kernels.medium_vertex)."""
    absorption: tuple = (0.0, 0.0, 0.0)
    scattering: tuple = (0.0, 0.0, 0.0)
    anisotropy: float = 0.0
    emission: tuple = (0.0, 0.0, 0.0)
    sampling: str = "MULTIPLE_IMPORTANCE"

    def is_empty(self) -> bool:
        return not (any(v > 0 for v in self.absorption) or any(v > 0 for v in self.scattering)
                    or any(v > 0 for v in self.emission))
