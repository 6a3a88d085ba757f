"""The Cornell sample renders through bpy.ops.render.render with DRT and matches Cycles.

Direct light only (diffuse bounces 0 in both engines), the issue's threshold: the mean
brightness per channel within 10% of Cycles'. Bands of rows are compared too, so an image
written upside down (Blender's rows are bottom-up) fails even though its mean is right.
"""
import os

import numpy as np
import pytest

from conftest import SAMPLES_DIR, render_blend

CORNELL = os.path.join(SAMPLES_DIR, "cornell_box.blend")
MEAN_TOLERANCE = 0.10


def _direct_only(scene):
    scene.cycles.diffuse_bounces = 0


@pytest.fixture(scope="module")
def renders(bpy_drt):
    drt = render_blend(bpy_drt, CORNELL, "DRT", samples=32, setup=_direct_only)
    cycles = render_blend(bpy_drt, CORNELL, "CYCLES", samples=64, setup=_direct_only)
    return drt, cycles


def test_drt_image_is_finite_and_not_constant(renders):
    drt, _ = renders
    assert drt.shape == (128, 128, 3)
    assert np.isfinite(drt).all()
    assert drt.std() > 0.05
    assert drt.max() > 0.2


def test_mean_per_channel_within_ten_percent_of_cycles(renders):
    drt, cycles = renders
    m_drt, m_cyc = drt.mean(axis=(0, 1)), cycles.mean(axis=(0, 1))
    rel = np.abs(m_drt - m_cyc) / m_cyc
    print("DRT mean", m_drt, "Cycles mean", m_cyc, "relative difference", rel)
    assert (rel < MEAN_TOLERANCE).all(), (m_drt, m_cyc, rel)


def test_rows_are_in_the_right_order(renders):
    drt, cycles = renders
    bands_drt = drt.reshape(4, 32, 128, 3).mean(axis=(1, 2, 3))
    bands_cyc = cycles.reshape(4, 32, 128, 3).mean(axis=(1, 2, 3))
    # The floor (bottom band) is much brighter than the dark ceiling corners (top band).
    assert bands_cyc[3] > 1.3 * bands_cyc[0]
    assert np.all(np.abs(bands_drt - bands_cyc) / bands_cyc < 0.15), (bands_drt, bands_cyc)
