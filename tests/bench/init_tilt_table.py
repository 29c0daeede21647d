#!/usr/bin/env python3
"""How well the visual-inertial initialisation knows gravity on each cell of the style matrix, from
the run logs tests/bench/vio_matrix.sh leaves (run.log of each cell's mode folder): the tilt sigma
of the first alignment over the 1 s window (the line `initialized: ...` or `waiting: ... (+- X
deg)`), and, when the window waited for a better one, how much later it started and the tilt sigma
it started with.

    BENCH_MODES=stereo-imu tests/bench/vio_matrix.sh
    tests/bench/init_tilt_table.py out/bench/vio_matrix

--mode picks the runs (default stereo-imu). A benchmark's table, not a test: nothing asserts."""
import argparse
import os
import re
import sys

from matrix_cells import cells

EVENT = re.compile(r"vio ([0-9.]+) s: (initialized|waiting): visual-inertial alignment.*?"
                   r"(?:tilt|uncertain) \(?\+- ([0-9.]+) deg")


def alignment_events(log):
    """(t_s, kind, tilt_sigma_deg) of the alignment lines, in order."""
    with open(log) as f:
        return [(float(m.group(1)), m.group(2), float(m.group(3)))
                for m in map(EVENT.search, f) if m]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("outs", nargs="+", help="vio_matrix.sh BENCH_OUT folders")
    parser.add_argument("--mode", default="stereo-imu")
    args = parser.parse_args()
    print(f"The initialisation's gravity ({args.mode}): the first alignment's tilt sigma and, when "
          "it waited, the start")
    print()
    print("| cell | first alignment: tilt sigma (deg) | waited (s) | started with (deg) |")
    print("| --- | --- | --- | --- |")
    rows = 0
    for cell_dir, _, _, run in cells(args.outs, args.mode, needs="run.log"):
        cell = os.path.basename(cell_dir)
        events = alignment_events(os.path.join(run, "run.log"))
        if not events:
            print(f"| {cell} | no alignment | | |")
            continue
        t0, _, sigma0 = events[0]
        start = next((e for e in events if e[1] == "initialized"), None)
        waited = f"{start[0] - t0:.1f}" if start and start[0] > t0 else "0"
        started = f"{start[2]:.2f}" if start else "never"
        print(f"| {cell} | {sigma0:.2f} | {waited} | {started} |")
        rows += 1
    if not rows:
        sys.exit("bench: no run.log in " + " ".join(args.outs))


if __name__ == "__main__":
    sys.exit(main())
