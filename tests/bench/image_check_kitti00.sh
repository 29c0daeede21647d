#!/usr/bin/env bash
# gvio consistency --images on the simulated KITTI-00 run (issue 19: <= 150 ms per keyframe at
# 1241x376 for the 14 M-point map; the map of true poses scoring above the SPP-fused one's, above
# the VIO's). The run folder's map is checked along three trajectories: `truth` (the simulator's
# groundtruth.tum), `fused` (the run's trajectory.tum: graph fusion of SPP fixes + loops) and `vio`
# (trajectory_vio.tum: the VIO alone, no loops, no GNSS). Each is a folder holding only the run's
# report.json and config.yaml (the dataset and the map settings) and that trajectory, so the check
# rebuilds the map from it. Prints one table (with the keyframes of not enough evidence, the
# depth self-check and the revisits of summary.json). A benchmark, not a test: nothing asserts.
#
# BENCH_RUN: the run folder (default: the KITTI-00 graph+loops run of tests/bench/vio_kitti00.sh).
# BENCH_SIM: instead of a run, a simulated dataset folder (e.g. vio_kitti00.sh's cache
# build/bench_cache/kitti00_full_seed1): its groundtruth.tum is checked (truth only, no VIO run).
# BENCH_TRAJ: which of truth fused vio (default all three). BENCH_ARGS: more consistency options
# (e.g. "--from 30 --to 60"). Work folder: BENCH_OUT (default build/bench_image_check).
#
#   tests/bench/image_check_kitti00.sh
#   BENCH_TRAJ=fused BENCH_ARGS="--every 5" tests/bench/image_check_kitti00.sh
#   BENCH_SIM=build/bench_cache/kitti00_full_seed1 tests/bench/image_check_kitti00.sh
#   BENCH_TABLE_ONLY=1 tests/bench/image_check_kitti00.sh   # the table of what BENCH_OUT holds
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR="${BUILD_DIR:-build}"
GVIO="$(pwd)/$BUILD_DIR/app/gvio"
RUN="${BENCH_RUN:-out/bench/vio_kitti00_full/stereo-imu_graph}"
OUT="${BENCH_OUT:-$BUILD_DIR/bench_image_check}"
TRAJ="${BENCH_TRAJ:-truth fused vio}"
[ -x "$GVIO" ] || { echo "bench: build gvio first ($GVIO)" >&2; exit 2; }
if [ -n "${BENCH_SIM:-}" ]; then
  # A run folder of the simulation's sources alone (the map's settings are the defaults).
  [ -f "$BENCH_SIM/sim.yaml" ] || { echo "bench: $BENCH_SIM is no simulated dataset" >&2; exit 2; }
  RUN="$BUILD_DIR/bench_image_check_sim_run"
  TRAJ=truth
  python3 tests/bench/trajectory_run.py "$RUN" "$BENCH_SIM" "$BENCH_SIM/groundtruth.tum" \
    groundtruth.tum
fi
need=(report.json)
for t in $TRAJ; do
  case "$t" in
    truth) need+=(groundtruth.tum) ;;
    fused) need+=(trajectory.tum) ;;
    vio) need+=(trajectory_vio.tum) ;;
  esac
done
for f in "${need[@]}"; do
  [ -f "$RUN/$f" ] || { echo "bench: $RUN has no $f (set BENCH_RUN or BENCH_SIM)" >&2; exit 2; }
done
if [ -z "${BENCH_TABLE_ONLY:-}" ]; then  # BENCH_TABLE_ONLY=1: the table of what BENCH_OUT holds
rm -rf "$OUT"
mkdir -p "$OUT"
for t in $TRAJ; do
  mkdir -p "$OUT/$t"
  cp "$RUN/report.json" "$OUT/$t/"
  [ -f "$RUN/config.yaml" ] && cp "$RUN/config.yaml" "$OUT/$t/"
  case "$t" in
    truth) cp "$RUN/groundtruth.tum" "$OUT/$t/trajectory.tum" ;;
    fused) cp "$RUN/trajectory.tum" "$OUT/$t/trajectory.tum" ;;
    vio) cp "$RUN/trajectory_vio.tum" "$OUT/$t/trajectory_vio.tum" ;;
    *) echo "bench: unknown trajectory $t (truth, fused or vio)" >&2; exit 2 ;;
  esac
  # shellcheck disable=SC2086
  /usr/bin/time -f "%e %M" -o "$OUT/$t.time" "$GVIO" --no-progress consistency --run "$OUT/$t" \
    --images ${BENCH_ARGS:-} > "$OUT/$t.log" 2>&1
done
fi
python3 - "$OUT" $TRAJ <<'PY'
import json, sys
out, names = sys.argv[1], sys.argv[2:]
print("| trajectory | keyframes | ZNCC mean | depth agreement mean | flagged (stretches) | not enough evidence | self-check depth agreement | at revisits: keyframes, flagged, ZNCC of the other passes minus every source's (median) | ms per keyframe mean / median / p90 | wall s | peak RSS MiB |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
def num(v, fmt):
    return "-" if v is None else format(v, fmt)
summaries = {n: json.load(open(f"{out}/{n}/consistency_images/summary.json")) for n in names}
for n, j in summaries.items():
    wall, rss_kb = open(f"{out}/{n}.time").read().split()
    ms, r = j["ms_per_keyframe"], j["revisits"]
    print(f"| {n} | {j['keyframes']['checked']} | {j['ncc']['mean']:.3f} | "
          f"{j['depth_agreement']['mean']:.3f} | {j['keyframes']['flagged']} "
          f"({len(j['flagged_stretches'])}) | {j['keyframes']['not_enough_evidence']} | "
          f"{num(j['self_check']['depth_agreement_median'], '.3f')} | {r['keyframes']}, "
          f"{r['flagged']}, {num(r['ncc']['median_minus_all_sources'], '+.3f')} | "
          f"{ms['mean']:.0f} / {ms['median']:.0f} / {ms['p90']:.0f} | {float(wall):.0f} | "
          f"{int(rss_kb) / 1024:.0f} |")
for n, j in summaries.items():
    spans = ", ".join(f"{s['from_s']:.1f}" + (f"-{s['to_s']:.1f}" if s["to_s"] > s["from_s"] else "")
                      for s in j["flagged_stretches"])
    scores = {}
    for f in j["flags"]:
        key = f["reason"].split()[0]
        scores[key] = scores.get(key, 0) + 1
    print(f"\n{n}: flagged stretches (s from the start) {spans or 'none'}; flags by score: "
          + (", ".join(f"{k} {v}" for k, v in sorted(scores.items())) or "none"))
PY
