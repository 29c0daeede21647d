#!/usr/bin/env bash
# Issue 62's viewer benchmark, in the real browser (Debian's chromium, headless, software GL):
#   - the demo run (./setup.sh demo's drive and run): gvio view, then first picture and memory;
#   - a merged map of BENCH_VIEWER_POINTS points (default 50 M; tests/bench/synthetic_merged_map.py:
#     20 drives in street corridors, tiles as gvio merge writes them): gvio view's cost per
#     million points, then first picture and memory, at the overview and in close.
# Targets: the demo's first picture <= 2 s; the 50 M map's <= 5 s with <= 500 MB of browser
# memory; the octree written in <= 0.2 s per million points.
# Needs ./setup.sh test (node, the page's npm packages, chromium). Cached in GVIO_BENCH_CACHE.
# usage: tests/bench/viewer_bench.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR="${BUILD_DIR:-build}"
gvio="$BUILD_DIR/app/gvio"
cache="${GVIO_BENCH_CACHE:-$BUILD_DIR/bench_cache}"
points="${BENCH_VIEWER_POINTS:-50000000}"
out="${BENCH_OUT:-out/bench/viewer}"
mkdir -p "$cache" "$out"

demo="$cache/viewer_demo"
if [ ! -f "$demo/run/report.json" ]; then
  "$gvio" simulate --trajectory assets/demo/drive.tum --seconds 20 --out "$demo/drive" --force >&2
  "$gvio" run --dataset "$demo/drive" --gnss graph --out "$demo/run" \
    --set fusion.origin=48.98253,8.39035,116.4 --set "fusion.lever_arm_b=[0,0,0.8]" >&2
fi
map="$cache/merged_${points}"
if [ ! -f "$map/tiles.json" ]; then
  /usr/bin/python3 tests/bench/synthetic_merged_map.py "$map" --points "$points" >&2
fi

# gvio view, then the browser BENCH_VIEWER_REPEATS times (default 3: a browser's memory varies
# by tens of MB from one start to the next); prints "cost_line<TAB>browser json<TAB>...".
repeats="${BENCH_VIEWER_REPEATS:-3}"
measure() {
  local input="$1" site="$2"
  rm -rf "$site"
  local log
  log=$("$gvio" view --run "$input" --out "$site" 2>&1)
  local line
  line=$(grep -o 'site written in [0-9.]* s ([0-9.]* s per million points)' <<<"$log")
  for ((i = 0; i < repeats; ++i)); do
    line+=$'\t'$(node tests/bench/viewer_bench.mjs --site "$site" --shot "$site.png")
  done
  printf '%s\n' "$line"
}

demo_line=$(measure "$demo/run" "$out/demo_site")
map_line=$(measure "$map" "$out/merged_site")
/usr/bin/python3 - "$demo_line" "$map_line" "$points" <<'PY'
import json, re, statistics, sys

def median_of(runs):
    """Each number the median over the browser's runs (nested figures too); the rest the first's."""
    first = runs[0]
    if isinstance(first, dict):
        return {k: median_of([r[k] for r in runs]) for k in first}
    if isinstance(first, (int, float)) and not isinstance(first, bool):
        return statistics.median_low(runs)
    return first

rows = []
for label, line in (("demo run", sys.argv[1]), (f"merged map, {int(sys.argv[3]) / 1e6:g} M points", sys.argv[2])):
    cost, *browser = line.split("\t")
    runs = [json.loads(b) for b in browser]
    if any(r["errors"] for r in runs):
        sys.exit(f"viewer_bench: the page reported errors on the {label}: {[r['errors'] for r in runs]}")
    b = median_of(runs)
    b["n"] = len(runs)
    per_m = re.search(r"\(([0-9.]+) s per million", cost)
    rows.append((label, b, per_m.group(1) if per_m else "n/a"))
print(f"The viewer in headless chromium (software GL: {rows[0][1].get('renderer', 'unknown')}), the median of {rows[0][1]['n']} browser starts: time from navigation to the first picture, and "
      "the browser's memory (proportional set size of all its processes), beside the floor: the "
      "same browser showing a page that only clears one WebGL canvas of the view's size; targets: "
      "demo first picture <= 2 s, 50 M points <= 5 s and <= 500 MB, octree <= 0.2 s per million points")
print()
print("| input | points | octree nodes | site written (s per M points) | first picture (ms) | memory: WebGL page (floor) / first picture / overview / close (MB) | drawn: overview / close (points, deepest level) |")
print("| --- | --- | --- | --- | --- | --- | --- |")
for label, b, per_m in rows:
    o, n = b["overview"], b["near"]
    print(f"| {label} | {b['points_total']:,} | {b['nodes_total']} | {per_m} | {b['first_picture_ms']} | "
          f"{b['pss_webgl_page_mb']} / {b['pss_first_picture_mb']} / {b['pss_overview_mb']} / {b['pss_near_mb']} | "
          f"{o['points_drawn']:,}, {o['deepest']} / {n['points_drawn']:,}, {n['deepest']} |")
PY
