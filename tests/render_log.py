"""Where the suite's rendering time goes: sums a DRT_TEST_RENDER_LOG file (written by
tests/conftest.py) by engine and by test file, longest first.

    DRT_TEST_RENDER_LOG=/tmp/renders.jsonl .venv/bin/python -m pytest
    .venv/bin/python tests/render_log.py /tmp/renders.jsonl
"""
from __future__ import annotations

import collections
import json
import sys


def main(path: str) -> None:
    rows = [json.loads(line) for line in open(path)]
    by_engine, by_file = collections.Counter(), collections.Counter()
    by_test = collections.Counter()
    for r in rows:
        by_engine[r["engine"]] += r["seconds"]
        by_file[(r["test"].split("::")[0], r["engine"])] += r["seconds"]
        by_test[(r["test"], r["engine"], r["samples"], tuple(r["size"]))] += r["seconds"]
    print(f"{len(rows)} renders, {sum(by_engine.values()):.0f} s")
    for engine, s in by_engine.most_common():
        print(f"  {engine}: {s:.0f} s")
    print("by test file and engine:")
    for (f, engine), s in by_file.most_common(30):
        print(f"  {s:7.1f} s  {engine:7s} {f}")
    print("by test, engine, samples and size:")
    for (t, engine, spp, size), s in by_test.most_common(40):
        print(f"  {s:7.1f} s  {engine:7s} {spp:5d} spp {size[0]}x{size[1]}  {t}")


if __name__ == "__main__":
    main(sys.argv[1])
