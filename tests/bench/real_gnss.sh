#!/usr/bin/env bash
# Fusion on a real receiver's errors (issue 58): the Nagoya drive of ../shared/data/nagoya2023 (a
# real car, its 5 Hz GNSS/INS reference and the rover's RTKLIB solutions) cut into its windows of
# continuous motion (tests/bench/real_gnss_windows.py: above 1 m/s, 50-120 s each). Each window is
# simulated once along the reference (camera and IMU; the street world) with the single-point
# solution's real errors replayed (`gvio simulate --gnss-errors-from rover_1Hz_spp.pos`, no GNSS
# lever arm), then run with the SPP and with the 5 Hz RTK solution as the receiver wrote them
# (`gvio run --gnss-file rover_1Hz_spp.pos` or `rover_rtk.pos`: with no lever arm, replaying a
# solution along its own reference gives back the solution to within the trajectory fit, 2 mm RMS;
# read from the .pos, every field RTKLIB states is fused, the error ellipse included; compare
# BENCH_SET=dataset.gnss_ellipse=circle) by the graph fusion (its smoothed
# trajectory.tum and causal trajectory_online.tum) and the paper's Kalman filter (--gnss kf).
# Everything is evaluated against the reference by `gvio eval` (horizontal and vertical errors in
# ENU, --errors-csv) and tabled by tests/bench/real_gnss_table.py: per window and solution the raw
# fixes, the floor (the window's robust mean fix error: a bias no fusion can remove), and each
# estimate's horizontal RMS / median / p95 and vertical RMS. A benchmark, not a test: nothing
# asserts.
#
#   tests/bench/real_gnss.sh
#   BENCH_WINDOWS="79.6:59.0" tests/bench/real_gnss.sh   # one window (start:length, s)
#   BENCH_SET="fusion.smoother.bias_ratio=0.3" BENCH_OUT=out/bench/x tests/bench/real_gnss.sh
#   BENCH_TABLE_ONLY=1 tests/bench/real_gnss.sh          # the table of what BENCH_OUT holds
#   BENCH_FUSIONS=kf tests/bench/real_gnss.sh            # run the KF again, keep the graph's
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR="${BUILD_DIR:-build}"
GVIO="$BUILD_DIR/app/gvio"
DATA="${GVIO_SHARED_DATA:-../shared/data}/nagoya2023"
CACHE_ROOT="${GVIO_BENCH_CACHE:-$BUILD_DIR/bench_cache}"
OUT="${BENCH_OUT:-out/bench/real_gnss}"
SOLUTIONS="${BENCH_SOLUTIONS:-spp rtk}"
FUSIONS="${BENCH_FUSIONS:-graph kf}"  # e.g. BENCH_FUSIONS=kf: run only the KF (the rest kept)
RUN_SET=()
for kv in ${BENCH_SET:-}; do RUN_SET+=(--set "$kv"); done

if [ ! -f "$DATA/reference.csv" ]; then
  echo "bench: $DATA/reference.csv absent (../shared/data/nagoya2023): nothing to measure" >&2
  exit 0
fi
REF="$DATA/reference.csv"
declare -A SOLUTION_FILE=([spp]="$DATA/rover_1Hz_spp.pos" [rtk]="$DATA/rover_rtk.pos")

windows="${BENCH_WINDOWS:-}"
if [ -z "$windows" ]; then
  windows="$(python3 tests/bench/real_gnss_windows.py "$REF" 50 120 | tr ' ' ':' | tr '\n' ' ')"
fi

# "lat,lon,h" of a run's ENU frame (georef.json enu_origin).
run_origin() {
  python3 -c 'import json,sys; o=json.load(open(sys.argv[1]))["enu_origin"]; print(",".join(repr(o[k]) for k in ("lat_deg", "lon_deg", "h_ellipsoid_m")))' "$1/georef.json"
}

evaluate() {  # evaluate RUN_DIR FILE NAME ORIGIN WINDOW_CSV
  "$GVIO" eval --ref "$5" --est "$1/$2" --origin "$4" --errors-csv "$1/$3.errors.csv" \
    > "$1/$3.eval.log" 2>&1 || echo "eval failed" > "$1/$3.failed"
}

if [ -z "${BENCH_TABLE_ONLY:-}" ]; then
  [ -x "$GVIO" ] || { echo "bench: $GVIO not built (./setup.sh build)" >&2; exit 2; }
  mkdir -p "$OUT" "$CACHE_ROOT"
  for w in $windows; do
    start="${w%%:*}"
    length="${w##*:}"
    name="nagoya_t${start}_${length}s"
    cell="$OUT/$name"
    mkdir -p "$cell"
    python3 tests/bench/real_gnss_windows.py "$REF" "$start" "$length" "$cell/reference.csv"
    cache="$CACHE_ROOT/real_gnss_$name"
    if [ ! -f "$cache/sim.yaml" ]; then
      echo "bench: $name: simulating" >&2
      "$GVIO" simulate --trajectory "$cell/reference.csv" --gnss-errors-from "${SOLUTION_FILE[spp]}" \
        --set "sim.gnss_lever_arm_m=[0,0,0]" --out "$cache" --force --no-progress \
        > "$cell/simulate.log" 2>&1 || { echo "bench: $name: simulation failed" >&2; continue; }
    fi
    for sol in $SOLUTIONS; do
      "$GVIO" eval --ref "$cell/reference.csv" --est "${SOLUTION_FILE[$sol]}" \
        --errors-csv "$cell/$sol.fixes.errors.csv" > "$cell/$sol.fixes.eval.log" 2>&1 || true
      gnss_file=(--gnss-file "${SOLUTION_FILE[$sol]}")
      for fusion in $FUSIONS; do
        run="$cell/$sol.$fusion"
        rm -rf "$run"
        echo "bench: $name: $sol $fusion" >&2
        rc=0
        "$GVIO" run --dataset "$cache" --gnss "$fusion" "${gnss_file[@]}" \
          --set map.enabled=false ${RUN_SET[@]+"${RUN_SET[@]}"} --out "$run" --no-progress \
          > "$cell/$sol.$fusion.log" 2>&1 || rc=$?
        echo "$rc" > "$cell/$sol.$fusion.rc"
        [ "$rc" -eq 0 ] || continue
        origin="$(run_origin "$run")"
        evaluate "$run" trajectory.tum final "$origin" "$cell/reference.csv"
        [ "$fusion" = graph ] && evaluate "$run" trajectory_online.tum online "$origin" "$cell/reference.csv"
      done
    done
  done
fi

python3 tests/bench/real_gnss_table.py "$OUT" $SOLUTIONS
