#!/usr/bin/env python3
"""Where do a drive's raw fixes lie against its truth? From a run folder with a truth
(groundtruth.tum: body poses in local ENU) and its screened fixes (gnss_fixes.csv, same frame),
each fix's error against the truth interpolated at its stamp, split along and across the track
(horizontal; across = to the left of travel) and vertically, the steps between the fixes' stamps,
and two least-squares fits of the error:

- a latency alone:                  fix - truth = v tau
- a latency and a lever arm:        fix - truth = R_enu_b l + v tau   (l in the body: x forward,
                                                                       y left, z up)

v is the truth's velocity (central differences), R_enu_b its orientation. Fitted on the truth the
figures say what a calibration would buy; they are not an estimator's result.

    gvio run --dataset ../shared/data/comma2k19 --out out/comma2k19
    tests/bench/gnss_lag_fit.py out/comma2k19
"""
import bisect
import math
import statistics
import sys


def read_tum(path):
    rows = []
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                rows.append([float(x) for x in line.split()])
    return rows


def read_fixes(path):
    out = []
    with open(path) as f:
        header = f.readline().strip().split(",")
        for line in f:
            row = dict(zip(header, line.strip().split(",")))
            out.append([float(row[k]) for k in ("t_s", "e_m", "n_m", "u_m")])
    return out


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def rotation(q):  # TUM order qx qy qz qw; rows of R_enu_b
    n = math.sqrt(dot(q, q))
    x, y, z, w = (c / n for c in q)
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]


def solve(M, b):
    """Gaussian elimination with partial pivoting (a small dense system)."""
    n = len(b)
    A = [row[:] + [b[i]] for i, row in enumerate(M)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(A[r][c]))
        A[c], A[p] = A[p], A[c]
        for r in range(c + 1, n):
            f = A[r][c] / A[c][c]
            A[r] = [a - f * b_ for a, b_ in zip(A[r], A[c])]
    x = [0.0] * n
    for r in reversed(range(n)):
        x[r] = (A[r][n] - sum(A[r][k] * x[k] for k in range(r + 1, n))) / A[r][r]
    return x


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    run = sys.argv[1]
    truth = read_tum(f"{run}/groundtruth.tum")
    fixes = read_fixes(f"{run}/gnss_fixes.csv")
    t = [r[0] for r in truth]
    rows = []  # (error, velocity, R_enu_b) for each fix inside the truth
    for tf, e, n, u in fixes:
        i = bisect.bisect_right(t, tf) - 1
        if i < 1 or i + 2 >= len(t):
            continue
        a = (tf - t[i]) / (t[i + 1] - t[i])
        p = [(1 - a) * truth[i][k] + a * truth[i + 1][k] for k in (1, 2, 3)]
        v = [(truth[i + 2][k] - truth[i - 1][k]) / (t[i + 2] - t[i - 1]) for k in (1, 2, 3)]
        q = truth[i][4:8] if a < 0.5 else truth[i + 1][4:8]
        rows.append(([e - p[0], n - p[1], u - p[2]], v, rotation(q)))
    if len(rows) < 10:
        sys.exit(f"{run}: {len(rows)} fixes inside the truth; at least 10 are needed")

    along, across = [], []
    for err, v, _ in rows:
        speed = math.hypot(v[0], v[1])
        if speed < 1.0:
            continue  # no direction of travel
        fwd = [v[0] / speed, v[1] / speed, 0.0]
        left = [-fwd[1], fwd[0], 0.0]
        along.append(dot(err, fwd))
        across.append(dot(err, left))
    print(f"{len(rows)} fixes; {len(along)} moving faster than 1 m/s")
    steps = [1e3 * (b[0] - a[0]) for a, b in zip(fixes, fixes[1:])]
    print(f"stamp steps: median {statistics.median(steps):.0f} ms, from {min(steps):.0f} to"
          f" {max(steps):.0f} ms")
    print(f"vertical: mean {statistics.mean(err[2] for err, _, _ in rows):+.2f} m (+ = fix above)")
    print(f"along the track:  mean {statistics.mean(along):+.2f} m, std {statistics.stdev(along):.2f} m")
    print(f"across the track: mean {statistics.mean(across):+.2f} m, std {statistics.stdev(across):.2f} m"
          " (+ = left)")

    # Latency alone: minimise sum |e - v tau|^2.
    tau = sum(dot(err, v) for err, v, _ in rows) / sum(dot(v, v) for _, v, _ in rows)
    print(f"latency alone: tau {tau:+.3f} s")

    # Latency and lever arm: [R_enu_b | v] [l; tau] = e for every fix, by the normal equations.
    N = [[0.0] * 4 for _ in range(4)]
    g = [0.0] * 4
    design = []
    for err, v, R in rows:
        for k in range(3):
            a = R[k] + [v[k]]
            design.append((a, err[k]))
            for i in range(4):
                g[i] += a[i] * err[k]
                for j in range(4):
                    N[i][j] += a[i] * a[j]
    x = solve(N, g)
    res = [e - dot(a, x) for a, e in design]
    h = math.sqrt(sum(res[i] ** 2 + res[i + 1] ** 2 for i in range(0, len(res), 3)) / len(rows))
    d3 = math.sqrt(sum(r * r for r in res) / len(rows))
    print(f"lever arm and latency: l = [{x[0]:+.2f}, {x[1]:+.2f}, {x[2]:+.2f}] m (forward, left, up),"
          f" tau {x[3]:+.3f} s; residual RMS {h:.2f} m horizontal, {d3:.2f} m 3-D")


if __name__ == "__main__":
    main()
