#!/usr/bin/env bash
# gvio merge's joint alignment (issue 18's target): two simulated drives over the same streets
# (one world: --world-seed, their own noise: --seed 1 and 2, SPP-grade GNSS, graph fusion),
# merged without and with the joint alignment. Prints, for the second drive's dense points, the
# share within 0.2 m of the first drive's (tiles.json "agreement") and the median distance, and
# how far each drive moved (alignment.json). A benchmark, not a test: nothing asserts.
#
# Drives: BENCH_SECONDS (default 60) of KITTI-00 ground truth from BENCH_START s (default 0) when
# ../shared/data has it, else of the embedded assets/demo/drive.tum (35 s); GNSS error model
# BENCH_GNSS (default spp; rtk shows the floor that the dense stereo points' own noise leaves).
# Work folder: BENCH_OUT (default build/bench_merge_align[_GNSS]; simulations are kept and reused).
#
#   tests/bench/merge_align.sh
#   BENCH_START=150 BENCH_SECONDS=60 tests/bench/merge_align.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR="${BUILD_DIR:-build}"
GVIO="$(pwd)/$BUILD_DIR/app/gvio"
DATA="${GVIO_SHARED_DATA:-../shared/data}/kitti00"
DRIVE_S="${BENCH_SECONDS:-60}"
START_S="${BENCH_START:-0}"
GNSS="${BENCH_GNSS:-spp}"
OUT="${BENCH_OUT:-$BUILD_DIR/bench_merge_align$([ "$GNSS" = spp ] || echo "_$GNSS")}"
WORLD_SEED="${BENCH_WORLD_SEED:-7}"
[ -x "$GVIO" ] || { echo "bench: build gvio first ($GVIO)" >&2; exit 2; }
mkdir -p "$OUT"

traj=(--trajectory assets/demo/drive.tum)
route="assets/demo/drive.tum"
if [ -f "$DATA/KITTI_00_gt.txt" ] && [ -f "$DATA/KITTI_00_gt_times.txt" ]; then
  python3 tests/bench/kitti00_window.py "$DATA/KITTI_00_gt.txt" "$DATA/KITTI_00_gt_times.txt" \
    "$START_S" "$OUT"
  traj=(--trajectory "$OUT/kitti00_window.txt" --times "$OUT/kitti00_window_times.txt")
  route="KITTI-00 from ${START_S} s"
else
  echo "bench: no KITTI-00 ground truth in $DATA: the demo route (35 s)" >&2
fi

geo=(--set fusion.origin=48.98253,8.39035,116.4 --set "fusion.lever_arm_b=[0,0,0.8]")
for seed in 1 2; do
  sim="$OUT/sim$seed"
  if [ ! -f "$sim/sim.yaml" ]; then
    "$GVIO" simulate "${traj[@]}" --seconds "$DRIVE_S" --seed "$seed" --world-seed "$WORLD_SEED" \
      --gnss-noise "$GNSS" --out "$sim" --force --no-progress > "$OUT/simulate$seed.log" 2>&1
  fi
  "$GVIO" run --dataset "$sim" --out "$OUT/run$seed" --gnss graph --no-progress "${geo[@]}" \
    > "$OUT/run$seed.log" 2>&1
done
"$GVIO" merge --runs "$OUT/run1" "$OUT/run2" --out "$OUT/apart" --set merge.align=false \
  > "$OUT/merge_apart.log" 2>&1
/usr/bin/time -f "%e %M" -o "$OUT/merge_joint.time" \
  "$GVIO" merge --runs "$OUT/run1" "$OUT/run2" --out "$OUT/joint" > "$OUT/merge_joint.log" 2>&1

python3 - "$OUT" "$route" "$DRIVE_S" "$GNSS" <<'PY'
import json, sys
out, route, seconds, gnss = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4].upper()
def agreement(folder):
    a = json.load(open(f"{out}/{folder}/tiles.json"))["drives"][1].get("agreement", {})
    return a.get("within_percent", float("nan")), a.get("median_m", float("nan")), a.get("overlap_points", 0)
align = json.load(open(f"{out}/joint/alignment.json"))
wall, rss_kb = open(f"{out}/merge_joint.time").read().split()
print(f"two drives, {route}, {seconds} s, seeds 1 and 2, one world, {gnss} GNSS, graph fusion")
print("| merge | within 0.2 m | median | overlap points (sample) |")
print("| --- | --- | --- | --- |")
for name, folder in (("without alignment", "apart"), ("joint alignment", "joint")):
    w, m, n = agreement(folder)
    print(f"| {name} | {w:.1f} % | {m:.3f} m | {n} |")
print(f"loops between the drives: {align['pairs_in_radius']} pairs in reach, {align['verified']} "
      f"verified, {align['accepted']} accepted, {align['active']} kept; detection "
      f"{align['ms_detection']:.0f} ms; graph {align['graph']['ms_solve'] if align['graph'] else 0:.0f} ms; "
      f"merge {float(wall):.1f} s, peak {int(rss_kb) / 1024:.0f} MB")
for d in align["drives"]:
    if d["aligned"]:
        m = d["moved_m"]
        print(f"  {d['name']}: {d['keyframes']} keyframes, {d['loops_active']} loops; moved mean "
              f"{m['mean']:.3f} m, p95 {m['p95']:.3f} m, max {m['max']:.3f} m, turned "
              f"{d['rotated_max_deg']:.3f} deg at most")
    else:
        print(f"  {d['name']}: not moved ({d['note']})")
PY
