#!/usr/bin/env python3
"""A run folder over a simulated dataset with a given trajectory, for `gvio consistency --images`.

  trajectory_run.py RUN DATASET TRAJECTORY.tum [NAME]

A run folder is its report.json's sources and a trajectory: the image check rebuilds the map from
them, so no `gvio run` is needed. RUN is emptied, then holds report.json (mode and sources only:
the map's settings are the defaults) and the trajectory as NAME (default trajectory.tum).
"""
import json
import os
import shutil
import sys


def main():
    if len(sys.argv) not in (4, 5):
        sys.exit(__doc__.strip())
    run, dataset, trajectory = sys.argv[1:4]
    name = sys.argv[4] if len(sys.argv) == 5 else "trajectory.tum"
    shutil.rmtree(run, ignore_errors=True)
    os.makedirs(run)
    sources = {"dataset": os.path.realpath(dataset), "format": "kitti-raw", "calib_files": [],
               "gnss_file": None}
    with open(os.path.join(run, "report.json"), "w") as f:
        json.dump({"mode": "stereo-imu", "sources": sources}, f, indent=2)
    shutil.copyfile(trajectory, os.path.join(run, name))


if __name__ == "__main__":
    main()
