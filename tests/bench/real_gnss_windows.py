#!/usr/bin/env python3
"""The windows of continuous motion of a GNSS/INS reference CSV (the Nagoya drive's
reference.csv), for tests/bench/real_gnss.sh.

    real_gnss_windows.py REFERENCE.csv MIN_S MAX_S          # prints "start_s length_s" per window
    real_gnss_windows.py REFERENCE.csv START_S LENGTH_S OUT  # writes that window's rows to OUT

A window is a stretch where the speed stays above 1 m/s, stops shorter than 3 s included, at least
MIN_S long; longer stretches are cut into pieces of at most MAX_S. Times are seconds since the
reference's first epoch. The window files are the benchmark's scratch: no copy of the shared data
stays in the project."""
import csv
import math
import sys


def rows(path):
    with open(path) as f:
        reader = csv.reader(f)
        header = next(reader)
        return header, [r for r in reader if r]


def column(header, name):
    for i, h in enumerate(header):
        if h.strip().lower().startswith(name):
            return i
    sys.exit(f"bench: {name} column missing")


def windows(path, min_s, max_s):
    header, data = rows(path)
    it, ive, ivn = column(header, "gps tow"), column(header, "east velocity"), column(header, "north velocity")
    t = [float(r[it]) for r in data]
    moving = [math.hypot(float(r[ive]), float(r[ivn])) > 1.0 for r in data]
    out, start, last = [], None, None
    for ti, m in zip(t + [math.inf], moving + [False]):
        if m:
            start = ti if start is None else start
            last = ti
        elif start is not None and (ti - last > 3.0 or ti == math.inf):
            length = last - start
            n = max(1, math.ceil(length / max_s))
            for k in range(n):
                piece = length / n
                if piece >= min_s:
                    out.append((start - t[0] + k * piece, piece))
            start = None
    return out


def write_window(path, start_s, length_s, out):
    with open(path) as f:
        lines = f.read().splitlines()
    it = column(lines[0].split(","), "gps tow")
    t0 = float(lines[1].split(",")[it])
    keep = [l for l in lines[1:] if l.strip() and start_s - 1e-6 <= float(l.split(",")[it]) - t0 <= start_s + length_s + 1e-6]
    with open(out, "w") as f:
        f.write("\n".join([lines[0]] + keep) + "\n")


if len(sys.argv) == 4:
    for s, n in windows(sys.argv[1], float(sys.argv[2]), float(sys.argv[3])):
        print(f"{s:.1f} {n:.1f}")
elif len(sys.argv) == 5:
    write_window(sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4])
else:
    sys.exit(__doc__)
