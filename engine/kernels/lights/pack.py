"""`pack_lights`: an `engine.lights.LightSet` as a tuple of NumPy arrays for the kernels.

The tuple L (one Numba argument; always the same array types, so one compilation serves
every scene):

  L[LAMPS]       float64 (n_lamps, N_COLUMNS): one row per lamp model, in the order of
                 `LightSet.models` (entry k < n_lamps is lamp k); the columns are the
                 C_* constants below, the kind in column C_TYPE (the T_* codes).
  L[SELECT_PDF]  float64 (n_entries,): `LightSet.select_pdf` (lamps, then triangles).
  L[CDF]         float64 (n_entries,): `LightSet.cdf` (last entry 1).
  L[SUNS]        int64 (n_suns,): lamp index of each non-delta sun, in the order of
                 `LightSet.suns()`.
  L[TRI_V0], L[TRI_E1], L[TRI_E2], L[TRI_NORMAL]   float64 (n_tri, 3): the emissive
                 triangles (`EmissiveTriangles` v0, e1 = v1 - v0, e2 = v2 - v0, unit normal);
                 triangle j is entry n_lamps + j. Empty when the set has no mesh lights.
  L[TRI_AREA]    float64 (n_tri,): area.
  L[TRI_PRIM]    int64 (n_tri,): its global triangle id (the first of coincident copies),
                 which shadow rays towards it name (engine.embree.self_hits).
  L[TRI_RADIANCE]  float64 (n_tri, 3): emitted radiance (two-sided).
  L[TRI_ENTRY]   int64 (n_prims,): global triangle id -> triangle entry j, or -1
                 (`EmissiveTriangles.entry`; empty without mesh lights).
  L[ENV]         float64 (6,): [lamp index of the world light or -1, radiance r, g, b,
                 solid-angle pdf 1 / (4 pi), the ray kinds that see the world (its
                 `seen_by` mask, 31 without a world)]; radiance and pdf 0 when the world
                 is not a light or is an environment map.
  L[TRI_VISIBILITY]  int64 (n_tri,): the ray kinds that see emissive triangle j (its
                 object's engine.visibility mask; all 31 when not given), and above them
                 the sides next-event estimation leaves out (NEE_FRONT_OFF,
                 NEE_BACK_OFF: engine.mesh_lights, Material > Settings > Emission
                 Sampling), and EMISSION_SHADED where its emission varies over it.
  The environment map (`engine.environment_map.EnvironmentMap`, whether or not it is
  bright enough to be a light; empty arrays and M_HAS = 0 without one):
  L[ENV_MAP]     float64 (N_MAP,): the M_* fields below (flags, |det|, strength, matrix
                 M and its inverse, row-major).
  L[ENV_PIXELS]  float32 (4 W H,): the image's RGBA texels, as `kernels.textures` T[PIXELS]
                 (then the camera's image's, when M_CAMERA).
  L[ENV_TEXTURE] int64 (1 or 2, 6): its row of `kernels.textures` T[TEXTURES] (offset 0),
                 and the camera's image's row (M_CAMERA: what camera rays see instead).
  L[ENV_MARGINAL]  float64 (H + 1,), L[ENV_CONDITIONAL] float64 (H, W + 1): the CDFs of
                 its `PiecewiseConstant2D`.
  L[ENV_MARGINAL_GUIDE] int32 (m + 1,), L[ENV_CONDITIONAL_GUIDE] int32 (H, c + 1): their
                 guide tables (`kernels.cdf_search`), for the row and column searches.
  L[CDF_GUIDE]   int32 (m + 1,): L[CDF]'s guide table, for picking an entry.
  Lamps that move during the shutter (`engine.lights.TimeSlicedLight`: the lamp at the
  middles of K equal slices of the shutter):
  L[LAMP_SLICES] float64 (n_rows, N_COLUMNS): the rows of every moving lamp's slices.
  L[SLICE_OF]    int64 (n_lamps, 2): lamp k's first row in L[LAMP_SLICES] and its slice
                 count K (0 for a lamp that does not move). A moving lamp's own row in
                 L[LAMPS] is its middle slice (K // 2, as TimeSlicedLight without a time);
                 a ray at shutter time t in [0, 1] sees slice min(floor(t K), K - 1).
  The light tree (tree_build.py; all three empty when lights are picked without the tree,
  as with Cycles' Light Tree off or a single entry):
  L[TREE_NODES]  float64 (n_nodes, tree_build.N_NODE), L[TREE_SLOTS] int64 (n_slots,),
  L[TREE_EMIT]   float64 (n_entries, tree_build.N_EMIT).
  Emission that a Principled's coat and sheen dim (engine.kernels.bsdf.layered_emission;
  both empty when no material's is):
  L[TRI_DIM]     int64 (n_tri,): the row of L[EMIT_DIM] that dims triangle j's radiance,
                 or -1.
  L[EMIT_DIM]    float64 (n_rows, 2, layered_emission.N_COS, 3): the rows (a material's
                 P_EMISSION_DIM names its row).
"""
from __future__ import annotations

import numpy as np

from ...lights import AreaLightModel, PointLightModel, SunLightModel, TimeSlicedLight
from ...world_light import EnvironmentLightModel, EnvironmentMapLightModel
from ..cdf_search import guide_cells, guide_table
from ..textures import texture_info

# ---------------------------------------------------------------- fields of the tuple L
LAMPS = 0
SELECT_PDF = 1
CDF = 2
SUNS = 3
TRI_V0 = 4
TRI_E1 = 5
TRI_E2 = 6
TRI_NORMAL = 7
TRI_AREA = 8
TRI_PRIM = 9        # (the tuple keeps its size: each array more in L, which the vertex
#                     kernels pass everywhere, cost 18 % of a Cornell box's time)
TRI_RADIANCE = 10
TRI_ENTRY = 11
ENV = 12
TRI_VISIBILITY = 13
NEE_FRONT_OFF = 32  # bits of L[TRI_VISIBILITY] above the ray kinds (engine.visibility):
NEE_BACK_OFF = 64   # the side of the triangle (its normal's, the other) not sampled
EMISSION_SHADED = 128   # its radiance an estimate: the sample runs its material
#                         (engine.kernels.shaded_emitter)
ENV_MAP = 14
ENV_PIXELS = 15
ENV_TEXTURE = 16
ENV_MARGINAL = 17
ENV_CONDITIONAL = 18
ENV_MARGINAL_GUIDE = 19
ENV_CONDITIONAL_GUIDE = 20
CDF_GUIDE = 21
LAMP_SLICES = 22
SLICE_OF = 23
TREE_NODES = 24
TREE_SLOTS = 25
TREE_EMIT = 26
TRI_DIM = 27
EMIT_DIM = 28

# ---------------------------------------------------------------- L[ENV_MAP] fields
M_HAS = 0           # 1: the world is an environment map
M_IDENTITY = 1      # 1: its mapping is the identity
M_ABS_DET = 2       # |det M|
M_STRENGTH = 3      # 3: strength r, g, b
M_MATRIX = 6        # 9: M (world direction -> lookup vector), row-major
M_INVERSE = 15      # 9: M^-1
M_CAMERA = 24       # 1: camera rays see texture 1 of L[ENV_TEXTURE] instead of texture 0
N_MAP = 25

# ---------------------------------------------------------------- lamp kinds (C_TYPE)
T_POINT = 0         # delta point or spot (radius 0)
T_SPHERE = 1        # point light with radius > 0, soft_falloff off
T_DISC = 2          # point light with radius > 0 and soft_falloff: the facing disc
T_SUN_DELTA = 3     # sun with (near) zero angle
T_SUN = 4           # sun with an angular diameter: a uniform cone
T_AREA = 5          # SQUARE, RECTANGLE, DISK or ELLIPSE area light
T_ENV = 6           # the uniform world
T_ENV_MAP = 7       # the world's environment map (L[ENV_MAP] and the following fields)

# ---------------------------------------------------------------- lamp table columns
C_TYPE = 0
C_VISIBLE = 1       # 1: BSDF rays can hit it (lamp_hit), 0: not (delta, sun, world)
C_VISIBILITY = 2    # the ray kinds that see it (engine.visibility mask)
C_DELTA = 3         # 1 for point and zero-angle sun lights
C_RAD = 4           # 3: radiance (sphere / disc, sun disc, area, world)
# point, spot, sphere, disc
C_POS = 7           # 3: position
C_INTENSITY = 10    # 3: strength / (4 pi)
C_RADIUS = 13
C_IS_SPOT = 14
C_AXIS = 15         # 3: unit spot direction
C_COS_HALF = 18
C_SMOOTH = 19       # spot blend x (1 - cos_half)
# sun
C_TO_LIGHT = 20     # 3: unit direction towards the sun
C_IRRADIANCE = 23   # 3
C_ONE_MINUS = 26    # 1 - cos(half angle)
C_SUN_T = 27        # 3: tangent of the sun's cone frame
C_SUN_B = 30        # 3: bitangent
# area
C_CENTER = 33       # 3
C_AX = 36           # 3: half-extent vector along local x
C_AY = 39           # 3: half-extent vector along local y
C_NORMAL = 42       # 3: local +Z (emission along -Z)
C_AREA = 45
C_INV = 46          # 9: inverse of [ax ay normal], row-major
C_ROUND = 55        # 1 for DISK / ELLIPSE
C_SR_OK = 56        # 1: spherical rectangle sampling possible (perpendicular edges)
C_LX = 57
C_LY = 58
C_XH = 59           # 3: unit edge x
C_YH = 62           # 3: unit edge y
C_ZH = 65           # 3: xh cross yh
C_CORNER = 68       # 3: center - ax - ay
# world
C_ENV_PDF = 71
# area, continued
C_TAN_SPREAD = 72   # tan of half the Spread (0: the whole hemisphere)
C_NORM_SPREAD = 73  # the Spread's normalisation (engine.lights.spread_parameters)
N_COLUMNS = 74


def _put(row, col, values):
    values = np.asarray(values, dtype=np.float64).reshape(-1)
    row[col:col + len(values)] = values


def _lamp_row(model) -> np.ndarray:
    if isinstance(model, TimeSlicedLight):
        return _lamp_row(model.slices[model.k // 2])
    row = np.zeros(N_COLUMNS)
    row[C_VISIBLE] = float(bool(model.visible))
    row[C_VISIBILITY] = float(int(getattr(model, "visibility", 31)))
    row[C_DELTA] = float(bool(model.delta))
    if isinstance(model, PointLightModel):
        row[C_TYPE] = T_POINT if model.delta else (T_DISC if model.disc else T_SPHERE)
        _put(row, C_POS, model.position)
        _put(row, C_INTENSITY, model.intensity)
        row[C_RADIUS] = model.radius
        if model.sphere_radiance is not None and not model.delta:
            _put(row, C_RAD, model.sphere_radiance)
        row[C_IS_SPOT] = float(model.is_spot)
        if model.is_spot:
            _put(row, C_AXIS, model.axis)
            row[C_COS_HALF] = model.cos_half
            row[C_SMOOTH] = model.smooth
    elif isinstance(model, SunLightModel):
        row[C_TYPE] = T_SUN_DELTA if model.delta else T_SUN
        _put(row, C_TO_LIGHT, model.to_light)
        _put(row, C_IRRADIANCE, model.irradiance)
        row[C_ONE_MINUS] = model.one_minus
        if not model.delta:
            _put(row, C_RAD, model.radiance)
            _put(row, C_SUN_T, model.t)
            _put(row, C_SUN_B, model.b)
    elif isinstance(model, AreaLightModel):
        row[C_TYPE] = T_AREA
        _put(row, C_RAD, model.radiance)
        _put(row, C_CENTER, model.center)
        _put(row, C_AX, model.ax)
        _put(row, C_AY, model.ay)
        _put(row, C_NORMAL, model.normal)
        row[C_AREA] = model.area
        _put(row, C_INV, model.inv)
        row[C_ROUND] = float(model.round)
        row[C_SR_OK] = float(bool(model.solid_angle_ok))
        row[C_LX], row[C_LY] = model.lx, model.ly
        _put(row, C_XH, model.xh)
        _put(row, C_YH, model.yh)
        _put(row, C_ZH, model.zh)
        _put(row, C_CORNER, model.corner)
        row[C_TAN_SPREAD] = model.tan_half_spread
        row[C_NORM_SPREAD] = model.normalize_spread
    elif isinstance(model, EnvironmentLightModel):
        row[C_TYPE] = T_ENV
        _put(row, C_RAD, model.radiance)
        row[C_ENV_PDF] = model.pdf_value
    elif isinstance(model, EnvironmentMapLightModel):
        row[C_TYPE] = T_ENV_MAP
    else:
        raise TypeError(f"no kernel for light model {type(model).__name__}")
    return row


def _f64(a, shape):
    """A writable C-ordered float64 copy: the kernels' argument types never vary."""
    return np.array(np.asarray(a, dtype=np.float64).reshape(shape), order="C", copy=True)


def pack_lights(light_set, tri_visibility=None, timed=True, tree=True,
                dimming=None) -> tuple:
    """The LightSet as the kernels' tuple L (fields: this module's docstring).
    tri_visibility: the visibility mask of every global triangle (Surfaces.visibility),
    or None when every triangle is seen by every ray.
    A lamp that moves during the shutter (`TimeSlicedLight`) has a row per slice in
    L[LAMP_SLICES] (see the module docstring); with `timed` False (a render that samples
    no time: the shutter is closed) it is its middle slice alone, as TimeSlicedLight
    without a time. `tree`: pick lights with the light tree (Cycles' default), else by
    LightSet.select_pdf (Cycles' distribution without the tree). `dimming`: (the row
    of dimming_rows of every global triangle, or -1; those rows), or None: nothing
    dims the triangles' emission (see the module docstring, L[TRI_DIM])."""
    models = light_set.models
    lamps = np.zeros((len(models), N_COLUMNS))
    slice_of = np.zeros((len(models), 2), dtype=np.int64)
    slice_rows = []
    for k, model in enumerate(models):
        lamps[k] = _lamp_row(model)
        if isinstance(model, TimeSlicedLight) and timed:
            slice_of[k] = len(slice_rows), model.k
            slice_rows += [_lamp_row(m) for m in model.slices]
    slices = np.array(slice_rows, dtype=np.float64).reshape(-1, N_COLUMNS)
    select_pdf = _f64(light_set.select_pdf, (-1,))
    cdf = _f64(light_set.cdf, (-1,))
    suns = np.array([k for k, _ in light_set.suns()], dtype=np.int64)
    mesh = light_set.mesh
    if mesh is not None and len(mesh):
        tri = (_f64(mesh.v0, (-1, 3)), _f64(mesh.e1, (-1, 3)), _f64(mesh.e2, (-1, 3)),
               _f64(mesh.normal, (-1, 3)), _f64(mesh.area, (-1,)),
               np.array(mesh.prim, dtype=np.int64, order="C", copy=True),
               _f64(mesh.radiance, (-1, 3)),
               np.array(mesh.entry, dtype=np.int64, order="C", copy=True))
    else:
        z3 = np.zeros((0, 3))
        tri = (z3, z3.copy(), z3.copy(), z3.copy(), np.zeros(0), np.zeros(0, np.int64),
               z3.copy(), np.zeros(0, dtype=np.int64))
    env = np.zeros(6)
    env[0] = -1.0
    env[5] = getattr(light_set.world, "seen_by", 31)
    if light_set.env_index is not None:
        m = models[light_set.env_index]
        env[0] = light_set.env_index
        if isinstance(m, EnvironmentLightModel):
            env[1:4] = m.radiance[:3]
            env[4] = m.pdf_value
    if len(select_pdf) != len(models) + len(tri[4]):
        raise ValueError("LightSet entries do not match its lamps and triangles")
    n_tri = len(tri[4])
    vis = np.full(n_tri, 31, dtype=np.int64)
    if tri_visibility is not None and n_tri:
        entry = tri[7]
        prims = np.flatnonzero(entry >= 0)
        vis[entry[prims]] = np.asarray(tri_visibility)[prims]
    sides = getattr(mesh, "sides", None) if n_tri else None
    if sides is not None:
        from ...mesh_lights import BACK, FRONT
        sides = np.asarray(sides, np.int64)
        vis |= (np.where(sides & FRONT, 0, NEE_FRONT_OFF)
                | np.where(sides & BACK, 0, NEE_BACK_OFF))
    shaded = getattr(mesh, "shaded", None) if n_tri else None
    if shaded is not None:
        vis |= np.where(np.asarray(shaded) != 0, EMISSION_SHADED, 0)
    L = ((lamps, select_pdf, cdf, suns) + tri + (env, vis) + _pack_map(light_set.world)
         + (guide_table(cdf, guide_cells(len(cdf))), slices, slice_of))
    if tree and len(select_pdf) > 0:
        # a single light too: Cycles' tree then still refuses it to receivers it cannot
        # light (below a surface that does not transmit), which a closure whose sampling
        # and evaluation differ (the Hair BSDF's) sees in its MIS weights
        from .tree_build import tree_arrays
        L = L + tree_arrays(L, models)
    else:
        from .tree_build import N_EMIT, N_NODE
        L = L + (np.zeros((0, N_NODE)), np.zeros(0, np.int64), np.zeros((0, N_EMIT)))
    return L + _dimming(dimming, tri[5])


def _dimming(dimming, tri_prim) -> tuple:
    """(L[TRI_DIM], L[EMIT_DIM]) of `dimming` (pack_lights) for the triangles of global
    ids tri_prim: both empty when no triangle's emission is dimmed."""
    from ..bsdf.layered_emission import N_COS
    empty = (np.zeros(0, np.int64), np.zeros((0, 2, N_COS, 3)))
    if dimming is None or len(tri_prim) == 0:
        return empty
    per_prim, rows = dimming
    tri_dim = np.asarray(per_prim, np.int64)[tri_prim]
    if not (tri_dim >= 0).any():
        return empty
    return np.ascontiguousarray(tri_dim), _f64(rows, (-1, 2, N_COS, 3))


def _pack_map(world) -> tuple:
    """The L[ENV_MAP:] fields of the world model (empty without an environment map)."""
    params = np.zeros(N_MAP)
    if not isinstance(world, EnvironmentMapLightModel):
        return (params, np.zeros(0, np.float32), np.zeros((0, 6), np.int64), np.zeros(1),
                np.zeros((0, 1)), np.zeros(2, np.int32), np.zeros((0, 2), np.int32))
    env = world.map
    params[M_HAS] = 1.0
    params[M_IDENTITY] = float(env.identity)
    params[M_ABS_DET] = env.abs_det
    params[M_STRENGTH:M_STRENGTH + 3] = env.strength
    params[M_MATRIX:M_MATRIX + 9] = env.matrix.reshape(-1)
    params[M_INVERSE:M_INVERSE + 9] = env.inverse.reshape(-1)
    tex = env.texture
    pixels = np.ascontiguousarray(tex.pixels, dtype=np.float32).reshape(-1)
    info = [texture_info(tex, 0)]
    camera = getattr(world, "camera_texture", None)
    if camera is not None:
        params[M_CAMERA] = 1.0
        info.append(texture_info(camera, len(pixels)))
        pixels = np.concatenate([pixels, np.asarray(camera.pixels, np.float32).reshape(-1)])
    info = np.array(info, dtype=np.int64)
    dist = env.distribution
    marginal = _f64(dist.marginal, (-1,))
    conditional = _f64(dist.conditional, dist.conditional.shape)
    return (params, pixels, info, marginal, conditional,
            guide_table(marginal, guide_cells(len(marginal) - 1)),
            guide_table(conditional, guide_cells(conditional.shape[1] - 1)))
