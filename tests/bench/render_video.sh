#!/usr/bin/env bash
# Video rendering cost (`gvio render --video`) on three maps: the demo drive (20 s, as
# ./setup.sh demo runs it), simulated KITTI-00's first 60 s and the whole simulated KITTI-00 (the
# cache of tests/bench/vio_kitti00.sh; that row is left out when it is absent). Each drive is
# simulated and run once (kept under BENCH_CACHE_ROOT), then each video is written and timed:
# the frame loop as `gvio render` reports it ("N frames in S s"), the setup (reading and
# uploading the map) as the rest of the wall time, the peak RSS. Prints one markdown table.
# A benchmark, not a test: nothing asserts a timing; run it on an idle machine.
#
#   tests/bench/render_video.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR="${BUILD_DIR:-build}"
GVIO="$BUILD_DIR/app/gvio"
DATA="${GVIO_SHARED_DATA:-../shared/data}/kitti00"
CACHE_ROOT="${GVIO_BENCH_CACHE:-$BUILD_DIR/bench_cache}"
OUT="${BENCH_OUT:-out/bench/render_video}"
[ -x "$GVIO" ] || { echo "bench: $GVIO not built (./setup.sh build)" >&2; exit 2; }
mkdir -p "$OUT" "$CACHE_ROOT"
GEO=(--set "fusion.origin=48.98253,8.39035,116.4" --set "fusion.lever_arm_b=[0,0,0.8]")

# run_once SIM RUN: `gvio run` of SIM into RUN (GNSS graph, map on) unless RUN holds a complete run.
run_once() {
  if [ ! -f "$2/report.json" ] || ! grep -q '"status": "complete"' "$2/report.json"; then
    rm -rf "$2"
    "$GVIO" run --dataset "$1" --gnss graph "${GEO[@]}" --out "$2" --no-progress > /dev/null 2>&1
  fi
}

# drive NAME SIMULATE_ARGS...: simulates and runs once; prints the run folder.
drive() {
  local name="$1"
  shift
  local sim="$CACHE_ROOT/render_video_$name" run="$CACHE_ROOT/render_video_${name}_run"
  if [ ! -f "$sim/sim.yaml" ]; then
    rm -rf "$sim"
    "$GVIO" simulate "$@" --out "$sim" --no-progress > /dev/null 2>&1
  fi
  run_once "$sim" "$run"
  echo "$run"
}

map_points() {
  python3 -c "import json,sys; m=json.load(open(sys.argv[1]))['map']; \
print(f\"{(m['dense_points'] + m['sparse_points']) / 1e6:.2f}\")" "$1/report.json"
}

# video LABEL RUN VIEW [render options...]: one table row.
video() {
  local label="$1" run="$2" view="$3"
  shift 3
  local log="$OUT/${label// /_}_$view.log"
  /usr/bin/time -f "wall %e rss_kb %M" "$GVIO" render --run "$run" --view "$view" \
    --video "$OUT/${label// /_}_$view.mp4" "$@" > "$log" 2>&1
  python3 - "$log" "$label" "$(map_points "$run")" "$view" "$*" <<'PY'
import re, sys
log, label, points, view, options = sys.argv[1:]
text = open(log).read()
frames, loop_s = re.search(r"(\d+) frames in ([\d.]+) s", text).groups()
wall, rss_kb = re.search(r"wall ([\d.]+) rss_kb (\d+)", text).groups()
frames, loop_s, wall = int(frames), float(loop_s), float(wall)
size = re.search(r"--size (\S+)", options)
size = size.group(1) if size else ("the camera's size" if view == "camera" else "1280x720")
rest = re.sub(r"--size \S+ ?", "", options).strip()
print(f"| {label}, {points} M map points | {view}, {size}{f' (`{rest}`)' if rest else ''}"
      f" | {frames} | {1e3 * loop_s / frames:.0f} | {wall - loop_s:.1f} |"
      f" {int(rss_kb) / 1024:.0f} |")
PY
}

echo "| map | view, size (options) | frames | ms per frame (drawing, readback, encoding) | setup (s) | peak RSS (MiB) |"
echo "| --- | --- | --- | --- | --- | --- |"
demo=$(drive demo --trajectory assets/demo/drive.tum --seconds 20)
video "demo drive 20 s" "$demo" follow --size 1920x1080
video "demo drive 20 s" "$demo" topdown
video "demo drive 20 s" "$demo" camera
if [ -f "$DATA/KITTI_00_gt.txt" ]; then
  k60=$(drive kitti00_60s --trajectory "$DATA/KITTI_00_gt.txt" \
    --times "$DATA/KITTI_00_gt_times.txt" --seconds 60 --gnss-noise spp)
  video "KITTI-00 first 60 s" "$k60" follow --size 1920x1080 --speed 2
else
  echo "bench: $DATA/KITTI_00_gt.txt absent: the KITTI-00 rows are left out" >&2
fi
full="$CACHE_ROOT/kitti00_full_seed1"
if [ -f "$full/sim.yaml" ]; then
  run="$CACHE_ROOT/render_video_kitti00_full_run"
  run_once "$full" "$run"
  video "KITTI-00" "$run" follow --size 1920x1080 --speed 50
  video "KITTI-00" "$run" topdown --size 1920x1080 --speed 50
else
  echo "bench: $full absent (tests/bench/vio_kitti00.sh simulates it): the full drive's rows are left out" >&2
fi
