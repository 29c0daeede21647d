#!/usr/bin/env python3
"""Does a receiver's stated error ellipse describe its errors? For each epoch of an RTKLIB
solution (lat/lon/height, sdn sde sdu sdne ...) whose error against a reference `gvio eval`
wrote (--errors-csv: t_s, ape, dx_m = east, dy_m = north, ...), per RTKLIB quality Q:

- the median, over the epochs, of the negative log-likelihood of the horizontal error under the
  stated covariance minus that under a circle of the same size (variance (sdn^2 + sde^2) / 2):
  below 0 the ellipse describes the error better (a median: formal sigmas far too small make
  the means a few epochs' matter);
- the fraction of the squared error that lies along the stated major axis, beside what the
  ellipses themselves predict for it: for a Gaussian error of axis sigmas s1 >= s2,
  E[e1^2 / (e1^2 + e2^2)] = s1 / (s1 + s2); 0.5 = no relation;
- the median |rho_ne| the solution states.

    gvio eval --ref reference.csv --est rover_1Hz_spp.pos --errors-csv spp_errors.csv
    tests/bench/gnss_ellipse_fit.py rover_1Hz_spp.pos spp_errors.csv

The errors CSV is in UTC, the .pos in GPST (or UTC, as its header says): epochs are matched after
the leap seconds of their date."""
import calendar
import math
import statistics
import sys

# GPS - UTC leap seconds from each date on (the table of io/gps_time.hpp from 2006).
LEAPS = [((2006, 1, 1), 14), ((2009, 1, 1), 15), ((2012, 7, 1), 16), ((2015, 7, 1), 17),
         ((2017, 1, 1), 18)]
GPS_EPOCH = calendar.timegm((1980, 1, 6, 0, 0, 0))


def leap_at(t_gpst):
    leap = 13
    for (y, m, d), s in LEAPS:
        if t_gpst >= calendar.timegm((y, m, d, 0, 0, 0)):
            leap = s
    return leap


def read_pos(path):
    """{utc seconds (0.1 s): (var_e, var_n, cov_en, Q)}."""
    out, utc = {}, False
    for line in open(path):
        if line.startswith("%"):
            utc = utc or ("UTC" in line and "GPST" not in line)
            continue
        f = line.split()
        if len(f) < 11:
            continue
        if "/" in f[0]:
            y, mo, d = map(int, f[0].split("/"))
            h, mi, s = f[1].split(":")
            t = calendar.timegm((y, mo, d, int(h), int(mi), 0)) + float(s)
        else:  # GPS week, seconds of week
            t = GPS_EPOCH + int(f[0]) * 604800 + float(f[1])
        if not utc:
            t -= leap_at(t)
        sdn, sde, sdne = float(f[7]), float(f[8]), float(f[10])
        out[round(t, 1)] = (sde * sde, sdn * sdn, math.copysign(sdne * sdne, sdne), int(f[5]))
    return out


def mahalanobis(e, a, b, c):  # e^T [[a, c], [c, b]]^-1 e and the determinant
    det = a * b - c * c
    return (b * e[0] * e[0] - 2 * c * e[0] * e[1] + a * e[1] * e[1]) / det, det


def main(pos_path, errors_path):
    stated = read_pos(pos_path)
    per_q = {}
    with open(errors_path) as f:
        header = f.readline().strip().split(",")
        ix, iy = header.index("dx_m"), header.index("dy_m")
        for line in f:
            r = line.strip().split(",")
            key = round(float(r[0]), 1)
            if key not in stated:
                continue
            a, b, c, q = stated[key]
            if a * b - c * c <= 0.0:
                continue
            e = (float(r[ix]), float(r[iy]))
            d_ell, det_ell = mahalanobis(e, a, b, c)
            s = 0.5 * (a + b)
            d_circ, det_circ = mahalanobis(e, s, s, 0.0)
            half, disc = 0.5 * (a + b), math.sqrt((0.5 * (a - b)) ** 2 + c * c)
            major = half + disc
            v = (c, major - a) if abs(c) > 1e-15 else ((1.0, 0.0) if a >= b else (0.0, 1.0))
            n = math.hypot(*v)
            along = ((e[0] * v[0] + e[1] * v[1]) / n) ** 2
            norm2 = e[0] ** 2 + e[1] ** 2
            per_q.setdefault(q, []).append(
                (0.5 * (d_ell + math.log(det_ell)), 0.5 * (d_circ + math.log(det_circ)),
                 along / norm2 if norm2 > 0 else 0.5,
                 math.sqrt(major) / (math.sqrt(major) + math.sqrt(max(a + b - major, 0.0))),
                 abs(c) / math.sqrt(a * b)))
    if not per_q:
        sys.exit(f"{errors_path}: no epoch matches {pos_path}")
    print("| Q | epochs | median NLL, ellipse - circle | error share on the major axis | "
          "stated share | median abs(rho_ne) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for q, rows in sorted(per_q.items()):
        mean = lambda i: statistics.fmean(r[i] for r in rows)
        nll = statistics.median(r[0] - r[1] for r in rows)
        print(f"| {q} | {len(rows)} | {nll:.3f} | {mean(2):.3f} | {mean(3):.3f} | "
              f"{statistics.median(r[4] for r in rows):.2f} |")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
