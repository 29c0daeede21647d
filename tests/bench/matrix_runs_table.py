#!/usr/bin/env python3
"""One line per run of tests/bench/vio_matrix.sh: the stereo+IMU APE over its cells (geometric
mean, in m and in % of the path) and the cells within the 0.10 % target, read from what the
script printed (its standard output, or a committed tests/bench/results file): its summary lines
where it has them (exact), else the table's rounded columns.

    matrix_runs_table.py [--title TEXT] [--what HEADER] [--cells] LABEL=TABLE_FILE...

e.g. `assumed=tests/bench/results/vio_matrix_stereo_imu.txt truth:1=out/bench/vio_imu_truth1.txt`:
what the estimator was told of the IMU noise against the drives' own noise (BENCH_IMU_NOISE,
the defaults of --title and --what); or the same drives simulated with sensor effects
(BENCH_SIM_SET) against the plain ones. --cells adds each cell's APE (m) to its line."""
import argparse
import math
import re
import sys

TARGET = 0.10  # % of the path


def cells(text, path):
    """(style seed, APE m, APE %) of each cell (APEs None where it failed) in a vio_matrix
    table."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip().startswith("|")]
    if not lines:
        sys.exit(f"matrix_runs_table: {path}: no table")
    head = [c.strip() for c in lines[0].strip("|").split("|")]
    try:
        style_col, seed_col = head.index("style"), head.index("seed")
        m_col, pct_col = head.index("stereo-imu APE (m)"), head.index("stereo-imu APE %")
    except ValueError:
        sys.exit(f"matrix_runs_table: {path}: no seed and stereo-imu APE (m) and % columns")
    out = []
    for ln in lines[2:]:
        row = [c.strip() for c in ln.strip("|").split("|")]
        if len(row) != len(head) or not row[seed_col]:  # the "worst" rows carry no seed
            continue
        try:
            out.append((f"{row[style_col]} {row[seed_col]}", float(row[m_col]),
                        float(row[pct_col])))
        except ValueError:
            out.append((f"{row[style_col]} {row[seed_col]}", None, None))
    return out


def geometric_mean(values):
    return math.exp(sum(math.log(v) for v in values) / len(values)) if values else math.nan


parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--title", default="Stereo+IMU over the matrix's cells: the IMU noise the "
                    "estimator is told, SE(3)-aligned APE")
parser.add_argument("--what", default="the estimator's IMU noise",
                    help="the first column's header: what the runs differ in")
parser.add_argument("--cells", action="store_true", help="add each cell's APE (m)")
parser.add_argument("runs", nargs="+", metavar="LABEL=TABLE_FILE")
args = parser.parse_args()

print(args.title)
print()
print(f"| {args.what} | cells | failed | geometric mean APE (m) "
      f"| geometric mean APE (% of the path) | within {TARGET:.2f} % |"
      + (" each cell's APE (m) |" if args.cells else ""))
print("| --- | --- | --- | --- | --- | --- |" + (" --- |" if args.cells else ""))
for arg in args.runs:
    label, sep, path = arg.rpartition("=")  # a label may hold "=" (a setting)
    if not sep:
        sys.exit(f"matrix_runs_table: '{arg}' is not LABEL=FILE")
    with open(path) as f:
        text = f.read()
    values = cells(text, path)
    ok = [(m, pct) for _, m, pct in values if m is not None and m > 0.0 and pct > 0.0]
    geo_m = geometric_mean([m for m, _ in ok])
    geo = geometric_mean([pct for _, pct in ok])
    within = sum(1 for _, pct in ok if pct <= TARGET)
    # "cells meet" in outputs before 6544b45, "cells within" since.
    met = re.search(r"^stereo-imu: (\d+) of (\d+) cells (?:meet|within)", text, re.M)
    if met and int(met.group(2)) == len(values):
        within = int(met.group(1))
    mean = re.search(r"^stereo-imu: geometric mean APE ([0-9.]+) %", text, re.M)
    if mean:
        geo = float(mean.group(1))
    each = ""
    if args.cells:
        each = " " + ", ".join(f"{cell} {m:.3f}" if m is not None else f"{cell} failed"
                               for cell, m, _ in values) + " |"
    print(f"| {label} | {len(values)} | {len(values) - len(ok)} | {geo_m:.4f} | {geo:.4f} "
          f"| {within} |{each}")
