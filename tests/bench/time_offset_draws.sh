#!/usr/bin/env bash
# What a camera-IMU lag costs with the online time offset estimated (issue 58), over several draws
# of the 20 s demo drive: each seed in BENCH_SEEDS (default 6-11; seed 6 is the drive of
# CliTimeOffset.KalibrTimeshift*) simulated twice in the EuRoC layout, synchronised and with its
# images stamped BENCH_LAG_S (default 0.02) s late, both run as the VIO alone (t_d estimated on
# both, the default) and evaluated with SE(3) alignment. Prints per seed the two APEs, their ratio
# and the estimator's last t_d (report.json time_offset.t_d_final_s), then the ratios' range and
# geometric mean. A benchmark, not a test: nothing asserts.
#
#   tests/bench/time_offset_draws.sh [OUT]     # OUT defaults to out/bench/time_offset_draws
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR="${BUILD_DIR:-build}"
GVIO="$BUILD_DIR/app/gvio"
SEEDS="${BENCH_SEEDS:-6 7 8 9 10 11}"
LAG="${BENCH_LAG_S:-0.02}"
OUT="${1:-out/bench/time_offset_draws}"
[ -x "$GVIO" ] || { echo "bench: $GVIO not built (./setup.sh build)" >&2; exit 2; }
mkdir -p "$OUT"

for seed in $SEEDS; do
  for lag in 0 "$LAG"; do
    drive="$OUT/drive_s${seed}_lag${lag}"
    run="$OUT/run_s${seed}_lag${lag}"
    if [ ! -f "$drive/.done" ]; then
      echo "bench: seed $seed, lag $lag s: simulating" >&2
      "$GVIO" --no-progress simulate --trajectory assets/demo/drive.tum --seconds 20 \
        --seed "$seed" --format euroc --set "sim.camera_time_offset_s=$lag" --out "$drive" \
        --force > "$OUT/simulate_s${seed}_lag${lag}.log" 2>&1
      touch "$drive/.done"
    fi
    echo "bench: seed $seed, lag $lag s: running" >&2
    rm -rf "$run"
    "$GVIO" --no-progress run --dataset "$drive" --gnss off --set map.enabled=false \
      --set loops.enabled=false --out "$run" > "$run.log" 2>&1
    "$GVIO" eval --ref "$drive/groundtruth.tum" --est "$run/trajectory_vio.tum" --align se3 \
      --json "$run/eval.json" > "$run/eval.log" 2>&1
  done
done

python3 - "$OUT" "$LAG" $SEEDS <<'PY'
import json, math, os, sys
out, lag, seeds = sys.argv[1], sys.argv[2], sys.argv[3:]

def figures(seed, lag_s):
    run = os.path.join(out, f"run_s{seed}_lag{lag_s}")
    ape = json.load(open(os.path.join(run, "eval.json")))["ape"]["rmse"]
    t_d = json.load(open(os.path.join(run, "report.json")))["time_offset"]["t_d_final_s"]
    return ape, 1e3 * t_d

print(f"The camera-IMU lag's cost over draws of the 20 s demo drive: images {1e3 * float(lag):g} ms "
      "late against synchronised, t_d estimated on both (the default), VIO alone, SE(3)-aligned APE")
print()
print("| seed | synchronised APE (m) | lagging APE (m) | ratio | last t_d: synchronised / lagging (ms) |")
print("| --- | --- | --- | --- | --- |")
ratios, sums = [], [0.0, 0.0]
for seed in seeds:
    (a0, t0), (a1, t1) = figures(seed, "0"), figures(seed, lag)
    ratios.append(a1 / a0)
    sums[0] += a0
    sums[1] += a1
    print(f"| {seed} | {a0:.4f} | {a1:.4f} | {a1 / a0:.2f} | {t0:.1f} / {t1:.1f} |")
geo = math.exp(sum(map(math.log, ratios)) / len(ratios))
print()
print(f"ratio {min(ratios):.2f} to {max(ratios):.2f}, geometric mean {geo:.2f}; APE summed over the "
      f"{len(seeds)} drives {sums[0]:.3f} m synchronised, {sums[1]:.3f} m lagging")
PY
