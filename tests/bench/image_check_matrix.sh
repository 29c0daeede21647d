#!/usr/bin/env bash
# The image check (`gvio consistency --images`) across worlds (issue 59): per world style x seed,
# its false flags with the true poses and its detection of displaced stretches of poses. Each
# drive of the VIO matrix (tests/bench/matrix_drives.sh: a 60 s window of KITTI-00 per seed when
# ../shared/data has it, simulated once into the cache) is checked along its true poses and along
# the true poses with BENCH_FAULT_S (default 10) s moved from BENCH_FAULT_FROM (default 25) s into
# the drive, by each of BENCH_FAULTS (default "side:0.3 side:0.5 up:0.3 up:0.5": sideways along
# the body's y axis or up, in metres). A run folder is its report.json's sources and a trajectory:
# the check rebuilds the map from the trajectory, so no gvio run is needed.
# Prints one table: keyframes checked, flagged with the true poses (% and the target 1 %), and per
# fault whether a flag lies within 5 s of the stretch, the first such flag's time relative to the
# stretch's start, and the new flags (not flagged with the true poses) farther than 5 s from it.
# A benchmark, not a test: nothing asserts.
#
#   tests/bench/image_check_matrix.sh
#   BENCH_STYLES="street open_road" BENCH_SEEDS="1 2" tests/bench/image_check_matrix.sh
#   BENCH_FAULTS="side:0.5" BENCH_ARGS="--every 2" tests/bench/image_check_matrix.sh
#   BENCH_TABLE_ONLY=1 tests/bench/image_check_matrix.sh   # the table of what BENCH_OUT holds
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR="${BUILD_DIR:-build}"
GVIO="$BUILD_DIR/app/gvio"
SEEDS="${BENCH_SEEDS:-1}"
IMU_MIN=0.5
IMU_MAX=2
FAULTS="${BENCH_FAULTS:-side:0.3 side:0.5 up:0.3 up:0.5}"
FAULT_FROM="${BENCH_FAULT_FROM:-25}"
FAULT_S="${BENCH_FAULT_S:-10}"
OUT="${BENCH_OUT:-out/bench/image_check_matrix}"
source tests/bench/matrix_drives.sh

for f in $FAULTS; do
  [[ "$f" =~ ^(side|up):[0-9]*\.?[0-9]+$ ]] ||
    { echo "bench: BENCH_FAULTS: '$f' is not side:M or up:M" >&2; exit 2; }
done

check() {
  local run=$1
  # shellcheck disable=SC2086
  /usr/bin/time -f "%e %M" -o "$run/time.txt" "$GVIO" --no-progress consistency --run "$run" \
    --images ${BENCH_ARGS:-} > "$run/check.log" 2>&1 || echo "$?" > "$run/failed.txt"
}

# One cell: its drive simulated (once), then checked along the true and the moved poses.
check_cell() {
  local style=$1 seed=$2
  local f dir metres
  simulate_drive "$style" "$seed" "$start" "$cache" || { echo "$?" > "$cell/simulate_rc.txt"; return 0; }
  echo "bench: $style seed $seed: true poses" >&2
  python3 tests/bench/trajectory_run.py "$cell/truth" "$cache" "$cache/groundtruth.tum"
  check "$cell/truth"
  for f in $FAULTS; do
    dir="${f%%:*}" metres="${f#*:}"
    echo "bench: $style seed $seed: $dir $metres m" >&2
    python3 tests/bench/displace_poses.py "$cache/groundtruth.tum" "$cell/moved.tum" \
      "$FAULT_FROM" "$(awk -v a="$FAULT_FROM" -v b="$FAULT_S" 'BEGIN { print a + b }')" \
      "$dir" "$metres"
    python3 tests/bench/trajectory_run.py "$cell/${dir}_${metres}" "$cache" "$cell/moved.tum"
    check "$cell/${dir}_${metres}"
  done
  rm -f "$cell/moved.tum"
}

for_each_cell check_cell

python3 - "$OUT" "$STYLES" "$SEEDS" "$FAULTS" "$FAULT_FROM" "$FAULT_S" <<'PY'
import csv, json, os, sys
out, styles, seeds, faults = sys.argv[1], sys.argv[2].split(), sys.argv[3].split(), sys.argv[4].split()
t0, dur = float(sys.argv[5]), float(sys.argv[6])
t1, NEAR = t0 + dur, 5.0

def rows(run):
    path = os.path.join(run, "consistency_images", "keyframes.csv")
    if os.path.exists(os.path.join(run, "failed.txt")) or not os.path.exists(path):
        return None
    with open(path) as f:
        return [(float(r["t_from_start_s"]), r["flagged"] == "1") for r in csv.DictReader(f)]

def ms(run):
    try:
        return json.load(open(os.path.join(run, "consistency_images", "summary.json")))["ms_per_keyframe"]["mean"]
    except (OSError, ValueError, KeyError):
        return float("nan")

head = ["style", "seed", "keyframes", "true poses: flagged", "ms/kf"]
head += [f"{f.replace(':', ' ')} m: found, first flag (s), new flags > 5 s away" for f in faults]
print(f"The image check across worlds: {t0:g}-{t1:g} s of the true poses moved; a fault is found "
      f"by a flag within {NEAR:g} s of the stretch; targets: <= 1 % flagged with true poses, 0.5 m "
      f"found on every cell, 0.3 m on >= 80 %, no new flag farther than {NEAR:g} s")
print()
print("| " + " | ".join(head) + " |")
print("|" + " --- |" * len(head))
tally = {"cells": 0, "truth_ok": 0, "worst_rate": 0.0}
found = {f: [0, 0] for f in faults}
far_new = {f: 0 for f in faults}
for style in styles:
    for seed in seeds:
        cell = os.path.join(out, f"{style}_seed{seed}")
        truth = rows(os.path.join(cell, "truth"))
        if truth is None:
            print(f"| {style} | {seed} | check failed or not run | | |" + " |" * len(faults))
            continue
        flagged = sum(1 for _, fl in truth if fl)
        rate = 100.0 * flagged / max(len(truth), 1)
        tally["cells"] += 1
        tally["truth_ok"] += rate <= 1.0
        tally["worst_rate"] = max(tally["worst_rate"], rate)
        truth_flags = {round(t, 3) for t, fl in truth if fl}
        row = [style, seed, str(len(truth)), f"{flagged} ({rate:.1f} %)",
               f"{ms(os.path.join(cell, 'truth')):.0f}"]
        for f in faults:
            moved = rows(os.path.join(cell, f.replace(":", "_")))
            if moved is None:
                row.append("check failed")
                continue
            near = [t for t, fl in moved if fl and t0 - NEAR <= t <= t1 + NEAR]
            far = [t for t, fl in moved if fl and not (t0 - NEAR <= t <= t1 + NEAR)
                   and round(t, 3) not in truth_flags]
            found[f][0] += bool(near)
            found[f][1] += 1
            far_new[f] += len(far)
            first = f"{min(near) - t0:+.1f}" if near else "-"
            row.append(f"{'yes' if near else '**no**'}, {first}, {len(far)}")
        print("| " + " | ".join(row) + " |")
print()
print(f"true poses: {tally['truth_ok']} of {tally['cells']} cells flag <= 1 % "
      f"(worst {tally['worst_rate']:.1f} %)")
for f in faults:
    n, total = found[f]
    print(f"{f.replace(':', ' ')} m: found on {n} of {total} cells; {far_new[f]} new flags farther "
          f"than {NEAR:g} s")
PY
