# The matrix's drives, shared by the benchmarks over world styles x seeds (vio_matrix.sh,
# image_check_matrix.sh): sourced, not run. The caller sets BUILD_DIR, GVIO, IMU_MIN, IMU_MAX, OUT
# and the optional arrays TURN_ON_SET and SIM_SET (with the tags TURN_ON_TAG, SIM_TAG naming their
# cache folders). The environment: GVIO_SHARED_DATA, BENCH_STYLES, BENCH_SECONDS (default 60),
# BENCH_START_STRIDE (default 150), GVIO_BENCH_CACHE (default BUILD_DIR/bench_cache),
# BENCH_TRAJECTORY / BENCH_TIMES.
# shellcheck shell=bash

DATA="${GVIO_SHARED_DATA:-../shared/data}/kitti00"
STYLES="${BENCH_STYLES:-street open_road sparse_texture repetitive vegetation}"
DRIVE_S="${BENCH_SECONDS:-60}"
STRIDE_S="${BENCH_START_STRIDE:-150}"
CACHE_ROOT="${GVIO_BENCH_CACHE:-$BUILD_DIR/bench_cache}"

# The trajectory: a window of KITTI-00 per seed, or one file for every seed.
TRAJ_KIND="file"
TRAJ=""
TIMES=""
if [ -n "${BENCH_TRAJECTORY:-}" ]; then
  TRAJ="$BENCH_TRAJECTORY"
  TIMES="${BENCH_TIMES:-}"
elif [ -f "$DATA/KITTI_00_gt.txt" ] && [ -f "$DATA/KITTI_00_gt_times.txt" ]; then
  TRAJ_KIND=kitti00
else
  TRAJ="assets/demo/drive.tum"
  echo "bench: $DATA absent: driving assets/demo/drive.tum (35 s, the same route for every seed)" >&2
fi
TRAJ_TAG=kitti00
if [ "$TRAJ_KIND" = file ]; then
  TRAJ_TAG="$(basename "$TRAJ")"
  TRAJ_TAG="${TRAJ_TAG%.*}"
  TRAJ_TAG="${TRAJ_TAG//[^A-Za-z0-9_-]/_}"
fi

# Start of seed SEED's window into KITTI-00 (s): (seed - 1) x stride, wrapped into the drive.
kitti_start() {
  python3 - "$DATA/KITTI_00_gt_times.txt" "$1" "$STRIDE_S" "$DRIVE_S" <<'PY'
import sys
times = [float(l) for l in open(sys.argv[1]) if l.strip()]
seed, stride, dur = int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
span = max(times[-1] - times[0] - dur, 0.0)
start = ((seed - 1) * stride) % span if span > 0 else 0.0
print(f"{start:g}")
PY
}

# The cache folder of one drive (its name says everything the simulation was given).
drive_cache() {
  local style=$1 seed=$2 start=$3
  echo "$CACHE_ROOT/vio_matrix_${TRAJ_TAG}_t${start}_${DRIVE_S}s_${style}_seed${seed}_imu${IMU_MIN}-${IMU_MAX}${TURN_ON_TAG:-}${SIM_TAG:-}"
}

# Calls `$1 STYLE SEED` for every cell of the matrix (STYLES x SEEDS) with `start` (s into
# KITTI-00), `cache` (the drive's folder) and `cell` (OUT/STYLE_seedSEED, made) set; nothing when
# BENCH_TABLE_ONLY is set.
for_each_cell() {
  local body=$1 style seed
  [ -n "${BENCH_TABLE_ONLY:-}" ] && return 0
  [ -x "$GVIO" ] || { echo "bench: $GVIO not built (./setup.sh build)" >&2; exit 2; }
  mkdir -p "$OUT"
  for style in $STYLES; do
    for seed in $SEEDS; do
      start=0
      [ "$TRAJ_KIND" = kitti00 ] && start="$(kitti_start "$seed")"
      cache="$(drive_cache "$style" "$seed" "$start")"
      cell="$OUT/${style}_seed${seed}"
      mkdir -p "$cell"
      "$body" "$style" "$seed"
    done
  done
}

# Simulates one drive into the cache (once); prints nothing, returns the simulator's exit code.
simulate_drive() {
  local style=$1 seed=$2 start=$3 cache=$4
  [ -f "$cache/sim.yaml" ] && return 0
  local traj=("--trajectory" "$TRAJ") tmp=""
  [ -n "$TIMES" ] && traj+=(--times "$TIMES")
  if [ "$TRAJ_KIND" = kitti00 ]; then
    # The window as its own KITTI trajectory (poses in KITTI-00's world; the simulator starts the
    # stamps at its default epoch), in a temporary folder: no copy of the shared data stays.
    tmp="$(mktemp -d)"
    python3 tests/bench/kitti00_window.py "$DATA/KITTI_00_gt.txt" "$DATA/KITTI_00_gt_times.txt" \
      "$start" "$tmp"
    traj=(--trajectory "$tmp/kitti00_window.txt" --times "$tmp/kitti00_window_times.txt")
  fi
  echo "bench: simulating $style seed $seed (${DRIVE_S} s from ${start} s) into $cache" >&2
  rm -rf "$cache.partial"
  mkdir -p "$cache.partial"
  local rc=0
  "$GVIO" simulate "${traj[@]}" --gnss-noise spp --seed "$seed" --seconds "$DRIVE_S" \
    --world-style "$style" --set "sim.imu_noise_scale_min=$IMU_MIN" \
    --set "sim.imu_noise_scale_max=$IMU_MAX" ${TURN_ON_SET[@]+"${TURN_ON_SET[@]}"} \
    ${SIM_SET[@]+"${SIM_SET[@]}"} --out "$cache.partial" --force \
    --no-progress \
    > "$cache.partial/simulate.log" 2>&1 || rc=$?
  [ -n "$tmp" ] && rm -rf "$tmp"
  if [ "$rc" -ne 0 ]; then
    echo "bench: simulation failed (exit $rc): $cache.partial/simulate.log" >&2
    return "$rc"
  fi
  echo "trajectory: ${TRAJ_TAG} start_s: ${start} seconds: ${DRIVE_S}" > "$cache.partial/bench_drive.txt"
  rm -rf "$cache"
  mv "$cache.partial" "$cache"
}
