"""What the Cycles comparison tests measure, kept for the docs: with DRT_FIGURES=FILE in
the environment, `record` appends one JSON line per comparison to FILE, named by the test
that made it (docs/make_feature_figures.py runs the tests so and writes
docs/features_vs_cycles.md); without it, it does nothing. The tests still assert on their
figures: this only lets a script print them, so the docs quote no figure by hand."""
from __future__ import annotations

import json
import os

AGAINST_CYCLES = "DRT against Cycles"


def record(what: str, **figures: float) -> None:
    """One comparison: `what` says which (AGAINST_CYCLES, or "control: ..." for a render
    with the feature left out, which the test requires to differ), `figures` its numbers
    (mean and block: differences over the image mean, as fractions)."""
    path = os.environ.get("DRT_FIGURES")
    if not path:
        return
    test = os.environ.get("PYTEST_CURRENT_TEST", "").split(" ")[0]
    row = {"test": test, "what": what, **{k: float(v) for k, v in figures.items()}}
    with open(path, "a") as f:
        f.write(json.dumps(row) + "\n")
