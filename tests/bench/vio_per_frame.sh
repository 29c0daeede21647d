#!/usr/bin/env bash
# Per-frame cost of the VIO (issue 7's 20 ms target): `gvio run` over the full simulated KITTI-00
# drive (the cache of tests/bench/vio_kitti00.sh) with the map, loop closure and GNSS off, twice:
# pinned to one core with one thread (`taskset -c 0 ... --threads 1`: the tracking and estimator
# clocks are the frame's whole cost) and with two threads (decoding ahead, the next frame tracked
# during the solve: the stage's wall time is what a user waits for). Prints each run's per-frame
# tracking and estimator times (report.json timing_ms), the VIO stage's wall time per frame, the
# VIO APE and whether the two trajectories are the same bytes, with the load average before each
# run (the figures need an otherwise idle machine). BENCH_SET ("key=value ...") adds `--set`
# overrides to both runs (an option's cost: BENCH_SET="vio.tracker.detect_level=1"). A benchmark,
# not a test: nothing asserts.
#
#   tests/bench/vio_per_frame.sh [OUT]        # OUT defaults to out/bench/vio_per_frame
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/bench/kitti00_cache.sh
OUT="${1:-out/bench/vio_per_frame}"
[ -x "$GVIO" ] || { echo "bench: $GVIO not built (./setup.sh build)" >&2; exit 2; }
command -v taskset > /dev/null || { echo "bench: taskset (util-linux) not found" >&2; exit 2; }
mkdir -p "$OUT"

VIO_ONLY=(--gnss off --set map.enabled=false --set loops.enabled=false --no-progress)
for kv in ${BENCH_SET:-}; do VIO_ONLY+=(--set "$kv"); done
cut -d' ' -f1 /proc/loadavg > "$OUT/load_one_core.txt"
taskset -c 0 "$GVIO" run --dataset "$CACHE" "${VIO_ONLY[@]}" --threads 1 --out "$OUT/one_core"
cut -d' ' -f1 /proc/loadavg > "$OUT/load_two_threads.txt"
"$GVIO" run --dataset "$CACHE" "${VIO_ONLY[@]}" --threads 2 --out "$OUT/two_threads"

python3 - "$OUT" <<'PY'
import json, os, sys
out = sys.argv[1]
TARGET_MS = 20.0


def read(name):
    with open(os.path.join(out, name)) as f:
        return f.read()


print("The VIO over the full simulated KITTI-00 drive (map, loops and GNSS off): per-frame cost")
print()
print("| run | load before | frames | tracking ms mean / p95 | estimator ms mean / p95 "
      "| tracking + estimator (ms) | VIO stage wall (s) | wall per frame (ms) | VIO APE (m) |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
sums = {}
for run, label in (("one_core", "one core, 1 thread"), ("two_threads", "2 threads")):
    rep = json.loads(read(os.path.join(run, "report.json")))
    t = rep["timing_ms"]
    frames = rep["counts"]["frames"]
    sums[run] = t["tracking"]["mean"] + t["estimator"]["mean"]
    ape = rep.get("evaluation", {}).get("ape_se3", {}).get("rmse")
    ape_text = f"{ape:.3f}" if ape is not None else "-"
    load = read(f"load_{run}.txt").strip()
    print(f'| {label} | {load} | {frames} '
          f'| {t["tracking"]["mean"]:.2f} / {t["tracking"]["p95"]:.2f} '
          f'| {t["estimator"]["mean"]:.2f} / {t["estimator"]["p95"]:.2f} | {sums[run]:.2f} '
          f'| {rep["wall_s"]:.1f} | {1e3 * rep["wall_s"] / frames:.1f} | {ape_text} |')
print()
same = read("one_core/trajectory_vio.tum") == read("two_threads/trajectory_vio.tum")
print(f"trajectory_vio.tum: {'the same bytes' if same else 'DIFFERENT'} with 1 and 2 threads")
met = "met" if sums["one_core"] <= TARGET_MS else "not met"
print(f"one core: tracking + estimator {sums['one_core']:.2f} ms per frame "
      f"(target {TARGET_MS:.0f} ms: {met})")
PY
