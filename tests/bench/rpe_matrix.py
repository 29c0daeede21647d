#!/usr/bin/env python3
"""The VIO's relative error over the style matrix, the measure behind the global graph's
stereo+IMU odometry noise model (docs/how-it-works/loops.md): for every cell of the given
tests/bench/vio_matrix.sh output folders, `gvio eval --align se3 --rpe-delta D --rpe-unit m` of the
run's trajectory_vio.tum against its groundtruth.tum, translation (m) and rotation (deg, `--relation
angle_deg`), RMSE over the pairs D metres apart; then the median and range over the cells, and per
step the fraction of D (translation) and radians per metre (rotation).

    BENCH_MODES=stereo-imu tests/bench/vio_matrix.sh
    tests/bench/rpe_matrix.py out/bench/vio_matrix

BUILD_DIR (default build) gives the gvio binary; --mode picks the runs (default stereo-imu);
--deltas the distances (default 10 100). A benchmark's table, not a test: nothing asserts."""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile

from matrix_cells import cells

GVIO = os.path.join(os.environ.get("BUILD_DIR", "build"), "app", "gvio")


def rpe(run, delta, relation):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "eval.json")
        subprocess.run([GVIO, "eval", "--ref", os.path.join(run, "groundtruth.tum"), "--est",
                        os.path.join(run, "trajectory_vio.tum"), "--align", "se3", "--relation",
                        relation, "--rpe-delta", str(delta), "--rpe-unit", "m", "--json", out],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        with open(out) as f:
            return json.load(f)["rpe"]["rmse"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("outs", nargs="+", help="vio_matrix.sh BENCH_OUT folders")
    parser.add_argument("--mode", default="stereo-imu")
    parser.add_argument("--deltas", type=float, nargs="+", default=[10.0, 100.0])
    args = parser.parse_args()
    runs = [(os.path.basename(c), run)
            for c, _, _, run in cells(args.outs, args.mode, needs="trajectory_vio.tum")]
    if not runs:
        sys.exit("bench: no run folders with a trajectory_vio.tum in " + " ".join(args.outs))
    head = " | ".join(f"{d:g} m: trans (m), rot (deg)" for d in args.deltas)
    print(f"Relative error of the VIO alone ({args.mode}), RMSE over pose pairs D metres apart "
          "(gvio eval --align se3 --rpe-unit m)")
    print()
    print(f"| cell | {head} |")
    print("| --- |" + " --- |" * len(args.deltas))
    table = {d: ([], []) for d in args.deltas}
    for cell, run in runs:
        row = []
        for d in args.deltas:
            t, r = rpe(run, d, "trans"), rpe(run, d, "angle_deg")
            table[d][0].append(t)
            table[d][1].append(r)
            row.append(f"{t:.3f}, {r:.3f}")
        print(f"| {cell} | " + " | ".join(row) + " |")
    print()
    for d, (t, r) in table.items():
        mt, mr = statistics.median(t), statistics.median(r)
        print(f"{d:g} m over {len(t)} cells: median {mt:.3f} m ({min(t):.3f}-{max(t):.3f}) = "
              f"{100 * mt / d:.2f} % of the step, {mr:.3f} deg ({min(r):.3f}-{max(r):.3f}) = "
              f"{math.radians(mr) / d:.2e} rad per metre")


if __name__ == "__main__":
    sys.exit(main())
