#!/usr/bin/env python3
"""The table of tests/bench/real_gnss.sh: per window and solution, horizontal RMS / median / p95
and vertical RMS (m) of the raw fixes, the floor, the graph fusion (smoothed and online) and the
paper's KF, from the `gvio eval --errors-csv` files the benchmark wrote.

    real_gnss_table.py OUT SOLUTION...

The floor is the window's robust mean fix error: the per-axis median of the fixes' east and north
errors, its length. A bias common to the window's fixes is indistinguishable from where the drive
really is, for any fusion: an estimate's horizontal RMS cannot be expected below it. With RTK, the
fused errors at the epochs the solution called fixed are given apart, per window and over every
window's fixed epochs together (the target: median <= 0.10 m, RMS <= 0.5 m there).

The floor presumes the heading known. A VIO's heading is not (an IMU levels roll and pitch only):
it comes from the window's fixes, so errors that change along the track turn it. The shape fit is
the true track fitted to the window's fixes by a robust yaw and shift (Huber, 1.5 robust sigmas,
iterated): the error of a perfect VIO whose heading and position come from the fixes alone, with
the yaw that fit turns the track by (mrad)."""
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


def solve3(a, b):
    m = [a[i][:] + [b[i]] for i in range(3)]
    for c in range(3):
        p = max(range(c, 3), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        for r in range(3):
            if r != c:
                f = m[r][c] / m[c][c]
                for k in range(c, 4):
                    m[r][k] -= f * m[c][k]
    return [m[i][3] / m[i][i] for i in range(3)]


def read_tum_en(path):
    """t (0.1 s) -> (east, north) of a TUM file in ENU."""
    try:
        with open(path) as f:
            rows = [ln.split() for ln in f if ln.strip() and not ln.startswith("#")]
    except OSError:
        return None
    return {round(float(r[0]), 1): (float(r[1]), float(r[2])) for r in rows}


def shape_fit(fixes, truth):
    """(RMS over the window's true track, yaw in rad) of the robust yaw + shift fit of the fixes'
    errors e = yaw J (p - c) + t, J the 90-degree turn, c the fixes' centroid."""
    pairs = [(truth[t], (float(r["dx_m"]), float(r["dy_m"])))
             for r in fixes if (t := round(float(r["t_s"]), 1)) in truth]
    if len(pairs) < 3:
        return math.nan, math.nan
    cx = sum(p[0] for p, _ in pairs) / len(pairs)
    cy = sum(p[1] for p, _ in pairs) / len(pairs)

    def field(x, p):
        return (-x[0] * (p[1] - cy) + x[1], x[0] * (p[0] - cx) + x[2])

    weights, x = [1.0] * len(pairs), [0.0, 0.0, 0.0]
    for _ in range(50):
        a, b = [[0.0] * 3 for _ in range(3)], [0.0] * 3
        for (p, e), w in zip(pairs, weights):
            for row, value in (([-(p[1] - cy), 1.0, 0.0], e[0]), ([p[0] - cx, 0.0, 1.0], e[1])):
                for i in range(3):
                    b[i] += w * row[i] * value
                    for j in range(3):
                        a[i][j] += w * row[i] * row[j]
        x = solve3(a, b)
        residuals = [math.dist(e, field(x, p)) for p, e in pairs]
        k = 1.5 * max(1.4826 * percentile(residuals, 0.5), 1e-3)
        weights = [1.0 if r <= k else k / r for r in residuals]
    track = list(truth.values())
    rms = math.sqrt(sum(math.hypot(*field(x, p)) ** 2 for p in track) / len(track))
    return rms, x[0]


out, solutions = sys.argv[1], sys.argv[2:]
cells = sorted((d for d in os.listdir(out) if d.startswith("nagoya_")),
               key=lambda d: float(d.split("_t")[1].split("_")[0])) if os.path.isdir(out) else []
print("Fusion on a real receiver's errors (Nagoya): horizontal RMS / median / p95 / vertical RMS (m)")
print()
print("| window | solution | fixes (n) | raw fixes | floor | shape fit (yaw) | graph | graph online | KF (paper) |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
fixed_rows = []
pooled, pooled_n = {}, {}  # estimate -> its errors at every window's fixed epochs
for cell in cells:
    window = cell.removeprefix("nagoya_").replace("_", " ")
    for sol in solutions:
        fixes = read(os.path.join(out, cell, f"{sol}.fixes.errors.csv"))
        if fixes is None:
            continue
        truth = read_tum_en(os.path.join(out, cell, f"{sol}.graph", "groundtruth.tum"))
        fit, yaw = shape_fit(fixes, truth) if truth else (math.nan, math.nan)
        row = [window, sol, str(len(fixes)), fmt(stats(fixes)), f"{floor(fixes):.2f}",
               f"{fit:.2f} ({1e3 * yaw:.1f} mrad)"]
        for run, which in (("graph", "final"), ("graph", "online"), ("kf", "final")):
            rows = read(os.path.join(out, cell, f"{sol}.{run}", f"{which}.errors.csv"))
            row.append(fmt(stats(rows)) if rows is not None else "not run")
            if sol == "rtk" and rows is not None:
                fixed_t = {round(float(r["t_s"]), 1) for r in fixes if r["quality"] == "4"}
                at_fixed = [r for r in rows if round(float(r["t_s"]), 1) in fixed_t]
                fixed_rows.append((window, f"{run} {which}", stats(at_fixed), len(fixed_t)))
                pooled.setdefault(f"{run} {which}", []).extend(at_fixed)
                pooled_n[f"{run} {which}"] = pooled_n.get(f"{run} {which}", 0) + len(fixed_t)
        print("| " + " | ".join(row) + " |")
if fixed_rows:
    print()
    print("RTK, at the epochs the solution called fixed: horizontal RMS / median / p95 / vertical RMS (m)")
    print()
    print("| window | estimate | fixed epochs | fused at them |")
    print("| --- | --- | --- | --- |")
    for window, name, s, n in fixed_rows:
        print(f"| {window} | {name} | {n} | {fmt(s) if s else 'none'} |")
    for name, rows in pooled.items():
        s = stats(rows)
        print(f"| all windows | {name} | {pooled_n[name]} | {fmt(s) if s else 'none'} |")
