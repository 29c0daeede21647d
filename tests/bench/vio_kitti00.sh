#!/usr/bin/env bash
# End-to-end benchmark (issues 6, 7, 8, 15): simulates the full KITTI-00 drive once (cached,
# SPP-grade GNSS), runs `gvio run` per mode, evaluates the VIO with `gvio eval` (SE(3) alignment:
# APE RMSE, RPE per 100 m), the final trajectory (trajectory.tum: loop-closed, fused) with no
# alignment against the ENU truth (SE(3) without GNSS) and its revisit consistency
# (`gvio eval --revisits 5`), and prints tables with ms/frame per stage (mean, p95), GNSS cost per
# fix, the map stage, loop closure, the whole run's and each stage's wall time and peak RSS from
# report.json.
# A mode is VIO_MODE:GNSS[:noloops] (GNSS off|kf|graph; noloops: loops.enabled=false, today's
# behaviour before loop closure). BENCH_SET adds --set options to every run. A benchmark, not a
# test: nothing asserts a timing.
#
#   tests/bench/vio_kitti00.sh                         # all modes, full drive
#   BENCH_MODES="stereo-imu:graph stereo-imu:graph:noloops" BENCH_SECONDS=60 tests/bench/vio_kitti00.sh
#   BENCH_SEED=3 BENCH_MODES=stereo-imu:graph tests/bench/vio_kitti00.sh   # another draw
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR="${BUILD_DIR:-build}"
GVIO="$BUILD_DIR/app/gvio"
DATA="${GVIO_SHARED_DATA:-../shared/data}/kitti00"
MODES="${BENCH_MODES:-stereo-imu:graph stereo-imu:graph:noloops stereo-imu:off stereo-imu:off:noloops stereo-imu:kf stereo:off mono-imu:off}"
SECONDS_ARG=()
TAG="full"
if [ -n "${BENCH_SECONDS:-}" ]; then
  SECONDS_ARG=(--seconds "$BENCH_SECONDS")
  TAG="${BENCH_SECONDS}s"
fi
if [ ! -f "$DATA/KITTI_00_gt.txt" ]; then
  echo "bench: $DATA/KITTI_00_gt.txt absent: nothing to benchmark" >&2
  exit 0
fi
[ -x "$GVIO" ] || { echo "bench: $GVIO not built (./setup.sh build)" >&2; exit 2; }

# BENCH_SEED (default 1) draws another simulation of the same drive: its own sensor noise, GNSS
# errors and world, to tell a setting's effect from one draw's luck.
SEED="${BENCH_SEED:-1}"
case "$SEED" in '' | *[!0-9]*) echo "bench: BENCH_SEED must be a whole number, not '$SEED'" >&2; exit 2 ;; esac
CACHE="${GVIO_BENCH_CACHE:-$BUILD_DIR/bench_cache}/kitti00_${TAG}_seed${SEED}"
if [ ! -f "$CACHE/sim.yaml" ]; then
  echo "bench: simulating KITTI-00 ($TAG) into $CACHE (once; about 12 min for the full drive)" >&2
  rm -rf "$CACHE.partial"
  "$GVIO" simulate --trajectory "$DATA/KITTI_00_gt.txt" --times "$DATA/KITTI_00_gt_times.txt" \
    --gnss-noise spp --seed "$SEED" "${SECONDS_ARG[@]}" --out "$CACHE.partial" --force --no-progress
  rm -rf "$CACHE"
  mv "$CACHE.partial" "$CACHE"
fi

OUT="${BENCH_OUT:-out/bench/vio_kitti00_$TAG}"
mkdir -p "$OUT"
# The simulator's ENU origin and antenna lever arm (its defaults), so that the fused trajectory can
# be compared with groundtruth.tum without any alignment.
GEO=(--set "fusion.origin=48.98253,8.39035,116.4" --set "fusion.lever_arm_b=[0,0,0.8]")
EXTRA=()
for kv in ${BENCH_SET:-}; do EXTRA+=(--set "$kv"); done
for mode in $MODES; do
  run="$OUT/${mode//:/_}"
  IFS=: read -r vio gnss loops <<< "$mode"
  LOOPS=()
  [ "${loops:-}" = "noloops" ] && LOOPS=(--set loops.enabled=false)
  "$GVIO" run --dataset "$CACHE" --gnss "$gnss" --set "vio.mode=$vio" "${GEO[@]}" "${LOOPS[@]}" \
    "${EXTRA[@]}" --out "$run" --no-progress
  if [ -s "$run/trajectory_vio.tum" ]; then
    "$GVIO" eval --ref "$CACHE/groundtruth.tum" --est "$run/trajectory_vio.tum" --align se3 \
      --rpe-delta 100 --rpe-unit m --json "$run/eval.json" > /dev/null
  fi
  # The run's final trajectory: in ENU (no alignment) when fused, else the VIO world (SE(3)).
  final="$run/trajectory.tum"
  [ -s "$final" ] || final="$run/trajectory_vio.tum"
  align=se3
  [ -f "$run/georef.json" ] && align=none
  if [ -s "$final" ]; then
    "$GVIO" eval --ref "$CACHE/groundtruth.tum" --est "$final" --align "$align" --revisits 5 \
      --json "$run/eval_final.json" > /dev/null
  fi
done

python3 - "$OUT" $MODES <<'PY'
import json, os, sys
out, modes = sys.argv[1], sys.argv[2:]
print("| mode | poses | VIO APE RMSE (m) | VIO RPE per 100 m (mean %, rmse %) | tracking ms mean / p95 "
      "| estimator ms mean / p95 | tracking + estimator mean (ms) | peak RSS (MiB) "
      "| fused APE RMSE, no alignment (m) | GNSS used / rejected | ms per fix mean / p95 |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for mode in modes:
    run = os.path.join(out, mode.replace(":", "_"))
    rep = json.load(open(os.path.join(run, "report.json")))
    t = rep["timing_ms"]
    ev_path = os.path.join(run, "eval.json")
    if os.path.exists(ev_path):
        ev = json.load(open(ev_path))
        ape = f'{ev["ape"]["rmse"]:.3f}'
        rpe = f'{ev["rpe"]["mean"]:.3f}, {ev["rpe"]["rmse"]:.3f}' if "rpe" in ev else "n/a"
    else:
        ape = rpe = "no poses"
    front_back = t["tracking"]["mean"] + t["estimator"]["mean"]
    print(f'| {mode} | {rep["counts"]["poses_written"]}/{rep["counts"]["frames"]} | {ape} | {rpe} '
          f'| {t["tracking"]["mean"]:.1f} / {t["tracking"]["p95"]:.1f} '
          f'| {t["estimator"]["mean"]:.1f} / {t["estimator"]["p95"]:.1f} | {front_back:.1f} '
          f'| {rep["peak_rss_mb"]:.0f} ', end="")
    fused = rep.get("evaluation_fused", {}).get("ape_none")
    g = rep.get("gnss", {})
    if fused:
        online = rep["evaluation_fused"].get("ape_none_online")
        causal = f' ({online["rmse"]:.3f} causal)' if online else ""
        print(f'| {fused["rmse"]:.3f}{causal} | {g["used"]} / {g["rejected"]} '
              f'| {g["ms_per_fix"]["mean"]:.3f} / {g["ms_per_fix"]["p95"]:.3f} |')
    else:
        print("| - | - | - |")

# The map stage (issue 8): per-keyframe cost of each stage, the build after the drive, memory.
print()
print("| mode | keyframes | sparse ms mean / p95 | dense depth ms mean / p95 | OctoMap ms mean / p95 "
      "| dense + OctoMap mean (ms) | build after the drive (s) | dense points | occupied voxels "
      "| store / OcTree (MB) | peak RSS (MiB) |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for mode in modes:
    rep = json.load(open(os.path.join(out, mode.replace(":", "_"), "report.json")))
    m = rep.get("map")
    if not m:
        print(f"| {mode} | no map | | | | | | | | | |")
        continue
    k = m["ms_per_keyframe"]
    print(f'| {mode} | {m["keyframes"]} | {k["sparse"]["mean"]:.2f} / {k["sparse"]["p95"]:.2f} '
          f'| {k["dense_depth"]["mean"]:.1f} / {k["dense_depth"]["p95"]:.1f} '
          f'| {k["octomap"]["mean"]:.1f} / {k["octomap"]["p95"]:.1f} '
          f'| {k["dense_depth"]["mean"] + k["octomap"]["mean"]:.1f} | {m["ms_build"] / 1e3:.1f} '
          f'| {m["dense_points"]} | {m["occupied_voxels"]} '
          f'| {m["store_mb"]:.0f} / {m["octree_mb"]:.0f} | {rep["peak_rss_mb"]:.0f} |')

# Loop closure (issue 15): the final trajectory's APE and revisit consistency, the map at revisits,
# what detection found and what it cost, the global graph.
print()
print("| mode | final APE RMSE (m) | revisits 5 m median / p95 (m) | map at revisits: within 0.2 m "
      "| loops verified / accepted / kept | detection ms per keyframe mean / p95 "
      "| features ms per keyframe mean | global solve (s), rounds, converged |")
print("| --- | --- | --- | --- | --- | --- | --- | --- |")
for mode in modes:
    run = os.path.join(out, mode.replace(":", "_"))
    rep = json.load(open(os.path.join(run, "report.json")))
    final_path = os.path.join(run, "eval_final.json")
    ape = rev = "-"
    if os.path.exists(final_path):
        ev = json.load(open(final_path))
        ape = f'{ev["ape"]["rmse"]:.3f}' + (" (SE3)" if not os.path.exists(
            os.path.join(run, "georef.json")) else "")
        r = ev.get("revisits", {})
        if r.get("n"):
            rev = f'{r["median"]:.3f} / {r["p95"]:.3f}'
    mr = rep.get("map", {}).get("revisits")
    map_rev = f'{100 * mr["fraction_within"]:.1f} %' if mr and mr.get("overlap_points") else "-"
    lp = rep.get("loops")
    if lp and "graph" in lp:
        g = lp["graph"]
        det = lp["ms_detection_per_keyframe"]
        solve = (f'{g["ms_solve"] / 1e3:.2f}, {g["rounds"]}, {"yes" if g["converged"] else "NO"}'
                 if g.get("solved") else "not needed (no loop)")
        print(f'| {mode} | {ape} | {rev} | {map_rev} | {lp["verified"]} / {lp["accepted"]} / '
              f'{g["active_loops"]} | {det["mean"]:.2f} / {det["p95"]:.2f} '
              f'| {lp["ms_features_per_keyframe"]["mean"]:.2f} | {solve} |')
    else:
        print(f"| {mode} | {ape} | {rev} | {map_rev} | off | - | - | - |")

# The whole command (report.json's run_wall_s) and each stage's wall time (by name).
print()
print("| mode | frames | run wall time (s) | wall time per stage (s) | peak RSS (MiB) |")
print("| --- | --- | --- | --- | --- |")
for mode in modes:
    rep = json.load(open(os.path.join(out, mode.replace(":", "_"), "report.json")))
    stages = ", ".join(f"{k} {v:.1f}" for k, v in rep.get("stage_wall_s", {}).items() if v >= 0.05)
    print(f'| {mode} | {rep["counts"]["frames"]} | {rep["run_wall_s"]:.1f} | {stages} '
          f'| {rep["peak_rss_mb"]:.0f} |')
PY

# The fused runs' floor on this draw: the error of the best constant offset the fixes allow with the
# trajectory's shape known exactly (tests/bench/gnss_offset_floor.py): what a fusion of these
# fixes can expect to reach at best.
echo
for mode in $MODES; do
  run="$OUT/${mode//:/_}"
  if [ -f "$run/georef.json" ] && [ -f "$run/gnss_fixes.csv" ]; then
    echo "$mode, seed $SEED: offset floor $(python3 tests/bench/gnss_offset_floor.py "$run" | tail -1)"
  fi
done
