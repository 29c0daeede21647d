#!/usr/bin/env bash
# Long-run memory (issue 17): `gvio run` over the full simulated KITTI-00 drive (the cache of
# tests/bench/vio_kitti00.sh) with its resident set sampled once a second from /proc, twice: the
# VIO alone (map and loop closure off: memory must stay flat) and the default run (the map store
# and loop features grow with the keyframes they keep). Prints RSS at each quarter of the drive
# and the growth per 1000 frames over the second half; writes the samples to OUT/rss_*.csv.
# A benchmark, not a test: nothing asserts.
#
#   tests/bench/rss_kitti00.sh [OUT]        # OUT defaults to build/bench_rss
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/bench/kitti00_cache.sh
OUT="${1:-$BUILD_DIR/bench_rss}"
mkdir -p "$OUT"

# run NAME [gvio run options...]: samples "t_s,rss_mib,frames_done" into OUT/rss_NAME.csv.
run() {
  local name="$1"
  shift
  local csv="$OUT/rss_$name.csv" err="$OUT/stderr_$name.txt"
  "$GVIO" run --dataset "$CACHE" --out "$OUT/run_$name" "$@" 2>"$err" &
  local pid=$! start=$SECONDS
  echo "t_s,rss_mib,frames_done" >"$csv"
  while kill -0 "$pid" 2>/dev/null; do
    local rss frames
    rss=$(awk '/^VmRSS:/ {print $2 / 1024}' "/proc/$pid/status" 2>/dev/null || true)
    # Progress lines (stderr is a file): "vio: N/M frames (...)".
    frames=$(grep -o '[0-9]*/[0-9]* frames' "$err" 2>/dev/null | tail -1 | cut -d/ -f1 || true)
    [ -n "$rss" ] && echo "$((SECONDS - start)),$rss,${frames:-0}" >>"$csv"
    sleep 1
  done
  wait "$pid"
  python3 - "$csv" "$name" "$OUT/run_$name/report.json" <<'PY'
import csv, json, sys
rows = [(float(r["t_s"]), float(r["rss_mib"]), int(r["frames_done"])) for r in csv.DictReader(open(sys.argv[1]))]
report = json.load(open(sys.argv[3]))
total = report["dataset"]["frames"]
last = max(f for _, _, f in rows)  # progress is printed every 5 s: the last line is short of the end
def at(fraction):  # RSS when the VIO had done this share of the frames (the last line for 100 %)
    for t, rss, f in rows:
        if f >= min(fraction * total, last):
            return rss
    return float("nan")
q = [at(x) for x in (0.25, 0.5, 0.75, 1.0)]
growth = (q[3] - q[1]) / (0.5 * total / 1000.0)
store = (report.get("map") or {}).get("store_mb")
print(f"{sys.argv[2]}: RSS at 25/50/75/100 % of {total} frames (last progress line: {last}): "
      f"{q[0]:.0f} / {q[1]:.0f} / {q[2]:.0f} / {q[3]:.0f} MiB; second half {growth:+.1f} MiB per "
      f"1000 frames; peak {report['peak_rss_mb']:.0f} MiB" +
      (f"; map store at the end {store:.0f} MB" if store is not None else ""))
PY
}

run vio_only --set map.enabled=false --set loops.enabled=false
run default
