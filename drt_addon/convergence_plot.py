"""convergence.png of a study (convergence.json's dict): error against samples (left) and
against render seconds (right), log-log, one row per metric (relMSE, RMSE, FLIP), one
curve per sampler and integrator (colour: sampler; line style: integrator), Cycles'
dashed in black. The legend gives each curve's fitted slope; a grey line marks the
floor the reference's own noise puts under every measurement.
"""
from __future__ import annotations

import zlib

ROWS = (("relmse", "relative MSE"), ("rmse", "RMSE"), ("flip", "FLIP (LDR)"))
SAMPLER_COLOURS = {"jittered": "tab:blue", "sobol": "tab:orange", "random": "tab:green"}
CLAMP_COLOURS = ("tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive")
INTEGRATOR_STYLES = {"path": "-", "distribution": ":", "whitted": "-."}


def _style(curve):
    if curve["engine"] == "Cycles":
        return {"color": "black", "linestyle": "--", "marker": "s"}
    if " clamp " in curve["label"]:          # a clamp curve of converge --clamps
        return {"color": CLAMP_COLOURS[zlib.crc32(curve["label"].encode()) % len(CLAMP_COLOURS)],
                "linestyle": "-", "marker": "^"}
    return {"color": SAMPLER_COLOURS.get(curve["sampler"], "tab:gray"),
            "linestyle": INTEGRATOR_STYLES.get(curve["integrator"], "-"), "marker": "o"}


def _slope_text(value) -> str:
    return "n/a" if value is None else f"{value:+.2f}"


def plot_study(study: dict, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(ROWS), 2, figsize=(15, 3.3 * len(ROWS)), squeeze=False)
    floor = study["reference"].get("noise_floor", {})
    for row, (metric, name) in enumerate(ROWS):
        for col, axis in enumerate(("samples", "seconds")):
            ax = axes[row][col]
            for curve in study["curves"]:
                ys = curve[metric]
                pts = [(x, y) for x, y in zip(curve[axis], ys) if y is not None and y > 0]
                if not pts:
                    continue
                slope = curve["slopes"][axis][metric]
                ax.plot(*zip(*pts), markersize=3, linewidth=1.3,
                        label=f"{curve['label']} ({_slope_text(slope)})", **_style(curve))
            if floor.get(metric):
                ax.axhline(floor[metric], color="0.6", linewidth=0.8, linestyle=(0, (2, 2)),
                           label="reference noise")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.grid(True, which="both", alpha=0.25)
            ax.set_xlabel("samples per pixel" if axis == "samples" else "render seconds")
            ax.set_ylabel(name)
            ax.legend(fontsize=7, title=f"slope vs {axis}", title_fontsize=7,
                      loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ref = study["reference"]
    fig.suptitle(f"{study['scene']} at {study['resolution'][0]}x{study['resolution'][1]}: "
                 f"error against {ref['engine']} {ref['samples']} spp", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
