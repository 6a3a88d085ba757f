"""The scene description: the whole contract between the Blender exporter and the tracer.

Plain NumPy arrays and small dataclasses, nothing else, so the tracer is tested without
Blender and the exporter is tested without tracing. Units and conventions follow Blender:
metres, right-handed world with +Z up, cameras looking down their local -Z with +Y up,
colours in scene-linear Rec.709, light strengths in Blender's watts (converted to radiance
in `engine.lights`, which is the only place that knows Cycles' unit conventions).

Precision: geometry is stored in float64 so that the exporter never loses bits; the
acceleration structure rounds to float32 (Embree's only format) and hit points are rebuilt
in float64 from barycentrics (see `engine.surface`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np


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
                   sqrt(base colour); a Glass BSDF node its colour).

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
    random walks).

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


@dataclass
class ObjectInfo:
    """What shader nodes read of the object a mesh instance belongs to: its transform at
    the frame (object coordinates, the Texture Coordinate node's Normal), Object Info's
    Color, Random and pass index, and the texture space Generated coordinates map to
    [0, 1]^3 (centre and half-size, in object space; Blender's auto texture space is
    the mesh's bounding box)."""
    matrix_world: np.ndarray
    color: tuple = (1.0, 1.0, 1.0)
    random: float = 0.0
    pass_index: int = 0
    texspace_location: tuple = (0.0, 0.0, 0.0)
    texspace_size: tuple = (1.0, 1.0, 1.0)


@dataclass
class Instances:
    """The K places of one mesh that appears more than once (Blender's collection
    instances, particles, Geometry Nodes instances, linked duplicates): the mesh is kept
    once, in object space, and Embree traces it as K instances, so memory grows with K,
    not with K times its triangles (engine.instancing).

    matrices: (K, 4, 4) float64 object -> world, one per place.
    colors, randoms, pass_indices: what Object Info reads of each place ((K, 3), (K,),
    (K,)); None: white, 0 and 0.
    names, name_ids: the (object name, asset name) pairs of the places (Cryptomatte,
    engine.cryptomatte) and each place's pair (K,) int; None: the mesh's own names."""
    matrices: np.ndarray
    colors: Optional[np.ndarray] = None
    randoms: Optional[np.ndarray] = None
    pass_indices: Optional[np.ndarray] = None
    names: Optional[tuple] = None
    name_ids: Optional[np.ndarray] = None

    def __post_init__(self):
        m = np.ascontiguousarray(self.matrices, dtype=np.float64)
        if m.ndim != 3 or m.shape[1:] != (4, 4):
            raise ValueError(f"instance matrices must be (K, 4, 4), got {m.shape}")
        if not np.all(np.isfinite(m[:, :3, :4])):
            raise ValueError("an instance's matrix is not finite (NaN or Inf)")
        self.matrices = m
        k = len(m)
        self.colors = (np.ones((k, 3)) if self.colors is None
                       else np.asarray(self.colors, np.float64).reshape(k, -1)[:, :3])
        self.randoms = (np.zeros(k) if self.randoms is None
                        else np.asarray(self.randoms, np.float64).reshape(k))
        self.pass_indices = (np.zeros(k) if self.pass_indices is None
                             else np.asarray(self.pass_indices, np.float64).reshape(k))
        if self.name_ids is not None:
            self.name_ids = np.asarray(self.name_ids, np.int64).reshape(k)
            if self.names is None or (k and not 0 <= self.name_ids.min() <= self.name_ids.max()
                                      < len(self.names)):
                raise ValueError("instance name ids must index `names`")

    def __len__(self):
        return len(self.matrices)


@dataclass
class TriangleMesh:
    """One evaluated mesh in world space, or in object space placed K times when
    `instances` is set.

    positions: (V, 3) float64 vertex positions.
    triangles: (T, 3) int32 vertex indices.
    material_indices: (T,) int32 indices into `Scene.materials`.
    corner_normals: optional (T, 3, 3) float32 shading normals per triangle corner
        (Blender's split normals); None means flat shading.
    uvs: optional (T, 3, 2) float32 texture coordinates per corner.
    tangents: optional (T, 3, 4) float32 tangent space per corner (world-space tangent
        and bitangent sign, Blender's MikkTSpace), for tangent-space Normal Maps.
    motion: None for a static mesh (positions in world space); an
        `engine.motion.RigidMotion` (positions then in OBJECT space, placed in the world by
        the motion's transform at each ray's time); or an `engine.motion.DeformMotion`
        (vertex positions over the shutter in world space; `positions` is ignored).
    """
    name: str
    positions: np.ndarray
    triangles: np.ndarray
    material_indices: np.ndarray
    corner_normals: Optional[np.ndarray] = None
    uvs: Optional[np.ndarray] = None
    motion: Optional[object] = None
    holdout: bool = False          # Cycles' holdout: a zero-alpha hole for camera rays
    visibility: int = 31           # the ray kinds that see it (engine.visibility)
    object_info: Optional[object] = None   # ObjectInfo, what shader nodes read of it
    tangents: Optional[np.ndarray] = None  # (T, 3, 4) float32: tangent, bitangent sign
    colors: Optional[np.ndarray] = None    # (T, 3, 4) float32: a color attribute, RGBA
    # (T, 3, 3) float32: a displaced mesh's corners before displacement, in object space
    # (engine.displacement): its hits read Generated coordinates there, as in Cycles
    undisplaced: Optional[np.ndarray] = None
    # Shadow Terminator > Geometry Offset (Cycles' per-object setting; 0 = off): how far
    # shadow rays start from the curved surface of a smooth mesh (engine.kernels.terminator)
    terminator_offset: float = 0.1
    # None: one mesh in world space. Instances: positions, corner normals and tangents
    # are in object space, and the mesh stands at each of its places (`object_info`
    # then gives only the texture space; Object Info reads the places' own values)
    instances: Optional[Instances] = None
    pass_index: int = 0            # Blender's object Pass Index (IndexOB pass)
    lightgroup: str = ""           # its emission's light group (Scene.light_groups)
    # Object > Visibility > Shadow Catcher (engine.shadow_catcher): the shadows and light
    # other objects cast on it become a pass of their own, the object itself a hole
    shadow_catcher: bool = False
    # the names Cryptomatte gives its hits (engine.cryptomatte): the Blender object's and
    # its topmost parent's ("": the mesh's name, and the object name)
    object_name: str = ""
    asset_name: str = ""

    def __post_init__(self):
        self.positions = np.ascontiguousarray(self.positions, dtype=np.float64).reshape(-1, 3)
        self.triangles = np.ascontiguousarray(self.triangles, dtype=np.int32).reshape(-1, 3)
        self.material_indices = np.ascontiguousarray(
            self.material_indices, dtype=np.int32).reshape(-1)
        if self.material_indices.size == 1 and len(self.triangles) != 1:
            self.material_indices = np.full(len(self.triangles), self.material_indices[0], np.int32)
        if len(self.material_indices) != len(self.triangles):
            raise ValueError(f"mesh {self.name!r}: {len(self.material_indices)} material indices "
                             f"for {len(self.triangles)} triangles")
        self.uvs = self._per_corner(self.uvs, 2, "UV")
        self.undisplaced = self._per_corner(self.undisplaced, 3, "undisplaced")
        if len(self.triangles) and (self.triangles.min() < 0
                                    or self.triangles.max() >= len(self.positions)):
            raise ValueError(f"mesh {self.name!r}: triangle index out of range")
        if self.instances is not None and self.motion is not None:
            raise ValueError(f"mesh {self.name!r}: instances cannot move (export moving "
                             f"places as meshes of their own)")

    def _per_corner(self, values, width: int, what: str):
        """A per-corner attribute as (T, 3, width) float32 (None stays None)."""
        if values is None:
            return None
        a = np.asarray(values, dtype=np.float32)
        if a.size != len(self.triangles) * 3 * width:
            raise ValueError(f"mesh {self.name!r}: {a.size // (3 * width)} {what} triangles "
                             f"for {len(self.triangles)} triangles")
        return np.ascontiguousarray(a.reshape(-1, 3, width))


@dataclass
class PointLight:
    """A point light, or a sphere light when radius > 0. strength: RGB watts (Blender's
    colour x power x 2**exposure). Spot lights add a cone: spot_size is the full cone
    angle in radians, spot_blend Blender's 0..1 blend, `direction` the light's -Z axis.

    soft_falloff: Blender's `use_soft_falloff` (on by default). With radius > 0, Cycles
    then does not render a sphere but a disc of the same radius and radiance
    S / (4 pi^2 r^2), centred on the light and always facing the shaded point (sampled
    uniformly by area); only the part above the point's horizon lights it. Far from the
    light both give the intensity S / (4 pi); 1 m from a 0.3 m light the disc gives a
    few percent less. False means a sphere (what `use_soft_falloff` off gives in Cycles)."""
    position: tuple
    strength: tuple
    radius: float = 0.0
    spot_size: Optional[float] = None
    spot_blend: float = 0.0
    direction: tuple = (0.0, 0.0, -1.0)
    name: str = "point"
    soft_falloff: bool = False
    visibility: int = 31           # the ray kinds that see it (engine.visibility)
    motion_slices: Optional[list] = None   # this light at K shutter-slice middles (moving)
    lightgroup: str = ""           # its light group's name (Scene.light_groups; "": none)
    shadow_catcher: bool = True    # the lamp lights shadow catchers (Blender's default)


@dataclass
class SunLight:
    """A distant light. strength: RGB irradiance in W/m^2 at normal incidence; direction
    is where the light travels (the lamp's -Z); angle the full angular diameter, radians."""
    direction: tuple
    strength: tuple
    angle: float = 0.0
    name: str = "sun"
    visibility: int = 31           # the ray kinds that see it (engine.visibility)
    motion_slices: Optional[list] = None   # this light at K shutter-slice middles (moving)
    lightgroup: str = ""           # its light group's name (Scene.light_groups; "": none)
    shadow_catcher: bool = True    # the lamp lights shadow catchers (Blender's default)


@dataclass
class AreaLight:
    """A one-sided area light emitting along its local -Z.

    matrix: 4x4 light-to-world transform (scale allowed), shape one of 'SQUARE',
    'RECTANGLE', 'DISK', 'ELLIPSE'; size_x/size_y in local units; strength RGB watts;
    normalize as Blender's `normalize` (radiance divided by the area when True)."""
    matrix: np.ndarray
    strength: tuple
    shape: str = "SQUARE"
    size_x: float = 1.0
    size_y: float = 1.0
    normalize: bool = True
    visible_camera: bool = True
    name: str = "area"
    visibility: int = 31           # the ray kinds that see it (engine.visibility)
    motion_slices: Optional[list] = None   # this light at K shutter-slice middles (moving)
    lightgroup: str = ""           # its light group's name (Scene.light_groups; "": none)
    shadow_catcher: bool = True    # the lamp lights shadow catchers (Blender's default)


@dataclass
class Camera:
    """A Blender camera reduced to what rays need.

    matrix: 4x4 camera-to-world (scale is removed by the camera model).
    kind: 'PERSP' or 'ORTHO'. For PERSP, `fov_x`/`fov_y` are implied by
    sensor_width/sensor_height/lens/sensor_fit like Blender; for ORTHO, ortho_scale is
    the extent along the fitted axis. shift_x/shift_y are in units of the fitted
    extent, as in Blender. aperture_radius in metres (0 = pinhole), focus_distance in
    metres, blades 0 for a round aperture.
    """
    matrix: np.ndarray
    kind: str = "PERSP"
    lens: float = 50.0
    sensor_width: float = 36.0
    sensor_height: float = 24.0
    sensor_fit: str = "AUTO"
    ortho_scale: float = 6.0
    shift_x: float = 0.0
    shift_y: float = 0.0
    clip_start: float = 0.1
    clip_end: float = 1000.0
    aperture_radius: float = 0.0
    focus_distance: float = 10.0
    blades: int = 0
    blade_rotation: float = 0.0
    aperture_ratio: float = 1.0
    motion: Optional[object] = None      # engine.motion.RigidMotion of `matrix` over the shutter
    lens_motion: Optional[tuple] = None  # (times (K,), focal lengths in mm (K,)) over the shutter


@dataclass
class World:
    """The background seen by escaped rays, which also lights the scene.

    Without a texture: uniform radiance `color` (Blender's colour x strength). With one:
    an equirectangular environment map (`engine.textures.Texture`, REPEAT extension, as
    Cycles' Environment Texture reads it) times `strength` (RGB), looked up along
    `mapping` @ direction (a 3x3 matrix, Blender's Mapping node; None = identity); see
    `engine.environment_map` for the projection. `color` is then not used.
    visibility: the ray kinds that see it (engine.visibility; Blender's World > Ray
    Visibility); see `engine.world_light`.
    camera_texture: what camera rays see instead of `texture` (same strength and
    mapping), when the world's node graph shows the camera another background than the
    one that lights the scene (a Light Path node's Is Camera Ray); None = the same.
    sun: a `SunLight` that belongs to the world (a Sky Texture's sun disc,
    `engine.sky_texture`), rendered as one more lamp; None = none.
    light_sampling: whether next-event estimation samples the world (Blender's World >
    Settings > Sampling Method, not None; see engine.lights.LightSet for a uniform
    world, which Cycles never samples)."""
    color: tuple = (0.0, 0.0, 0.0)
    texture: Optional[object] = None
    strength: tuple = (1.0, 1.0, 1.0)
    mapping: Optional[np.ndarray] = None
    visibility: int = 31
    volume: Optional[object] = None      # Volume filling the space outside every mesh
    camera_texture: Optional[object] = None
    sun: Optional[SunLight] = None
    light_sampling: bool = True
    lightgroup: str = ""           # its light's group (Scene.light_groups; "": none)


@dataclass
class Scene:
    camera: Camera
    width: int
    height: int
    meshes: list = field(default_factory=list)
    materials: list = field(default_factory=lambda: [Material()])
    lights: list = field(default_factory=list)
    world: World = field(default_factory=World)
    pixel_aspect: float = 1.0
    shutter: Optional[object] = None     # engine.motion.Shutter; None = motion blur off
    film_transparent: bool = False       # Blender's Film > Transparent: background alpha 0
    curves: list = field(default_factory=list)   # hair: engine.curves.HairCurves
    # the view layer's light groups (Cycles' Combined_<name> passes): lamps, emissive
    # meshes and the world name theirs by `lightgroup`
    light_groups: tuple = ()

    def __post_init__(self):
        if self.width < 1 or self.height < 1:
            raise ValueError(f"resolution must be positive, got {self.width}x{self.height}")
        if not self.materials:
            self.materials = [Material()]
        for m in self.meshes + self.curves:
            if len(m.material_indices) and m.material_indices.max() >= len(self.materials):
                raise ValueError(f"mesh {m.name!r} uses a material index beyond the "
                                 f"{len(self.materials)} materials")

    def has_motion(self) -> bool:
        """True only when motion blur is on and something actually moves: otherwise the
        render takes the static path (no time dimension, no extra acceleration structures)."""
        if self.shutter is None:
            return False
        moving = [m for m in self.meshes if m.motion is not None and not _is_static(m.motion)]
        camera_moves = self.camera.motion is not None and not _is_static(self.camera.motion)
        lamps_move = any(getattr(l, "motion_slices", None) for l in self.lights)
        lm = self.camera.lens_motion
        zooms = lm is not None and bool(np.ptp(np.asarray(lm[1], dtype=np.float64)) > 0)
        return bool(moving) or camera_moves or zooms or lamps_move

    def has_volumes(self) -> bool:
        """Whether any material or the world holds a medium (engine.kernels.volume)."""
        return any(m.volume is not None or not m.surface for m in self.materials) \
            or self.world.volume is not None

    def has_holdouts(self) -> bool:
        """Whether an object is a holdout, or a material is or holds a Holdout shader (also
        as a side of a Mix Shader)."""
        def holds(m):
            return (getattr(m, "holdout", False) or getattr(m, "holdout_weight", 0.0) > 0
                    or any(holds(side) for side in (getattr(m, "mix", None) or ())))
        return any(m.holdout for m in self.meshes + self.curves) or \
            any(holds(m) for m in self.materials)

    def needs_alpha(self) -> bool:
        """Whether samples carry a coverage (alpha) below one anywhere."""
        return self.film_transparent or self.has_holdouts()

    def triangle_count(self) -> int:
        return int(sum(len(m.triangles) for m in self.meshes))


def _is_static(motion) -> bool:
    if hasattr(motion, "is_static"):
        return motion.is_static()
    p = motion.positions
    return bool(np.all(np.abs(p - p[0]) == 0))
