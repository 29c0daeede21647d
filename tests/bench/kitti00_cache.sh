# Sourced by the benchmarks that run over the full KITTI-00 simulation tests/bench/vio_kitti00.sh
# caches: sets BUILD_DIR, GVIO and CACHE, or ends the benchmark (exit 0, with a message) when the
# simulation is absent.
BUILD_DIR="${BUILD_DIR:-build}"
GVIO="$BUILD_DIR/app/gvio"
CACHE="${GVIO_BENCH_CACHE:-$BUILD_DIR/bench_cache}/kitti00_full_seed1"
if [ ! -f "$CACHE/sim.yaml" ]; then
  echo "bench: $CACHE absent: run tests/bench/vio_kitti00.sh once to simulate KITTI-00" >&2
  exit 0
fi
