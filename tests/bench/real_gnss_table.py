#!/usr/bin/env python3
"""The table of tests/bench/real_gnss.sh: per window and solution, horizontal RMS / median / p95
and vertical RMS (m) of the raw fixes, the floor, the graph fusion (smoothed and online) and the
paper's KF, from the `gvio eval --errors-csv` files the benchmark wrote.

    real_gnss_table.py OUT SOLUTION...

The floor is the window's robust mean fix error: the per-axis median of the fixes' east and north
errors, its length. A bias common to the window's fixes is indistinguishable from where the drive
really is, for any fusion: an estimate's horizontal RMS cannot be expected below it. With RTK, the
fused errors at the epochs the solution called fixed are given apart (the target: median <= 0.10 m,
RMS <= 0.5 m there)."""
import csv
import math
import os
import sys


def read(path):
    try:
        with open(path) as f:
            return [r for r in csv.DictReader(f)]
    except OSError:
        return None


def percentile(values, q):
    s = sorted(values)
    if not s:
        return math.nan
    k = (len(s) - 1) * q
    lo, hi = math.floor(k), math.ceil(k)
    return s[lo] + (s[hi] - s[lo]) * (k - lo)


def stats(rows):
    if not rows:
        return None
    h = [math.hypot(float(r["dx_m"]), float(r["dy_m"])) for r in rows]
    v = [float(r["dz_m"]) for r in rows]
    return {
        "n": len(h),
        "rms": math.sqrt(sum(x * x for x in h) / len(h)),
        "median": percentile(h, 0.5),
        "p95": percentile(h, 0.95),
        "v_rms": math.sqrt(sum(x * x for x in v) / len(v)),
    }


def fmt(s):
    if s is None:
        return "failed"
    return f"{s['rms']:.2f} / {s['median']:.2f} / {s['p95']:.2f} / {s['v_rms']:.2f}"


def floor(rows):
    if not rows:
        return math.nan
    return math.hypot(percentile([float(r["dx_m"]) for r in rows], 0.5),
                      percentile([float(r["dy_m"]) for r in rows], 0.5))


out, solutions = sys.argv[1], sys.argv[2:]
cells = sorted((d for d in os.listdir(out) if d.startswith("nagoya_")),
               key=lambda d: float(d.split("_t")[1].split("_")[0])) if os.path.isdir(out) else []
print("Fusion on a real receiver's errors (Nagoya): horizontal RMS / median / p95 / vertical RMS (m)")
print()
print("| window | solution | fixes (n) | raw fixes | floor | graph | graph online | KF (paper) |")
print("| --- | --- | --- | --- | --- | --- | --- | --- |")
fixed_rows = []
for cell in cells:
    window = cell.removeprefix("nagoya_").replace("_", " ")
    for sol in solutions:
        fixes = read(os.path.join(out, cell, f"{sol}.fixes.errors.csv"))
        if fixes is None:
            continue
        row = [window, sol, str(len(fixes)), fmt(stats(fixes)), f"{floor(fixes):.2f}"]
        for run, which in (("graph", "final"), ("graph", "online"), ("kf", "final")):
            rows = read(os.path.join(out, cell, f"{sol}.{run}", f"{which}.errors.csv"))
            row.append(fmt(stats(rows)) if rows is not None else "not run")
            if sol == "rtk" and rows is not None:
                fixed_t = {round(float(r["t_s"]), 1) for r in fixes if r["quality"] == "4"}
                at_fixed = [r for r in rows if round(float(r["t_s"]), 1) in fixed_t]
                fixed_rows.append((window, f"{run} {which}", stats(at_fixed), len(fixed_t)))
        print("| " + " | ".join(row) + " |")
if fixed_rows:
    print()
    print("RTK, at the epochs the solution called fixed: horizontal RMS / median / p95 / vertical RMS (m)")
    print()
    print("| window | estimate | fixed epochs | fused at them |")
    print("| --- | --- | --- | --- |")
    for window, name, s, n in fixed_rows:
        print(f"| {window} | {name} | {n} | {fmt(s) if s else 'none'} |")
