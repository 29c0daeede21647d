#!/usr/bin/env bash
# gvio setup: installs exactly the Debian packages the project needs (apt-get update only when
# something is missing), builds, and runs one of:
#   ./setup.sh demo    the main job on the embedded demo input (the default)
#   ./setup.sh test    every test (ctest); this is what CI runs
#   ./setup.sh build   install + build only
# Idempotent and non-interactive. Environment: BUILD_DIR (default build), JOBS (default nproc).
set -euo pipefail
cd "$(dirname "$0")"
mode="${1:-demo}"
BUILD_DIR="${BUILD_DIR:-build}"
JOBS="${JOBS:-$(nproc)}"

PACKAGES=(
  g++ cmake ninja-build pkg-config clang-format
  libeigen3-dev libceres-dev libopencv-dev libpcl-dev liboctomap-dev libgdal-dev
  libegl-dev libgl-dev libepoxy-dev libegl-mesa0 libgl1-mesa-dri
  libgeographiclib-dev libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev
  nlohmann-json3-dev libcairo2-dev zlib1g-dev
  librosbag-storage-dev libsensor-msgs-dev libroscpp-core-dev
)
# Only the modes that build the test suite need its frameworks.
TEST_PACKAGES=(libgtest-dev libgmock-dev libbenchmark-dev)
[ "$mode" != demo ] && PACKAGES+=("${TEST_PACKAGES[@]}")

install_packages() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "setup: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# The demo builds the app alone (the test suite is most of the compile time); the other modes
# build everything.
build() {
  local werror=OFF tests=ON target=()
  [ -n "${CI:-}" ] && werror=ON  # warnings are errors in CI
  if [ "$mode" = demo ]; then
    tests=OFF
    target=(--target gvio)
  fi
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DGVIO_WERROR="$werror" \
    -DGVIO_BUILD_TESTS="$tests" >/dev/null
  cmake --build "$BUILD_DIR" -j "$JOBS" "${target[@]}"
}

install_packages
build
case "$mode" in
  build) ;;
  test)
    ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS"
    ;;
  demo)
    # Simulate 20 s of the embedded drive (stereo, IMU, SPP GNSS, exact truth), then validate it.
    mkdir -p out/demo
    "$BUILD_DIR/app/gvio" simulate --trajectory assets/demo/drive.tum --seconds 20 --out out/demo/drive --force
    "$BUILD_DIR/app/gvio" inspect --dataset out/demo/drive --json out/demo/inspect.json
    mkdir -p out/demo/run/render
    # GNSS graph fusion; the simulator's ENU origin and antenna lever arm make the fused trajectory
    # directly comparable with its truth (report.json evaluation_fused).
    "$BUILD_DIR/app/gvio" run --dataset out/demo/drive --gnss graph --out out/demo/run \
      --set fusion.origin=48.98253,8.39035,116.4 --set "fusion.lever_arm_b=[0,0,0.8]"
    # The views shown in README.md (docs/images/ holds copies): trajectory error, and the map from
    # above, in perspective and as OctoMap voxels.
    for view in error topdown perspective octomap; do
      "$BUILD_DIR/app/gvio" render --run out/demo/run --view "$view" --out "out/demo/run/render/$view.png"
    done
    echo "setup: demo drive in out/demo/drive, run (trajectories, map.pcd/ply/las/bt/ot, report.json)" \
      "in out/demo/run, images in out/demo/run/render"
    ;;
  *)
    echo "usage: ./setup.sh [demo|test|build]" >&2
    exit 2
    ;;
esac
