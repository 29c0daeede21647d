#!/usr/bin/env bash
# VIO across worlds: runs the pure odometry (no GNSS, no map, no loop closure) over a matrix of
# simulated world styles x seeds and prints one table (APE RMSE after SE(3) alignment, as metres
# and as % of the path length, keyframes/frames, tracking + estimator ms per frame) per VIO mode,
# a worst-seed row per style and how many stereo+IMU cells meet the target APE <= 0.10 % of the
# distance. A benchmark, not a test: nothing asserts; a cell that fails (or never initialises) is
# shown as such with its exit code and the matrix goes on.
#
# Drives: BENCH_SECONDS (default 60) of BENCH_TRAJECTORY (TUM, or KITTI with BENCH_TIMES), else of
# KITTI-00 ground truth when ../shared/data has it, starting (seed - 1) x BENCH_START_STRIDE s
# (default 150) into it (wrapped to fit), so that each seed drives other streets; else of the
# embedded assets/demo/drive.tum (35 s: shorter drives). Each is simulated once into
# GVIO_BENCH_CACHE (default build/bench_cache) with SPP GNSS, `--world-style STYLE`, `--seed SEED`
# and the IMU noise drawn per drive in BENCH_IMU_RANGE (MIN:MAX, default 0.5:2; the estimator
# assumes imu.*: KITTI's oxts cannot state the drive's noise) and, with BENCH_TURN_ON (ACC:GYR,
# 1-sigma per axis in m/s^2 and rad/s; default none), turn-on biases drawn per drive.
# BENCH_SET ("key=value ...") adds `--set` overrides to every run (compare a setting on the matrix);
# BENCH_SIM_SET ("sim.key=value ...") adds them to every simulation (sensor effects: exposure
# changes, a stereo gain mismatch, motion blur), with its own cache folders.
# BENCH_IMU_NOISE=truth:K tells the estimator each drive's own IMU noise (its sim.yaml) times K,
# as a dataset that states its noise would (default: imu.*, which the drives' noise is drawn
# around): the measure of how far the stated noise should be inflated.
#
#   tests/bench/vio_matrix.sh                                   # 5 styles x 3 seeds x 3 modes
#   BENCH_STYLES="street open_road" BENCH_SEEDS="1 2" BENCH_SECONDS=30 tests/bench/vio_matrix.sh
#   BENCH_RESUME=1 tests/bench/vio_matrix.sh      # keep cells that already finished
#   BENCH_TABLE_ONLY=1 tests/bench/vio_matrix.sh  # print the table of what BENCH_OUT holds
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR="${BUILD_DIR:-build}"
GVIO="$BUILD_DIR/app/gvio"
SEEDS="${BENCH_SEEDS:-1 2 3}"
MODES="${BENCH_MODES:-stereo-imu stereo mono-imu}"
IMU_RANGE="${BENCH_IMU_RANGE:-0.5:2}"
TURN_ON="${BENCH_TURN_ON:-}"
TURN_ON_SET=()
TURN_ON_TAG=""
RUN_SET=()
for kv in ${BENCH_SET:-}; do RUN_SET+=(--set "$kv"); done
SIM_SET=()
SIM_TAG=""
for kv in ${BENCH_SIM_SET:-}; do
  SIM_SET+=(--set "$kv")
  SIM_TAG="${SIM_TAG}_${kv#sim.}"
done
SIM_TAG="${SIM_TAG//[^A-Za-z0-9_.=-]/_}"
if [ -n "$TURN_ON" ]; then
  IFS=: read -r TURN_ACC TURN_GYR <<< "$TURN_ON"
  if [ -z "${TURN_ACC:-}" ] || [ -z "${TURN_GYR:-}" ]; then
    echo "bench: BENCH_TURN_ON must be ACC:GYR, not '$TURN_ON'" >&2
    exit 2
  fi
  TURN_ON_SET=(--set "sim.imu_turn_on_acc_bias_mps2=$TURN_ACC" --set
    "sim.imu_turn_on_gyr_bias_radps=$TURN_GYR")
  TURN_ON_TAG="_bias${TURN_ACC}-${TURN_GYR}"
fi
NOISE_K=""
if [ -n "${BENCH_IMU_NOISE:-}" ]; then
  NOISE_K="${BENCH_IMU_NOISE#truth:}"
  if [ "$NOISE_K" = "$BENCH_IMU_NOISE" ] || ! [[ "$NOISE_K" =~ ^[0-9]*\.?[0-9]+$ ]] ||
    ! awk -v k="$NOISE_K" 'BEGIN { exit !(k > 0) }'; then
    echo "bench: BENCH_IMU_NOISE must be truth:K (K > 0), not '$BENCH_IMU_NOISE'" >&2
    exit 2
  fi
fi
OUT="${BENCH_OUT:-out/bench/vio_matrix}"
IFS=: read -r IMU_MIN IMU_MAX <<< "$IMU_RANGE"
if [ -z "${IMU_MIN:-}" ] || [ -z "${IMU_MAX:-}" ]; then
  echo "bench: BENCH_IMU_RANGE must be MIN:MAX, not '$IMU_RANGE'" >&2
  exit 2
fi

source tests/bench/matrix_drives.sh

# The drive's own IMU noise (sim.yaml's imu_noise densities) times K, as `--set imu.*=` pairs.
truth_noise_set() {
  python3 - "$1/sim.yaml" "$2" <<'PY'
import re, sys
text, k = open(sys.argv[1]).read(), float(sys.argv[2])
block = re.search(r"^imu_noise:\n((?:[ ]+.*\n)+)", text, re.M)
if not block:
    sys.exit(f"bench: {sys.argv[1]}: no imu_noise block")
for key in ("acc_noise_density", "gyr_noise_density", "acc_random_walk", "gyr_random_walk"):
    value = re.search(rf"^\s+{key}:\s*([0-9.eE+-]+)", block.group(1), re.M)
    if not value:
        sys.exit(f"bench: {sys.argv[1]}: imu_noise has no {key}")
    print(f"imu.{key}={k * float(value.group(1)):.9g}")
PY
}

# One cell: its drive simulated (once), then every mode run and evaluated.
run_cell() {
  local style=$1 seed=$2
  echo "$cache" > "$cell/drive.txt"
  echo "$start" > "$cell/start_s.txt"
  sim_rc=0
  simulate_drive "$style" "$seed" "$start" "$cache" || sim_rc=$?
  echo "$sim_rc" > "$cell/simulate_rc.txt"
  for mode in $MODES; do
    run="$cell/$mode"
    if [ -n "${BENCH_RESUME:-}" ] && [ -f "$run/rc.txt" ]; then continue; fi
    rm -rf "$run"
    mkdir -p "$run"
    if [ "$sim_rc" -ne 0 ]; then
      echo "simulate $sim_rc" > "$run/rc.txt"
      continue
    fi
    echo "bench: $style seed $seed $mode" >&2
    noise_set=()
    if [ -n "$NOISE_K" ]; then
      while read -r kv; do noise_set+=(--set "$kv"); done < <(truth_noise_set "$cache" "$NOISE_K")
      [ "${#noise_set[@]}" -eq 8 ] || { echo "bench: no IMU noise in $cache/sim.yaml" >&2; exit 2; }
    fi
    run_rc=0
    "$GVIO" run --dataset "$cache" --gnss off --set "vio.mode=$mode" --set map.enabled=false \
      --set loops.enabled=false ${noise_set[@]+"${noise_set[@]}"} ${RUN_SET[@]+"${RUN_SET[@]}"} \
      --out "$run" --no-progress \
      > "$run/run.log" 2>&1 || run_rc=$?
    eval_rc=-1
    if [ "$run_rc" -eq 0 ] && [ -s "$run/trajectory_vio.tum" ]; then
      eval_rc=0
      "$GVIO" eval --ref "$cache/groundtruth.tum" --est "$run/trajectory_vio.tum" --align se3 \
        --json "$run/eval.json" > "$run/eval.log" 2>&1 || eval_rc=$?
    fi
    echo "run $run_rc eval $eval_rc" > "$run/rc.txt"
  done
}

for_each_cell run_cell

if [ -n "$NOISE_K" ]; then
  echo "estimator's IMU noise: each drive's own (sim.yaml) x $NOISE_K (BENCH_IMU_NOISE)"
fi
python3 - "$OUT" "$CACHE_ROOT" "$DRIVE_S" "$IMU_RANGE" "$TRAJ_TAG" "$STYLES" "$SEEDS" "$MODES" <<'PY'
import json, math, os, re, sys
out, cache_root, drive_s, imu_range, traj_tag = sys.argv[1:6]
styles, seeds, modes = sys.argv[6].split(), sys.argv[7].split(), sys.argv[8].split()
TARGET = 0.10  # % of the distance, stereo+IMU

def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None

def read(path, default=""):
    try:
        with open(path) as f:
            return f.read().strip()
    except OSError:
        return default

def drive_info(cell):
    """Start, truth path length and the drive's IMU noise factors, from the cached drive."""
    cache = read(os.path.join(cell, "drive.txt"))
    sim = read(os.path.join(cache, "sim.yaml")) if cache else ""
    length = re.search(r"^\s*path_length_m:\s*([0-9.eE+-]+)", sim, re.M)
    scale = re.search(r"^\s*scale:\s*\[([^\]]*)\]", sim, re.M)
    factors = [float(x) for x in scale.group(1).split(",")] if scale else []
    return (read(os.path.join(cell, "start_s.txt"), "?"),
            float(length.group(1)) if length else None, factors)

def cell_result(run):
    """(sort key: APE % or inf, the table cells for this mode, (APE m, evaluated path m) or None)."""
    rc = read(os.path.join(run, "rc.txt"))
    if not rc:
        return float("inf"), ["not run", "", "", ""], None
    words = rc.split()
    if words[0] == "simulate":
        return float("inf"), [f"simulation failed (exit {words[1]})", "", "", ""], None
    run_rc, eval_rc = int(words[1]), int(words[3])
    rep = load(os.path.join(run, "report.json"))
    counts = rep.get("counts", {}) if rep else {}
    kf = (f'{counts.get("keyframes", "?")}/{counts.get("frames", "?")}' if rep else "")
    t = rep.get("timing_ms", {}) if rep else {}
    ms = (f'{t["tracking"]["mean"] + t["estimator"]["mean"]:.1f}'
          if "tracking" in t and "estimator" in t else "")
    if run_rc != 0:
        return float("inf"), [f"run failed (exit {run_rc})", "", kf, ms], None
    if not counts.get("poses_written"):
        return float("inf"), ["never initialised", "", kf, ms], None
    ev = load(os.path.join(run, "eval.json"))
    if eval_rc != 0 or not ev:
        return float("inf"), [f"eval failed (exit {eval_rc})", "", kf, ms], None
    rmse = ev["ape"]["rmse"]
    # The % is of the path the estimate covers (report.json's evaluation), which is shorter than
    # the drive's (the path column) by what passes before the initialisation.
    length = rep.get("evaluation", {}).get("path_length_m")
    if not length:
        return float("inf"), [f"{rmse:.3f}", "no path length", kf, ms], None
    pct = 100.0 * rmse / length
    late = ""
    if counts.get("poses_written") and counts.get("frames"):
        share = counts["poses_written"] / counts["frames"]
        if share < 0.9:  # a late initialisation: the APE covers only part of the drive
            late = f" ({100 * share:.0f} % of frames)"
    return pct, [f"{rmse:.3f}{late}", f"{pct:.3f}", kf, ms], (rmse, length)

head = ["style", "seed", "start (s)", "path (m)", "IMU noise x"]
for m in modes:
    head += [f"{m} APE (m)", f"{m} APE %", f"{m} KF/frames", f"{m} ms/frame"]
print(f"VIO across worlds: {drive_s} s drives of {traj_tag}, IMU noise x{imu_range.replace(':', '-')} "
      f"per drive, SE(3)-aligned APE RMSE, no GNSS / map / loops; target stereo-imu APE <= "
      f"{TARGET:.2f} % of the path")
print()
print("| " + " | ".join(head) + " |")
print("|" + " --- |" * len(head))
results = {m: [] for m in modes}  # mode -> [(pct, style, seed, (APE m, evaluated m) or None)]
for style in styles:
    worst = {m: (float("-inf"), "") for m in modes}
    for seed in seeds:
        cell = os.path.join(out, f"{style}_seed{seed}")
        start, length, factors = drive_info(cell)
        imu = f"{min(factors):.2f}-{max(factors):.2f}" if factors else ""
        row = [style, seed, start, f"{length:.0f}" if length else "", imu]
        for m in modes:
            pct, cells, ape = cell_result(os.path.join(cell, m))
            row += cells
            if pct > worst[m][0]:
                worst[m] = (pct, f"{cells[1] or cells[0]} (seed {seed})")
            results[m].append((pct, style, seed, ape))
        print("| " + " | ".join(row) + " |")
    row = [f"**{style} worst**", "", "", "", ""]
    for m in modes:
        row += ["", f"**{worst[m][1]}**", "", ""]
    print("| " + " | ".join(row) + " |")
print()

def geometric_mean(values):
    return math.exp(sum(math.log(v) for v in values) / len(values))

# Per mode: the cells within the target (checked unrounded), the worst cell to four decimals
# with its APE and evaluated path, and the geometric means (% and m) over the cells that have an
# APE; the target applies to stereo-imu, the other modes' counts are for comparison.
for m in modes:
    cells = results[m]
    met = sum(1 for p, _, _, _ in cells if p <= TARGET)
    p, style, seed, ape = max(cells, key=lambda c: c[0])
    if ape:
        shown = f"{p:.4f} %: {ape[0]:.3f} m over {ape[1]:.1f} m evaluated"
    else:
        shown = "no APE"
    print(f"{m}: {met} of {len(cells)} cells within {TARGET:.2f} % of the path; "
          f"worst cell: {style} seed {seed} ({shown})")
    finite = [c for c in cells if c[3]]
    if finite:
        print(f"{m}: geometric mean APE {geometric_mean([c[0] for c in finite]):.4f} % of the "
              f"path, {geometric_mean([c[3][0] for c in finite]):.3f} m, over {len(finite)} of "
              f"{len(cells)} cells")
PY
