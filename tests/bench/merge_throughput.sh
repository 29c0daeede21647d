#!/usr/bin/env bash
# gvio merge's throughput and peak memory (issue 18's targets: >= 3 M points/s on one core,
# <= 1 GB for 10 KITTI-00-sized runs). Merges one run folder BENCH_COPIES times (default 10) as if
# they were different drives (hard-linked copies of its map.pcd, georef.json and trajectories:
# merge refuses a run given twice), without the joint alignment, pinned to one core. Prints
# points, tiles, seconds, M points/s and peak RSS. A benchmark, not a test: nothing asserts.
#
# BENCH_RUN: the run folder (default: the KITTI-00 graph+loops run of tests/bench/vio_kitti00.sh).
# Work folder: BENCH_OUT (default build/bench_merge_throughput; removed and made again).
#
#   tests/bench/merge_throughput.sh
#   BENCH_RUN=out/my_run BENCH_COPIES=4 tests/bench/merge_throughput.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR="${BUILD_DIR:-build}"
GVIO="$(pwd)/$BUILD_DIR/app/gvio"
RUN="${BENCH_RUN:-out/bench/vio_kitti00_full/stereo-imu_graph}"
COPIES="${BENCH_COPIES:-10}"
OUT="${BENCH_OUT:-$BUILD_DIR/bench_merge_throughput}"
[ -x "$GVIO" ] || { echo "bench: build gvio first ($GVIO)" >&2; exit 2; }
[ -f "$RUN/map.pcd" ] && [ -f "$RUN/georef.json" ] ||
  { echo "bench: $RUN is not a georeferenced run folder with a map.pcd (set BENCH_RUN)" >&2; exit 2; }
rm -rf "$OUT"
mkdir -p "$OUT"
runs=()
for i in $(seq 1 "$COPIES"); do
  mkdir -p "$OUT/r$i"
  for f in "$RUN"/*; do
    case "$(basename "$f")" in keyframes.bin | map.las | map.ply | map.bt | map.ot) continue ;; esac
    ln "$f" "$OUT/r$i/" 2>/dev/null || cp "$f" "$OUT/r$i/"
  done
  runs+=("$OUT/r$i")
done
pin=()
command -v taskset > /dev/null && pin=(taskset -c 0)
/usr/bin/time -f "%e %M" -o "$OUT/merge.time" "${pin[@]}" "$GVIO" -v merge --runs "${runs[@]}" \
  --out "$OUT/map" --set merge.align=false > "$OUT/merge.log" 2>&1
grep -E "first pass|second pass|points/s" "$OUT/merge.log" | sed 's/^\[[a-z]*\] //'
read -r wall rss_kb < "$OUT/merge.time"
python3 - "$OUT/map/tiles.json" "$wall" "$rss_kb" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))
wall, rss_mb = float(sys.argv[2]), int(sys.argv[3]) / 1024
points = sum(tile["points"] for tile in t["tiles"])
print(f"bench: {points} points in {len(t['tiles'])} tiles: {wall:.1f} s (whole process), "
      f"{points / wall / 1e6:.2f} M points/s, peak RSS {rss_mb:.0f} MB")
PY
