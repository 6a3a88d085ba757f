"""Light sampling as compiled scalar kernels, for the lamps of `engine.lights` (their
parameters, packed by pack.py) and the emissive triangles of `engine.mesh_lights`.

Every light has sample (one direction per shading point from u in [0,1)^2, through a
continuous map of u, so stratification survives; pdf in solid angle), an intersection
(what a BSDF-sampled ray sees) and pdf (the solid-angle pdf with which sampling produces
a direction: a deterministic function of the point and the direction, so whatever
strategy the sampler chose for the point, the pdf chooses the same, and the power
heuristic weights of multiple importance sampling sum to one;
tests/test_kernel_lights.py checks that every sample is found again with its pdf).

Strategies (all pdfs in solid angle, omega = solid angle subtended, A = area):
- sphere light outside the sphere: the uniform cone it subtends, pdf 1 / (2 pi (1 - cos
  theta_max)) with sin^2 theta_max = r^2 / d^2 (1 - cos computed without cancellation so
  a 1e-6 m light 1e4 m away keeps its precision); inside: uniform sphere, 1 / (4 pi).
- sun disc: uniform cone, 1 / (2 pi (1 - cos(a/2))), 1 - cos(x) = 2 sin^2(x/2).
- rectangle and square area lights: uniform in the spherical rectangle they subtend,
  pdf 1 / omega (Urena, Fajardo, King 2013, "An Area-Preserving Parametrization for
  Spherical Rectangles", EGSR), rewritten here in a cancellation-free form (see
  spherical_rectangle.py). Fallback to uniform area sampling, pdf d^2 / (A |cos theta_l|),
  when (area.py):
    omega < SOLID_ANGLE_MIN           (far or edge-on light: area sampling is then as good
                                       and the spherical inversion loses digits),
    |z| < IN_PLANE_REL x (edge sum)   (p almost in the light's plane: omega -> 0 or 2 pi),
    the edges are not perpendicular   (a sheared transform makes a parallelogram).
- disk and ellipse area lights: uniform area sampling (Shirley-Chiu concentric map), as
  Cycles does for ellipses.
- point light with soft_falloff and r > 0: uniform area sampling of the facing disc.

Use:

    L = pack_lights(light_set)                 # once per scene (NumPy arrays)
    recv = receiver(px, py, pz, nx, ny, nz, mode)   # the shading point (tree.py)
    k, wix, wiy, wiz, dist, r, g, b, pdf, delta, light_prim, margin = sample(
        L, recv, u_pick, u1, u2, time)
    t, k, r, g, b = hit_lamps(L, ox, oy, oz, dx, dy, dz, tmax, ray_bit, time)   # nearest
    n_lamps(L);  t, r, g, b = lamp_hit(L, k, ox, oy, oz, dx, dy, dz, ray_bit, time)
    lamp_pdf(L, k, recv, wix, wiy, wiz, t, time)     # recv: the ray's origin's receiver
    mesh_pdf(L, prim, recv, qx, qy, qz, time)
    environment_pdf(L, dx, dy, dz, recv, time);  environment_radiance(L) -> (r, g, b)
    world_escaped(L, world, ray_bit, dx, dy, dz, recv, time) -> (r, g, b, pdf)
    n_suns(L);  sun_escaped(L, j, dx, dy, dz, recv, time) -> (r, g, b, pdf);  sun_entry(L, j)
    n_entries(L);  entry_visibility(L, k)
    select_pdf(L, k, recv, time)                     # the probability `sample` picks k
    pick_entry(L, recv, u_pick, time) -> (k, probability)   # as `sample` picks
    pick(L, u_pick) -> k                             # by L[SELECT_PDF] alone
    sample_entry(L, k, px, py, pz, u1, u2, time)     # one entry, pick not included
    entry_center(L, k, time) -> (has_one, x, y, z)   # towards which distances are sampled

Every pdf is in solid angle with the pick probability included: the light tree's for the
receiver (tree.py), as Cycles picks lights by default, or LightSet.select_pdf (Cycles'
distribution without the tree) when the tree is off. `time` is the ray's shutter time in
[0, 1]: a lamp that moves during the shutter is its slice at that time (pack.py,
TimeSlicedLight). Array drivers for tests: `batch`.
"""
from .light_set import (entry_center, environment_pdf, environment_radiance, hit_lamps,
                        is_uniform_world, lamp_hit, lamp_pdf, entry_visibility, mesh_pdf,
                        n_entries, n_lamps, n_suns, pick, pick_entry, sample,
                        sample_entry, select_pdf, sun_entry, sun_escaped,
                        world_escaped)
from .pack import pack_lights
from .tree import OMNI, ONE_SIDED, SEGMENT, TWO_SIDED, receiver, segment_receiver

__all__ = ["pack_lights", "n_entries", "n_lamps", "sample", "hit_lamps", "lamp_hit",
           "entry_visibility", "entry_center", "pick", "select_pdf",
           "sample_entry", "pick_entry", "receiver", "segment_receiver", "OMNI",
           "ONE_SIDED", "TWO_SIDED", "SEGMENT",
           "lamp_pdf", "mesh_pdf", "environment_pdf", "environment_radiance", "n_suns",
           "sun_escaped", "world_escaped", "is_uniform_world"]
