#!/usr/bin/env python3
"""Writes the part of KITTI-00's ground truth from START seconds on as a KITTI trajectory of its
own (poses in KITTI-00's world) with its times, for `gvio simulate --trajectory --times`.

    kitti00_window.py KITTI_00_gt.txt KITTI_00_gt_times.txt START OUT_DIR
writes OUT_DIR/kitti00_window.txt and OUT_DIR/kitti00_window_times.txt (the benchmarks' scratch
folders: no copy of the shared data stays in the project)."""
import os
import sys

poses = open(sys.argv[1]).read().splitlines()
times = open(sys.argv[2]).read().splitlines()
start = float(sys.argv[3])
keep = [i for i, t in enumerate(times) if t.strip() and float(t) >= start - 1e-9]
with open(os.path.join(sys.argv[4], "kitti00_window.txt"), "w") as f:
    f.write("".join(poses[i] + "\n" for i in keep))
with open(os.path.join(sys.argv[4], "kitti00_window_times.txt"), "w") as f:
    f.write("".join(times[i] + "\n" for i in keep))
