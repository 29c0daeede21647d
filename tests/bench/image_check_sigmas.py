#!/usr/bin/env python3
"""The image check's standardised residuals over tests/bench/image_check_matrix.sh's true poses.

For each cell of BENCH_OUT (default out/bench/image_check_matrix) that holds a `truth` run, reads
consistency_images/keyframes.csv and prints: the keyframes scored, the lowest standardised ZNCC and
depth-agreement residuals (`ncc_sigmas`, `depth_sigmas`: how many of their sigmas a keyframe lies
from what is typical, negative below), the keyframes flagged (every one a false alarm) and how many
of them drew their map nearer than NEAR_M (drawn_depth_m, 15 m: the views drawn as near), and the
median residuals of the keyframes drawn that near, and the run's self-check (summary.json
`self_check`: the median depth agreement of keyframes drawn from their own points). The figures
behind the flag rule's items 3 and 7 in docs/benchmarks/image-check.md; item 7 is measured
without the rule's own correction too:

    BENCH_SEEDS="1 2" BENCH_FAULTS=side:0.5 tests/bench/image_check_matrix.sh
    tests/bench/image_check_sigmas.py out/bench/image_check_matrix
    BENCH_SEEDS=2 BENCH_FAULTS=side:0.5 BENCH_ARGS="--similar-views 0" \
      BENCH_OUT=out/bench/image_check_sv0 tests/bench/image_check_matrix.sh
    tests/bench/image_check_sigmas.py out/bench/image_check_sv0
"""
import csv
import json
import math
import os
import statistics
import sys

NEAR_M = 15.0


def number(text):
    """The CSV's number, None where it is empty or NaN (a score the keyframe does not have)."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        return None
    return None if math.isnan(value) else value


def near(row):
    depth = number(row["drawn_depth_m"])
    return depth is not None and depth < NEAR_M


def check_file(cell, name):
    """A file of the cell's check along its true poses."""
    return os.path.join(cell, "truth", "consistency_images", name)


def cell_rows(cell):
    path = check_file(cell, "keyframes.csv")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return list(csv.DictReader(f))


def self_check(cell):
    """The run's self-check: the median depth agreement of keyframes drawn from their own points."""
    path = check_file(cell, "summary.json")
    try:
        with open(path) as f:
            value = json.load(f)["self_check"]["depth_agreement_median"]
    except (OSError, ValueError, KeyError, TypeError):
        return ""
    return f"{value:.3f}"


def shown(value, digits=2):
    return "" if value is None else f"{value:+.{digits}f}"


def lowest(rows, key):
    values = [(number(r[key]), float(r["t_from_start_s"])) for r in rows]
    values = [v for v in values if v[0] is not None]
    if not values:
        return ""
    z, t = min(values)
    return f"{z:+.2f} at {t:.1f} s"


def near_median(rows, key):
    values = [number(r[key]) for r in rows if near(r)]
    values = [v for v in values if v is not None]
    if not values:
        return "", 0
    return shown(statistics.median(values)), len(values)


def at(flagged):
    times = [float(r["t_from_start_s"]) for r in flagged]
    return ", " + " ".join(f"{t:.1f}" for t in times) if times else ""


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "out/bench/image_check_matrix"
    if not os.path.isdir(out):
        sys.exit(f"bench: {out}: no such folder (run tests/bench/image_check_matrix.sh)")
    head = ["cell", "keyframes", "lowest ZNCC sigmas", "lowest depth sigmas",
            f"flagged: all / drawn nearer than {NEAR_M:g} m, at (s)",
            f"drawn nearer than {NEAR_M:g} m: keyframes, median ZNCC / depth sigmas",
            "self-check depth agreement"]
    print("The image check's standardised residuals with the true poses (keyframes.csv "
          "ncc_sigmas, depth_sigmas)")
    print()
    print("| " + " | ".join(head) + " |")
    print("|" + " --- |" * len(head))
    cells = 0
    for name in sorted(os.listdir(out)):
        cell = os.path.join(out, name)
        rows = cell_rows(cell)
        if not rows:
            continue
        cells += 1
        flagged = [r for r in rows if r["flagged"] == "1"]
        ncc_near, n_near = near_median(rows, "ncc_sigmas")
        depth_near, _ = near_median(rows, "depth_sigmas")
        print(f"| {name} | {len(rows)} | {lowest(rows, 'ncc_sigmas')} | "
              f"{lowest(rows, 'depth_sigmas')} | {len(flagged)} / {sum(map(near, flagged))}"
              f"{at(flagged)} | "
              f"{n_near}, {ncc_near} / {depth_near} | {self_check(cell)} |")
    if not cells:
        sys.exit(f"bench: {out}: no cell with a truth run")


if __name__ == "__main__":
    main()
