"""What one path vertex's shading costs, piece by piece: the measured cause behind target 1
of docs/benchmarks.md (called by docs/make_benchmarks.py for section 1).

The shading kernel (engine/kernels/path_vertex.py `shade`) calls, per vertex of the
Cornell box's diffuse walls: the sampler for four numbers (the lobe and the roulette 1D,
the light's point and the BSDF direction 2D), the hit rebuild, the Principled BSDF's setup
at the outgoing direction, next-event estimation (a light sample, the BSDF's value and pdf
there) and the BSDF's sample for the next ray. Each piece is timed here on its own: a
compiled loop calls it a million times, one thread, with inputs that change every call
(the scene's own materials, lamp and triangles; points inside the box; the render's
sample count), best of five, less the same loop without the piece; the scene's
tables are passed by reference, as the shading kernel passes them
(engine/kernels/tuple_ref.py). The BSDF's value, pdf
and sample are timed on states set up in advance. Their sum is set against the shading
kernel's measured time per vertex, which also holds the MIS weights, the roulette, the
ray queues and the path state.

    python docs/vertex_costs.py        # prints the table
"""
from __future__ import annotations

import math
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests")]

import numpy as np  # noqa: E402
from numba import njit  # noqa: E402

from engine.kernels import lights as lt  # noqa: E402
from engine.kernels.bsdf import principled as bsdf  # noqa: E402
from engine.kernels.surface import rebuild_at_time  # noqa: E402
from engine.kernels.tuple_ref import by_ref  # noqa: E402
from engine.sampling import dimensions as D  # noqa: E402
from engine.sampling.dispatch import sample_1d, sample_2d  # noqa: E402
from engine.sampling.hashing import pixel_key  # noqa: E402

CALLS = 1_000_000
GOLDEN = 0.618033988749895      # additive recurrences: inputs that change every call
PLASTIC = 0.7548776662466927
THIRD = 0.5698402909980532       # 1 / plastic number squared


@njit
def _direction(i):
    """An outgoing direction above the local surface, different for every i."""
    u, v = (i * GOLDEN) % 1.0, (i * PLASTIC) % 1.0
    z = 0.05 + 0.95 * u
    s = math.sqrt(1.0 - z * z)
    return s * math.cos(6.283185307179586 * v), s * math.sin(6.283185307179586 * v), z


@njit
def _sampler(kind, spp, two, n):
    """two 0: the inputs alone (the baseline); 1: a 1D sample; 2: a 2D sample."""
    acc = 0.0
    for i in range(n):
        key = pixel_key(7, i // spp)
        dim = D.FIRST_BOUNCE + (i % 4) * D.PER_BOUNCE + D.BSDF_DIR
        if two == 2:
            x, y = sample_2d(kind, key, spp, i % spp, dim)
            acc += x + y
        elif two == 1:
            acc += sample_1d(kind, key, spp, i % spp, dim)
        else:
            acc += np.float64(key >> np.uint64(40)) + dim
    return acc


@njit
def _rebuild(geometry_tuple, part, n):
    geometry = by_ref(geometry_tuple)          # as the shading kernel passes it
    acc = 0.0
    ntri = geometry[1].shape[0]
    for i in range(n):
        u, v = (i * GOLDEN) % 1.0, (i * PLASTIC) % 1.0
        dx, dy, dz = _direction(i)
        prim = (i * 7919) % ntri
        if part:
            r = rebuild_at_time(geometry, prim, -1, 0.5 * u, 0.5 * v, dx, dy, -dz, 0.5)
            acc += r[0] + r[6]
        else:
            acc += prim + u + v + dx + dy + dz
    return acc


STATES = 256        # BSDF states set up in advance for timing the value, pdf and sample


@njit
def _bsdf_setup(params, tables_tuple, part, n):
    """part 0: the inputs alone; 1: the Principled BSDF's setup at wo."""
    tables = by_ref(tables_tuple)
    state = np.empty(bsdf.NSTATE)
    row = np.empty(params.shape[1])
    acc = 0.0
    for i in range(n):
        wox, woy, woz = _direction(i)
        row[:] = params[i % params.shape[0]]
        if part:
            bsdf.setup(row, True, wox, woy, woz, tables, state)
            acc += state[i % bsdf.NSTATE]
        else:
            acc += wox + woy + woz + row[i % row.shape[0]]
    return acc


@njit
def _bsdf_states(params, tables):
    """STATES set-up BSDFs, state i at wo = _direction(i), the materials in turn."""
    states = np.empty((STATES, bsdf.NSTATE))
    row = np.empty(params.shape[1])
    for i in range(STATES):
        wox, woy, woz = _direction(i)
        row[:] = params[i % params.shape[0]]
        bsdf.setup(row, True, wox, woy, woz, tables, states[i])
    return states


@njit
def _bsdf_use(states, part, n):
    """On set-up states: part 0 the inputs alone; 1 the value at wi; 2 the pdf at wi; 3 a
    sample."""
    acc = 0.0
    for i in range(n):
        k = i % STATES
        state = states[k]
        wox, woy, woz = _direction(k)
        lx, ly, lz = _direction(i + 12345)
        if part == 1:
            acc += bsdf.eval_seen(state, wox, woy, woz, lx, ly, lz, True, True, True)[0]
        elif part == 2:
            acc += bsdf.pdf_seen(state, wox, woy, woz, lx, ly, lz, True, True, True, True,
                                 True, True)
        elif part == 3:
            acc += bsdf.sample(state, wox, woy, woz, (i * THIRD) % 1.0,
                               lx * 0.5 + 0.5, ly * 0.5 + 0.5, True, True, True)[6]
        else:
            acc += state[i % bsdf.NSTATE] + wox + woy + woz + lx + ly + lz
    return acc


@njit
def _light(light_tuple, lo, hi, part, n):
    lights = by_ref(light_tuple)
    acc = 0.0
    for i in range(n):
        u, v, w = (i * GOLDEN) % 1.0, (i * PLASTIC) % 1.0, (i * THIRD) % 1.0
        px = lo[0] + (hi[0] - lo[0]) * u
        py = lo[1] + (hi[1] - lo[1]) * v
        pz = lo[2] + (hi[2] - lo[2]) * w
        if part:
            acc += lt.sample(lights, lt.receiver(px, py, pz, 0.0, 0.0, 1.0, lt.ONE_SIDED), w,
                             u, v, 0.0)[8]
        else:
            acc += px + py + pz
    return acc


def _ns(fn, *args) -> float:
    """Best of five runs (after one that compiles) of fn(*args, CALLS), ns per call."""
    fn(*args, 10)
    best = math.inf
    for _ in range(5):
        t0 = time.perf_counter()
        fn(*args, CALLS)
        best = min(best, time.perf_counter() - t0)
    return best / CALLS * 1e9


def measure(spp: int = 16) -> dict:
    """{piece: ns per call, over its loop's inputs alone} on the Cornell box's own
    materials, lamp and triangles."""
    from engine import RenderContext, RenderSettings
    from engine_scenes import cornell_box
    ctx = RenderContext(cornell_box(64, 64), RenderSettings(samples=spp, threads=1))
    try:
        it = ctx.integrator
        positions = it.geometry[0]
        lo, hi = positions.min(axis=0), positions.max(axis=0)
        lo, hi = lo + 0.05 * (hi - lo), hi - 0.05 * (hi - lo)       # inside the box
        out = {}
        for kind, name in ((0, "jittered"), (1, "Sobol")):
            base = _ns(_sampler, kind, spp, 0)
            out[f"sampler, 1D ({name})"] = _ns(_sampler, kind, spp, 1) - base
            out[f"sampler, 2D ({name})"] = _ns(_sampler, kind, spp, 2) - base
        out["hit rebuild (position, normals)"] = (_ns(_rebuild, it.geometry, 1)
                                                  - _ns(_rebuild, it.geometry, 0))
        out["light sample (the area lamp)"] = (_ns(_light, it.lights, lo, hi, 1)
                                               - _ns(_light, it.lights, lo, hi, 0))
        out["Principled BSDF setup at wo"] = (_ns(_bsdf_setup, it.params, it.tables, 1)
                                              - _ns(_bsdf_setup, it.params, it.tables, 0))
        states = _bsdf_states(it.params, it.tables)
        t = [_ns(_bsdf_use, states, part) for part in range(4)]
        out["Principled BSDF value (all lobes)"] = t[1] - t[0]
        out["Principled BSDF pdf"] = t[2] - t[0]
        out["Principled BSDF sample"] = t[3] - t[0]
        return {k: max(v, 0.0) for k, v in out.items()}
    finally:
        ctx.close()


# how many of each piece one vertex of the Cornell box's walls calls
PER_VERTEX = {"sampler, 1D (jittered)": 2, "sampler, 2D (jittered)": 2,
              "hit rebuild (position, normals)": 1, "light sample (the area lamp)": 1,
              "Principled BSDF setup at wo": 1, "Principled BSDF value (all lobes)": 1,
              "Principled BSDF pdf": 1, "Principled BSDF sample": 1}


def lines(costs: dict, vertex_ns: float, embree_ns: float) -> list:
    """Markdown: each piece's ns per call and per vertex, against the shading kernel's
    measured ns per vertex (shading seconds over closest-hit rays) and bare Embree's ns
    per ray."""
    out = ["| piece (`docs/vertex_costs.py`) | ns per call | calls per vertex | ns per vertex "
           "| share of a vertex |", "|---|---|---|---|---|"]
    total = 0.0
    for name, ns in costs.items():
        n = PER_VERTEX.get(name, 0)
        total += n * ns
        per = f"{n * ns:.0f}" if n else "(not used: the jittered sampler is the default)"
        share = f"{n * ns / vertex_ns:.0%}" if n else ""
        out.append(f"| {name} | {ns:.0f} | {n} | {per} | {share} |")
    out += [f"| the pieces, added up | | | {total:.0f} | {total / vertex_ns:.0%} |",
            f"| **the shading kernel, per vertex (measured in the render)** | | | "
            f"**{vertex_ns:.0f}** | 100% |",
            f"| (bare Embree, per ray) | | | {embree_ns:.0f} | |"]
    used = {k: PER_VERTEX[k] * v for k, v in costs.items() if k in PER_VERTEX}
    top = max(used, key=used.get)
    big = sum(1 for v in used.values() if v >= embree_ns)
    out += ["", f"Timed alone, the pieces add up to {total / vertex_ns:.0%} of the kernel's "
            "time per vertex (alone, each pays its loop's own stalls; in the kernel they "
            "overlap, and the kernel also weighs MIS, plays the roulette and writes the ray "
            f"queues). The largest, {top.split(' (')[0]}, is {used[top] / vertex_ns:.0%} of a "
            f"vertex; {big} of the {len(used)} pieces each cost more per vertex than a bare "
            f"Embree ray ({embree_ns:.0f} ns). At target 1's ratio of 0.5 a vertex's "
            "shading would have to cost no more than its rays' tracing."]
    return out


if __name__ == "__main__":
    for name, ns in measure().items():
        print(f"{name:40s} {ns:7.1f} ns")
