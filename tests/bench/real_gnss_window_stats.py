#!/usr/bin/env python3
"""How one window of tests/bench/real_gnss.sh goes wrong along the track: from the per-epoch errors
`gvio eval --errors-csv` wrote in its folder (columns t_s, ape, dx_m, dy_m, dz_m, quality; dx east
and dy north in the reference's ENU frame, metres).

    real_gnss_window_stats.py out/bench/real_gnss/nagoya_t718.0_91.6s

Prints, per quarter of the window: the SPP fixes' median east and north errors and the graph's
median horizontal error (spp.graph/final.errors.csv); then the RTK solution's horizontal error
median per quality (NMEA GGA codes: 4 RTK fixed, 5 RTK float, 1 single). A benchmark's table, not a test."""
import csv
import math
import os
import statistics
import sys

# The quality column holds NMEA GGA's codes, as gvio reads every GNSS file (RTKLIB's Q 1 fixed is 4,
# Q 2 float is 5, Q 5 single is 1): app/io/geo_track.cpp qualityName.
QUALITY = {"1": "single", "2": "DGPS", "4": "RTK fixed", "5": "RTK float", "9": "SBAS"}


def rows(path):
    with open(path) as f:
        return [r for r in csv.DictReader(f) if r.get("t_s")]


def horizontal(r):
    return math.hypot(float(r["dx_m"]), float(r["dy_m"]))


def quarters(data, t0, t1):
    out = [[] for _ in range(4)]
    for r in data:
        k = min(3, max(0, int(4 * (float(r["t_s"]) - t0) / (t1 - t0))))
        out[k].append(r)
    return out


def median(values):
    return f"{statistics.median(values):.2f}" if values else "-"


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    folder = sys.argv[1]
    spp = rows(os.path.join(folder, "spp.fixes.errors.csv"))
    graph = rows(os.path.join(folder, "spp.graph", "final.errors.csv"))
    if not spp or not graph:
        sys.exit(f"bench: {folder}: no SPP fix or graph errors")
    t0 = min(float(r["t_s"]) for r in graph)
    t1 = max(float(r["t_s"]) for r in graph)
    print(f"{os.path.basename(folder.rstrip('/'))}: medians per quarter of the window (m)")
    print()
    print("| quarter | SPP fixes | fix east error | fix north error | graph horizontal error |")
    print("| --- | --- | --- | --- | --- |")
    for k, (fq, gq) in enumerate(zip(quarters(spp, t0, t1), quarters(graph, t0, t1))):
        print(f"| {k + 1} | {len(fq)} | {median([float(r['dx_m']) for r in fq])} | "
              f"{median([float(r['dy_m']) for r in fq])} | {median([horizontal(r) for r in gq])} |")
    rtk_path = os.path.join(folder, "rtk.fixes.errors.csv")
    if os.path.exists(rtk_path):
        by_quality = {}
        for r in rows(rtk_path):
            by_quality.setdefault(r["quality"], []).append(horizontal(r))
        print()
        print("| RTK quality | epochs | median horizontal error (m) |")
        print("| --- | --- | --- |")
        for q in sorted(by_quality):
            print(f"| {q} ({QUALITY.get(q, '?')}) | {len(by_quality[q])} | {median(by_quality[q])} |")


if __name__ == "__main__":
    sys.exit(main())
