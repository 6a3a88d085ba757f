"""DRT against Cycles, feature by feature: runs the Cycles comparison tests below (pytest,
with DRT_FIGURES set, so each comparison a test makes is recorded: tests/figures.py) and
writes what each measured to docs/features_vs_cycles.md, so that no page quotes such a
figure by hand.

    .venv/bin/python docs/make_feature_figures.py                 # every test below
    .venv/bin/python docs/make_feature_figures.py --tests tests/test_thin_film_vs_cycles.py

A run of some tests replaces their rows and keeps the others' from the last run
(docs/features_vs_cycles.json).
"""
from __future__ import annotations

import argparse
import ast
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

DOCS = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(DOCS)
PAGE = os.path.join(DOCS, "features_vs_cycles.md")
SAVED = os.path.join(DOCS, "features_vs_cycles.json")

# the Cycles comparison tests whose comparisons go through tests/node_probe.image_errors
# (or record their own figures); nodes.md has the node tests' figures
TESTS = ["tests/test_anisotropic_vs_cycles.py", "tests/test_coat_normal_vs_cycles.py",
         "tests/test_thin_film_vs_cycles.py", "tests/test_layered_emission_vs_cycles.py",
         "tests/test_triangle_lights_vs_cycles.py", "tests/test_oren_nayar_vs_cycles.py",
         "tests/test_emission_sampling_vs_cycles.py", "tests/test_bent_sheen_vs_cycles.py",
         "tests/test_bent_translucency_vs_cycles.py", "tests/test_normal_map_vs_cycles.py",
         "tests/test_bump_vs_cycles.py", "tests/test_terminator_vs_cycles.py",
         "tests/test_instances_vs_cycles.py", "tests/test_light_distribution_vs_cycles.py",
         "tests/test_bounce_budget_vs_cycles.py", "tests/test_caustics_switches_vs_cycles.py",
         "tests/test_shadow_ray_glass_vs_cycles.py", "tests/test_lights_vs_cycles.py",
         "tests/test_displacement_vs_cycles.py", "tests/test_ao_pass.py",
         "tests/test_mixed_emission_vs_cycles.py", "tests/test_area_spread_vs_cycles.py"]


def run_tests(tests) -> dict:
    """{test file: {"doc": first docstring line, "tests": {node id: {"outcome",
    "figures": [record, ...]}}}} from one pytest run."""
    with tempfile.TemporaryDirectory() as d:
        figures, junit = os.path.join(d, "figures.jsonl"), os.path.join(d, "junit.xml")
        env = dict(os.environ, DRT_FIGURES=figures)
        subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                        f"--junitxml={junit}", *tests], cwd=ROOT, env=env, check=False)
        records = []
        if os.path.exists(figures):
            with open(figures) as f:
                records = [json.loads(line) for line in f]
        outcomes = _outcomes(junit)
    out = {}
    for path in tests:
        rows = {tid: {"outcome": o, "figures": []} for tid, o in outcomes.items()
                if tid.startswith(path + "::")}
        for r in records:
            if r["test"].startswith(path + "::"):
                rows.setdefault(r["test"], {"outcome": "?", "figures": []})["figures"].append(
                    {k: v for k, v in r.items() if k != "test"})
        out[path] = {"doc": _first_line(path), "tests": rows}
    return out


def _outcomes(junit: str) -> dict:
    """{node id: passed | failed | skipped} from pytest's JUnit XML."""
    if not os.path.exists(junit):
        return {}
    out = {}
    for case in ET.parse(junit).getroot().iter("testcase"):
        path = case.get("classname", "").replace(".", "/") + ".py"
        outcome = "passed"
        for child in case:
            if child.tag in ("failure", "error"):
                outcome = "failed"
            elif child.tag == "skipped":
                outcome = "skipped"
        out[f"{path}::{case.get('name')}"] = outcome
    return out


def _first_line(path: str) -> str:
    with open(os.path.join(ROOT, path)) as f:
        doc = ast.get_docstring(ast.parse(f.read())) or ""
    return " ".join(doc.split("\n\n")[0].split())


def _figure(key, value) -> str:
    if key in ("mean", "block"):
        return f"{100 * value:.2f} %"
    return f"{key} {value:.4g}"


def _count(tests) -> dict:
    out: dict = {}
    for t in tests:
        out[t["outcome"]] = out.get(t["outcome"], 0) + 1
    return out


def page(saved: dict, meta: dict) -> str:
    passed = sum(t["outcome"] == "passed" for f in saved.values() for t in f["tests"].values())
    total = sum(len(f["tests"]) for f in saved.values())
    lines = ["# DRT against Cycles, feature by feature", "",
             "Written by `docs/make_feature_figures.py`, which runs the Cycles comparison "
             "tests below and writes what each measured; rerun it to reproduce "
             f"({meta['minutes']:.0f} minutes here for its last run). Machine: "
             f"{meta['machine']}. {passed} of {total} tests passed.", "",
             "Each test renders a small scene in both engines, Cycles at Blender's defaults, "
             "and asserts bounds on these figures: *mean* is the difference of the image "
             "means over Cycles' (of the worst channel where it says so), *block* the "
             "largest difference of the 8 x 8 pixel blocks' means over the image mean "
             "(where a local error or noise shows). A *control* is a render with the "
             "feature left out or changed, which the test requires to differ from Cycles: "
             "it shows what the feature buys and that the test can fail. The whole scenes "
             "are compared in [comparisons.md](comparisons.md), the nodes in "
             "[nodes.md](nodes.md).", ""]
    for path in sorted(saved):
        f = saved[path]
        lines += [f"## {path}", "", f["doc"], "",
                  "| test | outcome | comparison | mean | block | other |",
                  "|---|---|---|---|---|---|"]
        silent = [t for t in f["tests"].values() if not t["figures"]]
        for tid in sorted(f["tests"]):
            t = f["tests"][tid]
            name = tid.split("::", 1)[1]
            for k, r in enumerate(t["figures"]):
                other = ", ".join(_figure(key, v) for key, v in r.items()
                                  if key not in ("what", "mean", "block"))
                mean = _figure("mean", r["mean"]) if "mean" in r else ""
                block = _figure("block", r["block"]) if "block" in r else ""
                lines.append(f"| {name if k == 0 else ''} | {t['outcome'] if k == 0 else ''}"
                             f" | {r['what']} | {mean} | {block} | {other} |")
        if silent:
            outcomes = ", ".join(f"{n} {o}" for o, n in sorted(_count(silent).items()))
            lines += ["", f"The file's other {len(silent)} tests measure in other terms "
                          f"(see each test's docstring): {outcomes}."]
        lines.append("")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tests", default="", help="comma-separated test files (default: all)")
    ap.add_argument("--page", action="store_true", help="the page again from the last "
                    "run's figures (docs/features_vs_cycles.json), no test run")
    args = ap.parse_args(argv)
    tests = [t for t in args.tests.split(",") if t] or TESTS
    saved = {}
    if os.path.exists(SAVED):
        with open(SAVED) as f:
            saved = json.load(f)
    if args.page:
        with open(PAGE, "w") as f:
            f.write(page(saved["files"], saved["meta"]))
        return
    t0 = time.perf_counter()
    fresh = run_tests(tests)
    minutes = (time.perf_counter() - t0) / 60.0
    saved["files"] = {**saved.get("files", {}), **fresh}
    if tests == TESTS or "meta" not in saved:
        saved["meta"] = {"minutes": minutes,
                         "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python "
                                    f"{platform.python_version()}"}
    with open(SAVED, "w") as f:
        json.dump(saved, f, indent=1)
    with open(PAGE, "w") as f:
        f.write(page(saved["files"], saved["meta"]))
    print(f"wrote {PAGE}")


if __name__ == "__main__":
    main()
