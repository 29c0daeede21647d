#!/usr/bin/env python3
"""The camera-IMU time offset over the style matrix (issue 58): per vio_matrix.sh cell, the lag the
drive was simulated with (its sim.yaml's camera_time_offset_s), what `gvio run` estimated
(report.json time_offset: t_d +- sigma, or "not observed"), the estimator's last value (t_d_final),
the share of the window's solves that observed it, and, when a synchronised run of the same cells is
given, what it estimated on the synchronised drive and the APE against it.

    BENCH_MODES=stereo-imu BENCH_SEEDS=1 BENCH_SIM_SET="sim.camera_time_offset_s=0.02" \\
      BENCH_OUT=out/bench/vio_lag_0.02 tests/bench/vio_matrix.sh
    tests/bench/time_offset_table.py --sync out/bench/vio_matrix out/bench/vio_lag_0.02 ...

A benchmark's table, not a test: nothing asserts.
"""
import argparse
import json
import os
import re
import sys

from matrix_cells import cells


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def lag_of(cell):
    try:
        drive = open(os.path.join(cell, "drive.txt")).read().strip()
        sim = open(os.path.join(drive, "sim.yaml")).read()
    except OSError:
        return None
    m = re.search(r"^\s*camera_time_offset_s:\s*([0-9.eE+-]+)", sim, re.M)
    return float(m.group(1)) if m else 0.0


def ape(run):
    ev = load(os.path.join(run, "eval.json"))
    return ev["ape"]["rmse"] if ev else None


def estimate(to):
    """The report's estimate as "t_d +- sigma" (ms), or its status when not estimated."""
    if to.get("status") != "estimated":
        return to.get("status", "?")
    return f"{1e3 * to['t_d_s']:.1f} +- {1e3 * to['sigma_s']:.1f}"


def last_value(to):
    return f"{1e3 * to['t_d_final_s']:.1f}" if "t_d_final_s" in to else ""


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("outs", nargs="+", help="vio_matrix.sh BENCH_OUT folders")
    parser.add_argument("--sync", help="the BENCH_OUT of the same cells without a lag")
    parser.add_argument("--mode", default="stereo-imu")
    args = parser.parse_args()
    print(f"Camera-IMU time offset, {args.mode}: the simulated lag, the estimate and the "
          "estimator's last value (report.json), and, on the synchronised drive, its estimate "
          "and the APE against it")
    print()
    print("| style | seed | lag (ms) | estimated (ms) | last value (ms) | status | observed share | "
          "APE (m) | synchronised: estimated (ms) | synchronised APE (m) | APE change |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    within, within_last, within_2sigma, total = 0, 0, 0, 0
    for cell_dir, style, seed, run in cells(args.outs, args.mode):
        lag = lag_of(cell_dir) or 0.0
        to = (load(os.path.join(run, "report.json")) or {}).get("time_offset", {})
        total += 1
        if to.get("status") == "estimated":
            error = abs(to["t_d_s"] - lag)
            within += error <= 0.001
            within_2sigma += error <= 2.0 * to["sigma_s"]
        if "t_d_final_s" in to:
            within_last += abs(to["t_d_final_s"] - lag) <= 0.001
        a = ape(run)
        cell = os.path.basename(cell_dir)
        sync_run = os.path.join(args.sync, cell, args.mode) if args.sync else None
        s = ape(sync_run) if sync_run else None
        sync_to = ((load(os.path.join(sync_run, "report.json")) or {}).get("time_offset", {})
                   if sync_run else None)
        share = to.get("observed_fraction")
        row = [style, seed, f"{1e3 * lag:.0f}", estimate(to), last_value(to),
               to.get("status", "?"), f"{share:.2f}" if share is not None else "",
               f"{a:.3f}" if a is not None else "failed",
               estimate(sync_to) if sync_to is not None else "",
               f"{s:.3f}" if s is not None else "",
               f"{100 * (a / s - 1):+.0f} %" if a and s else ""]
        print("| " + " | ".join(row) + " |")
    print()
    print(f"estimated within 1 ms of the lag: {within} of {total} cells (the last value: "
          f"{within_last} of {total}); within two of its own stated sigmas: {within_2sigma} of "
          f"{total}")


if __name__ == "__main__":
    sys.exit(main())
