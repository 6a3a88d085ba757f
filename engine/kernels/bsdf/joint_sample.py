"""The lobe and its direction from one stratified 2D sample: the path tracer's BSDF
sampling (path_vertex). `sample_joint` chooses the Principled lobe with the direction's
first number and rescales that number within the lobe's share (pbrt's remapping of a
BSDF component's sample), so the directions a lobe is given are as evenly spread as the
pixel's samples. An independent lobe number gives each lobe a random subset of them:
a Principled plastic's highlight under an area lamp then had 2.5 times the per-pixel
noise of Cycles', whose closure choice and direction are one stratified 3D point
(tests/test_joint_lobe_sampling.py)."""
from __future__ import annotations

from ..jit import kernel
from .principled import ONE_MINUS_EPS, sample, selection


@kernel(allocates=False)
def sample_joint(state, wox, woy, woz, u_rest, u1, u2, allow_d, allow_g, allow_t):
    """principled.sample, the lobe chosen with u1 and u1 rescaled within the lobe's
    share for its direction; u_rest, independent, is `sample`'s rest of the lobe number
    (a glass's reflection or refraction, the Principled Hair's lobe)."""
    q = selection(state, allow_d, allow_g, allow_t)
    lo = 0.0
    total = 0.0
    q_sel = 0.0
    for k in range(11):
        if q[k] > 0.0 and (u1 >= total or q_sel == 0.0):
            lo, q_sel = total, q[k]
        total += q[k]
    if not q_sel > 0.0:
        return sample(state, wox, woy, woz, u_rest, u1, u2, allow_d, allow_g, allow_t)
    u_dir = min(max((u1 - lo) / q_sel, 0.0), ONE_MINUS_EPS)
    u_lobe = lo + u_rest * q_sel
    if not u_lobe < lo + q_sel:
        u_lobe = lo
    return sample(state, wox, woy, woz, u_lobe, u_dir, u2, allow_d, allow_g, allow_t)
