"""The Metallic BSDF node (Blender 4.3+) as the Principled metal lobe it equals in Cycles
(svm/closure.h, CLOSURE_BSDF_F82_CONDUCTOR and CLOSURE_BSDF_PHYSICAL_CONDUCTOR).

- **F82 Tint** (the node's default): Cycles sets up the same microfacet lobe with the
  same F82-tint Fresnel as Principled's metal, F0 the Base Color and the F82 tint the
  Edge Tint, both clamped to [0, 1]. So it is a Principled metal with that Specular Tint.
- **Physical Conductor**: Cycles evaluates the exact Fresnel of a conductor of complex
  index n + ik per channel (IOR, Extinction). DRT renders the F82-tint model fitted to
  it (Kutz et al. 2021, the model's own purpose): F0 the conductor's reflectance at
  normal incidence, the tint the ratio of its reflectance at mu = 1/7 (about 82 degrees)
  to Schlick's there, so the two agree at 0 and 82 degrees and the fit is reported.
  `fit_error` gives its largest difference over all angles (measured for Blender's
  default IOR and Extinction: see tests/test_metallic_node.py).
"""
from __future__ import annotations

import numpy as np

MU_BAR = 1.0 / 7.0                    # cos(82 degrees), where the F82 tint applies


def conductor_fresnel(mu, n, k):
    """Unpolarised Fresnel reflectance of a conductor n + ik from a dielectric of index 1,
    at cosines `mu` (broadcast against n and k)."""
    mu = np.clip(np.asarray(mu, np.float64), 0.0, 1.0)
    eta = np.asarray(n, np.float64) + 1j * np.asarray(k, np.float64)
    sin2 = 1.0 - mu * mu
    cos_t = np.sqrt(1.0 - sin2 / (eta * eta))
    rs = (mu - eta * cos_t) / (mu + eta * cos_t)
    rp = (eta * mu - cos_t) / (eta * mu + cos_t)
    return 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)


def schlick(mu, f0):
    return f0 + (1.0 - f0) * (1.0 - mu) ** 5


def f82_fit(n, k):
    """(F0, F82 tint) per channel of the F82-tint model fitted to conductor n + ik."""
    n, k = np.maximum(np.asarray(n, np.float64), 0.0), np.maximum(np.asarray(k, np.float64), 0.0)
    f0 = conductor_fresnel(1.0, n, k)
    tint = conductor_fresnel(MU_BAR, n, k) / schlick(MU_BAR, f0)
    return np.clip(f0, 0.0, 1.0), np.clip(tint, 0.0, 1.0)


def f82_tint(mu, f0, tint):
    """Cycles' F82-tint Fresnel (fresnel_f82tint_B and its use)."""
    b = schlick(MU_BAR, f0) * (1.0 - tint) / (MU_BAR * (1.0 - MU_BAR) ** 6)
    return np.clip(schlick(mu, f0) - b * mu * (1.0 - mu) ** 6, 0.0, 1.0)


def fit_error(n, k, samples=1001):
    """Largest |F82-tint fit - exact conductor Fresnel| over cosines in [0, 1]."""
    mu = np.linspace(0.0, 1.0, samples)[:, None]
    f0, tint = f82_fit(n, k)
    return float(np.abs(f82_tint(mu, f0, tint) - conductor_fresnel(mu, n, k)).max())


def metal_inputs(node, ctx, color_input, constant):
    """(base colour, F82 tint) of a Metallic BSDF node: Base Color (texturable, through
    `color_input(name, default)`) and Edge Tint, or the fit to IOR and Extinction
    (constants, through `constant(name, default)`)."""
    if getattr(node, "fresnel_type", "F82") == "PHYSICAL_CONDUCTOR":
        n = constant("IOR", (2.757, 2.513, 2.231))
        k = constant("Extinction", (3.867, 3.404, 3.009))
        f0, tint = f82_fit(np.asarray(n, np.float64)[:3], np.asarray(k, np.float64)[:3])
        ctx.issue(f"{node.name!r} is a Physical Conductor; DRT renders the F82-tint fit to "
                  f"its IOR and Extinction (exact at 0 and 82 degrees, within "
                  f"{fit_error(np.asarray(n)[:3], np.asarray(k)[:3]):.3f} elsewhere)")
        return tuple(float(x) for x in f0), tuple(float(x) for x in tint)
    tint = constant("Edge Tint", (0.695, 0.726, 0.770))
    return color_input("Base Color", (0.617, 0.577, 0.540)), tuple(float(x) for x in tint[:3])
