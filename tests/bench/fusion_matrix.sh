#!/usr/bin/env bash
# GNSS fusion across worlds: `gvio run --gnss BENCH_GNSS` (default graph) over the drives that
# tests/bench/vio_matrix.sh simulated (GVIO_BENCH_CACHE/vio_matrix_*, SPP GNSS), per VIO mode, map
# off, loops as configured. Each run is evaluated without alignment against the drive's truth,
# in the simulator's own ENU frame (its origin and GNSS lever arm read from the drive's sim.yaml
# and given to the run): the final trajectory (trajectory.tum: smoothed and loop-closed) and the
# causal one (trajectory_online.tum). Prints one table, APE RMSE in metres, and each mode's mean
# over the drives it ran on. A benchmark, not a test: nothing asserts; a failed run is shown as
# such and the matrix goes on.
#
#   tests/bench/vio_matrix.sh                   # simulates the drives (and runs the VIO alone)
#   tests/bench/fusion_matrix.sh                # 3 modes x every cached drive, graph fusion
#   BENCH_MODES=stereo BENCH_DRIVES='*seed2*' BENCH_SET="fusion.vio_rot_floor_rad=1e-3" \
#     tests/bench/fusion_matrix.sh              # one mode, some drives, a setting to compare
#   BENCH_SKIP='*sparse_texture*' tests/bench/fusion_matrix.sh   # leave some drives out
#   BENCH_TABLE_ONLY=1 tests/bench/fusion_matrix.sh  # the table of what BENCH_OUT holds
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR="${BUILD_DIR:-build}"
GVIO="$BUILD_DIR/app/gvio"
CACHE_ROOT="${GVIO_BENCH_CACHE:-$BUILD_DIR/bench_cache}"
MODES="${BENCH_MODES:-stereo-imu stereo mono-imu}"
GNSS="${BENCH_GNSS:-graph}"
DRIVES="${BENCH_DRIVES:-*}"
SKIP="${BENCH_SKIP:-}"
OUT="${BENCH_OUT:-out/bench/fusion_matrix}"
RUN_SET=()
for kv in ${BENCH_SET:-}; do RUN_SET+=(--set "$kv"); done
case "$GNSS" in kf | graph) ;; *)
  echo "bench: BENCH_GNSS must be kf or graph, not '$GNSS'" >&2
  exit 2
  ;;
esac

# "lat,lon,h lx,ly,lz" from a drive's sim.yaml: the simulator's ENU origin and GNSS lever arm.
sim_frame() {
  python3 - "$1/sim.yaml" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
def value(key):
    m = re.search(rf"^\s*{key}:\s*(\S+)", text, re.M)
    if not m:
        sys.exit(f"bench: {sys.argv[1]} has no {key}")
    return m.group(1)
lever = re.search(r"^\s*gnss_lever_arm_m:\s*\[([^\]]*)\]", text, re.M)
arm = ",".join(x.strip() for x in lever.group(1).split(",")) if lever else "0,0,0"
print(f"{value('origin_lat_deg')},{value('origin_lon_deg')},{value('origin_h_m')} {arm}")
PY
}

shopt -s nullglob
# shellcheck disable=SC2206  # DRIVES is a glob
drives=("$CACHE_ROOT"/vio_matrix_$DRIVES)
cached=()
for d in "${drives[@]}"; do
  # shellcheck disable=SC2053  # SKIP is a glob
  [ -n "$SKIP" ] && [[ "$(basename "$d")" == vio_matrix_$SKIP ]] && continue
  [ -f "$d/sim.yaml" ] && cached+=("$d")
done
if [ "${#cached[@]}" -eq 0 ]; then
  echo "bench: no simulated drives in $CACHE_ROOT (vio_matrix_$DRIVES): run tests/bench/vio_matrix.sh first" >&2
  exit 2
fi

if [ -z "${BENCH_TABLE_ONLY:-}" ]; then
  [ -x "$GVIO" ] || { echo "bench: $GVIO not built (./setup.sh build)" >&2; exit 2; }
  mkdir -p "$OUT"
  for cache in "${cached[@]}"; do
    name="$(basename "$cache")"
    read -r origin lever <<< "$(sim_frame "$cache")"
    for mode in $MODES; do
      run="$OUT/$name/$mode"
      rm -rf "$run"
      mkdir -p "$run"
      echo "bench: $name $mode" >&2
      run_rc=0
      "$GVIO" run --dataset "$cache" --gnss "$GNSS" --set "vio.mode=$mode" \
        --set "fusion.origin=$origin" --set "fusion.lever_arm_b=[$lever]" --set map.enabled=false \
        ${RUN_SET[@]+"${RUN_SET[@]}"} --out "$run" --no-progress > "$run/run.log" 2>&1 || run_rc=$?
      for which in trajectory trajectory_online; do
        if [ "$run_rc" -eq 0 ] && [ -s "$run/$which.tum" ]; then
          "$GVIO" eval --ref "$cache/groundtruth.tum" --est "$run/$which.tum" --align none \
            --json "$run/$which.eval.json" > "$run/$which.eval.log" 2>&1 || true
        fi
      done
      echo "$run_rc" > "$run/rc.txt"
    done
  done
fi

python3 - "$OUT" "$GNSS" "$MODES" "${cached[@]}" <<'PY'
import json, os, sys
out, gnss, modes, drives = sys.argv[1], sys.argv[2], sys.argv[3].split(), sys.argv[4:]

def ape(path):
    try:
        with open(path) as f:
            return json.load(f)["ape"]["rmse"]
    except (OSError, ValueError, KeyError):
        return None

def read(path):
    try:
        with open(path) as f:
            return f.read().strip()
    except OSError:
        return ""

print(f"GNSS fusion across worlds (--gnss {gnss}, SPP fixes): APE RMSE (m) without alignment, "
      "final (trajectory.tum) / online (trajectory_online.tum)")
print()
head = ["drive"] + [f"{m} final / online" for m in modes]
print("| " + " | ".join(head) + " |")
print("|" + " --- |" * len(head))
sums = {m: [] for m in modes}
for cache in drives:
    name = os.path.basename(cache)
    row = [name.removeprefix("vio_matrix_")]
    for m in modes:
        run = os.path.join(out, name, m)
        rc = read(os.path.join(run, "rc.txt"))
        final = ape(os.path.join(run, "trajectory.eval.json"))
        online = ape(os.path.join(run, "trajectory_online.eval.json"))
        if not rc:
            row.append("not run")
        elif rc != "0":
            row.append(f"run failed (exit {rc})")
        elif final is None or online is None:
            row.append("eval failed")
        else:
            row.append(f"{final:.3f} / {online:.3f}")
            sums[m].append((final, online))
    print("| " + " | ".join(row) + " |")
row = ["**mean**"]
for m in modes:
    s = sums[m]
    row.append(f"**{sum(a for a, _ in s) / len(s):.3f} / {sum(b for _, b in s) / len(s):.3f}** "
               f"({len(s)} drives)" if s else "")
print("| " + " | ".join(row) + " |")
PY
