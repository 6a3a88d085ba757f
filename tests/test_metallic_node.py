"""The Metallic BSDF's Physical Conductor mode as DRT renders it
(drt_addon/export/nodes/metallic.py): the F82-tint model fitted to the conductor's exact
Fresnel. Checked against closed forms: the exact Fresnel at normal incidence is
((n-1)^2 + k^2) / ((n+1)^2 + k^2) and reaches 1 at grazing incidence; the fit equals it at
0 and at 82 degrees by construction; and over all angles it stays within 0.03 of it for
Blender's default IOR and Extinction and for gold, silver, copper and aluminium
(measured: printed below). Its render against Cycles is `metallic` in
tests/test_closures_vs_cycles.py."""
from __future__ import annotations

import numpy as np
import pytest

from drt_addon.export.nodes.metallic import (MU_BAR, conductor_fresnel, f82_fit, f82_tint,
                                              fit_error)

METALS = {  # n and k at about 650, 550 and 450 nm
    "Blender's default": ((2.757, 2.513, 2.231), (3.867, 3.404, 3.009)),
    "gold": ((0.18, 0.42, 1.37), (3.42, 2.35, 1.77)),
    "silver": ((0.14, 0.13, 0.13), (4.15, 3.35, 2.47)),
    "copper": ((0.27, 0.68, 1.22), (3.61, 2.63, 2.29)),
    "aluminium": ((1.35, 0.96, 0.62), (7.47, 6.40, 5.28)),
}


@pytest.mark.parametrize("metal", list(METALS))
def test_the_f82_fit_agrees_with_the_exact_fresnel(metal):
    n, k = (np.asarray(v) for v in METALS[metal])
    np.testing.assert_allclose(conductor_fresnel(1.0, n, k),
                               ((n - 1) ** 2 + k ** 2) / ((n + 1) ** 2 + k ** 2), rtol=1e-12)
    np.testing.assert_allclose(conductor_fresnel(0.0, n, k), 1.0, rtol=1e-12)
    f0, tint = f82_fit(n, k)
    for mu in (1.0, MU_BAR):
        np.testing.assert_allclose(f82_tint(mu, f0, tint), conductor_fresnel(mu, n, k),
                                   rtol=1e-9)
    err = fit_error(n, k)
    print(f"{metal}: F0 {np.round(f0, 3)}, tint {np.round(tint, 3)}, largest error {err:.4f}")
    assert err < 0.03


def test_the_fit_differs_from_schlick_alone():
    """The tint matters: without it (white) the model misses the default conductor's
    exact Fresnel by far more than the fit does."""
    n, k = (np.asarray(v) for v in METALS["Blender's default"])
    f0, tint = f82_fit(n, k)
    mu = np.linspace(0, 1, 1001)[:, None]
    untinted = np.abs(f82_tint(mu, f0, np.ones(3)) - conductor_fresnel(mu, n, k)).max()
    assert untinted > 3 * fit_error(n, k)
