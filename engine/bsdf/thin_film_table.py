"""The spectral sensitivity table of thin-film interference (engine/kernels/bsdf/
thin_film.py), as Cycles builds it for its Principled BSDF's Thin Film (Belcour and Barla
2017, "A Practical Extension to Microfacet Theory for the Modeling of Varying
Iridescence"): the Fourier transform of the colour matching functions over frequency, so
that the reflectance of a film, a sum of cosines of the phase in wavelength, integrates
over the spectrum into scene-linear RGB without sampling wavelengths.

Row k of the table is the optical path difference OPD_k = k x 60000 / (2 pi 511) nm
(about 18.7 nm a row, 0 to 9.55 um over 512 rows), and holds, per channel c of
scene-linear Rec.709, the real and imaginary parts of

    S_c(OPD) = sum_j cmf_c(f_j) exp(-2 pi i j k / N),   f_j = j pi / 60 per um, N = 1022,

the CMFs resampled at the frequencies f_j (wavelength 1000 / f_j nm, with the density's
Jacobian 1 / f^2, cubic-spline interpolated between the 1 nm data, zero outside
360-830 nm), over their DC term, so that S_c(0) = 1. The XYZ CMFs are turned into
Rec.709's by the matrix of Blender's colour configuration (XYZ D65 to Linear Rec.709;
Cycles reaches the same through the ACES interchange role); the transform and the
normalisation are linear, so the XYZ table is transformed row by row.

The CMFs: CIE 1931 2-degree standard observer, 1 nm from 360 to 830 nm (CVRL's table,
as the colour-science package 0.4.4 ships it), in engine/bsdf/data/cie1931_2deg.npz
(`wavelength_nm` (471,), `xyz` (471, 3)); a zero row at 359 nm closes the spline at the
short end, as the data ends there.

The kernels read the table from engine/bsdf/data/thin_film_rec709.npy (`load`; building
it imports SciPy's spline, a second of a render's start); rebuild that file with

    python -m engine.bsdf.thin_film_table

(tests/test_thin_film.py checks that it is what `build` makes).
"""
from __future__ import annotations

import os
import threading

import numpy as np

ROWS = 512                 # complex values: the rfft of N = 1022 real samples
SAMPLES = 2 * (ROWS - 1)
END_UM = 60.0              # the frequency grid's scale: f_j = j pi / END_UM per um
# XYZ (D65) to Linear Rec.709, Blender's colour configuration (config.ocio)
XYZ_TO_REC709 = np.array([[3.2409699, -1.5373832, -0.4986108],
                          [-0.9692436, 1.8759675, 0.0415551],
                          [0.0556301, -0.2039770, 1.0569715]])
DATA = os.path.join(os.path.dirname(__file__), "data", "cie1931_2deg.npz")
TABLE = os.path.join(os.path.dirname(__file__), "data", "thin_film_rec709.npy")

_lock = threading.Lock()
_table = None


def xyz_table() -> np.ndarray:
    """(ROWS, 3) complex: the Fourier transform of the resampled XYZ CMFs."""
    from scipy.interpolate import CubicSpline
    data = np.load(DATA)
    wl = np.concatenate([[359.0], data["wavelength_nm"]])
    xyz = np.concatenate([np.zeros((1, 3)), data["xyz"]])
    spline = CubicSpline(wl, xyz, axis=0, extrapolate=False)
    freqs = np.linspace(0.0, np.pi * (SAMPLES - 1) / END_UM, SAMPLES)
    freqs = np.maximum(freqs, 1e-40)
    resampled = np.nan_to_num(spline(1000.0 / freqs) / (freqs * freqs)[:, None])
    return np.fft.rfft(resampled, axis=0)


def build(xyz_to_rgb=XYZ_TO_REC709) -> np.ndarray:
    """(6, ROWS) float64: the real parts of S_r, S_g, S_b, then their imaginary parts."""
    spectrum = xyz_table()
    re = spectrum.real @ np.asarray(xyz_to_rgb).T
    im = spectrum.imag @ np.asarray(xyz_to_rgb).T
    norm = 1.0 / re[0]
    return np.ascontiguousarray(np.concatenate([(re * norm).T, (im * norm).T]))


def load() -> np.ndarray:
    """The table for scene-linear Rec.709 (TABLE, read once per process)."""
    global _table
    if _table is None:
        with _lock:
            if _table is None:
                _table = np.ascontiguousarray(np.load(TABLE), dtype=np.float64)
    return _table


if __name__ == "__main__":
    np.save(TABLE, build())
    print(f"wrote {TABLE}")
