"""A Principled BSDF's emission under its sheen and coat, as Cycles weighs it.

Cycles sets a Principled BSDF's emission up after its sheen and its coat, with the
weight those layers leave to what lies below them (kernel/svm/closure.h: "Emission
(attenuated by sheen and coat)"): times 1 minus the sheen's albedo (its largest
channel), times 1 minus the coat's weight times its albedo, and times the coat's tint
over the refracted path, each at the angle the emitter is seen from. That is the base
lobes' factor that layers.setup writes (S_BASE_SCALE) at that angle: the LAYERS row.

The albedos are those of closures Cycles has set up, and Cycles sets up none where it
evaluates a shader for its emission alone (integrator/surface_shader.h: no closure
storage on a path flagged to terminate, for a shadow ray or for emission): there the
sheen and the coat do not dim, and the coat's tint, applied outside its closure, still
does. That is the TINT row, and it is what Cycles' next-event estimation of an
emissive triangle sees (shade_light.h evaluates a Principled's emission, never
constant to Cycles, with PATH_RAY_EMISSION), and what the ray of a bounce that spends a
budget finds (PATH_RAY_TERMINATE_AFTER_TRANSPARENT; path_weights.SPENT). So DRT keeps
both: LAYERS where a camera or BSDF ray finds the emitter, TINT where a light sample
does or a spent path's ray. An Emission shader added beside the BSDF is not dimmed at
all (Material.emission_under_layers is then False).

The factors depend on the cosine alone (both layers are isotropic about the normal),
so each dimmed material has two rows of N_COS cosines, uniform in [0, 1], filled once
per scene (`dimming_rows`: LAYERS by layers.setup itself), which the tracer reads by
linear interpolation (`dimmed`): at a ray's hit (path_vertex, whitted_vertex) about
the surface's own normal (Cycles' sd->N), at a light sample on an emissive triangle
(lights/triangles.py) about the triangle's geometric normal, the only one the light
table keeps. Both read the material's plain parameters: a coat or sheen driven per hit
by a texture or a program dims by its average. Cycles also leaves the coat's albedo
out of a BSDF ray's hit where Reflective Caustics is off and the ray left a diffuse
bounce; DRT dims there by the LAYERS row. A material that nothing dims has no rows
(P_EMISSION_DIM -1) and costs one read of its parameter row where its emission is
found; a scene without one carries empty tables (pack.py: L[TRI_DIM], L[EMIT_DIM]).
"""
from __future__ import annotations

import numpy as np

from ..jit import kernel
from . import coat, layers
from .layer_slots import S_BASE_SCALE, WEIGHT_CUTOFF
from .params import P_COAT_IOR, P_COAT_TINT, P_COAT_WEIGHT, P_EMISSION_DIM
from .state import NSTATE

N_COS = 129                # cosines tabulated per row, 0 to 1
LAYERS = 0                 # the sheen's and coat's albedos and the coat's tint
TINT = 1                   # the coat's tint alone


@kernel
def _fill(rows, tables, state, out):
    for s in range(rows.shape[0]):
        row = rows[s]
        cw = max(row[P_COAT_WEIGHT], 0.0)
        ior = max(row[P_COAT_IOR], 1.0)
        for i in range(N_COS):
            c = i / (N_COS - 1)
            layers.setup(row, np.sqrt(max(1.0 - c * c, 0.0)), 0.0, c, tables, state, 0.0,
                         0.0, 1.0)
            depth = coat.path_length(c, ior)
            for ch in range(3):
                out[s, LAYERS, i, ch] = state[S_BASE_SCALE + ch]
                out[s, TINT, i, ch] = (coat.tint_factor(row[P_COAT_TINT + ch], cw, depth)
                                       if cw > WEIGHT_CUTOFF else 1.0)


def dimming_rows(params, tables) -> np.ndarray:
    """(n_dimmed, 2, N_COS, 3) float64: [s, LAYERS] and [s, TINT] hold the factors of
    the material whose P_EMISSION_DIM is s (params.pack_materials numbers them in
    material order), per channel, at cosine i / (N_COS - 1); (0, 2, N_COS, 3) when no
    material is dimmed."""
    rows = np.ascontiguousarray(params[params[:, P_EMISSION_DIM] >= 0])
    out = np.zeros((len(rows), 2, N_COS, 3), np.float64)
    if len(rows):
        _fill(rows, tables, np.zeros(NSTATE, np.float64), out)
    return out


@kernel(allocates=False)
def dimmed(dims, s, which, cos, r, g, b):
    """Radiance (r, g, b) as row `which` (LAYERS or TINT) of material s of `dims`
    (dimming_rows) dims it, seen at cosine cos (either sign) to the emitter's normal."""
    c = min(abs(cos), 1.0) * (N_COS - 1)
    if not c >= 0.0:
        c = 0.0                              # NaN: seen edge-on
    i = min(int(c), N_COS - 2)
    f = c - i
    return (r * (dims[s, which, i, 0] * (1.0 - f) + dims[s, which, i + 1, 0] * f),
            g * (dims[s, which, i, 1] * (1.0 - f) + dims[s, which, i + 1, 1] * f),
            b * (dims[s, which, i, 2] * (1.0 - f) + dims[s, which, i + 1, 2] * f))
