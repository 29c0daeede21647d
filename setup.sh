#!/usr/bin/env bash
# gvio setup: installs exactly the Debian packages the project needs (apt-get update only when
# something is missing), builds, and runs one of:
#   ./setup.sh demo    the main job on the embedded demo input (the default)
#   ./setup.sh test    every test (ctest); this is what CI runs
#   ./setup.sh build   install + build only
#   ./setup.sh sanitize [quick|thread|thread-quick]
#                      the test suite built with AddressSanitizer + UndefinedBehaviorSanitizer
#                      (clang, in build-san; quick: without the slow drives), then the threaded
#                      tests with ThreadSanitizer (build-tsan; thread: only those; thread-quick:
#                      only the ordered worker's);
#                      SANITIZE_EXCLUDE (a ctest -E regex) skips tests of the ASan run
#   ./setup.sh fuzz [SECONDS [TARGET...]]
#                      every libFuzzer target (tests/fuzz) for SECONDS each (default 60)
#   ./setup.sh viewer  the demo (as ./setup.sh demo) and its web viewer (gvio view) in
#                      out/demo/run/viewer: node and npm from Debian, the page's npm packages from
#                      app/view/web/package-lock.json
#   ./setup.sh docs    the documentation site (MkDocs, strict) into build/site, and a check of
#                      every relative link and image in README.md
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
  librosbag-storage-dev libsensor-msgs-dev libroscpp-core-dev libbz2-dev
  libzstd-dev liblz4-dev libsqlite3-dev libcpp-httplib-dev
)
# Only the modes that build the test suite need its frameworks.
TEST_PACKAGES=(libgtest-dev libgmock-dev libbenchmark-dev)
case "$mode" in demo | viewer) ;; *) PACKAGES+=("${TEST_PACKAGES[@]}") ;; esac
# The fleet's Slurm test starts a single-node cluster (tests/fleet/slurm_fleet_test.sh).
[ "$mode" = test ] && PACKAGES+=(slurm-wlm munge)
# The web viewer's page is bundled with npm packages (node, npm) and tested in Debian's chromium.
case "$mode" in test | viewer) PACKAGES+=(nodejs) ;; esac
[ "$mode" = test ] && PACKAGES+=(chromium)
# Sanitizers and libFuzzer come with clang.
SANITIZER_PACKAGES=(clang-14 libfuzzer-14-dev libclang-rt-14-dev)
case "$mode" in sanitize | fuzz) PACKAGES+=("${SANITIZER_PACKAGES[@]}") ;; esac
# The documentation site needs nothing of the build: MkDocs and its Material theme alone.
[ "$mode" = docs ] && PACKAGES=(mkdocs mkdocs-material python3-pymdownx python3 python3-matplotlib)

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

# npm packages exactly as a folder's package-lock.json pins them (npm ci), skipped when that lock
# is what was installed last: the viewer page's (app/view/web) before CMake configures (it
# bundles the page when they are there), and for the tests Cesium's 3d-tiles-tools
# (tests/tiles3d). Debian's npm only where the nodejs package did not bring one.
npm_ci() {
  if ! command -v npm >/dev/null; then
    local sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends npm
  fi
  if ! cmp -s "$1/package-lock.json" "$1/node_modules/.package-lock.json.installed"; then
    # No install scripts: they would fetch prebuilt binaries from outside the npm registry
    # (sharp, better-sqlite3), which neither the page nor the checks use; esbuild runs without.
    (cd "$1" && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error)
    cp "$1/package-lock.json" "$1/node_modules/.package-lock.json.installed"
  fi
}

# The demo builds the app alone (the test suite is most of the compile time); the other modes
# build everything.
build() {
  local werror=OFF tests=ON target=()
  [ -n "${CI:-}" ] && werror=ON  # warnings are errors in CI
  if [ "$mode" = demo ] || [ "$mode" = viewer ]; then
    tests=OFF
    target=(--target gvio)
  fi
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DGVIO_WERROR="$werror" \
    -DGVIO_BUILD_TESTS="$tests" >/dev/null
  cmake --build "$BUILD_DIR" -j "$JOBS" "${target[@]}"
}

# The instrumented builds with clang: build_instrumented DIR SANITIZERS FUZZ [ninja targets...].
# With FUZZ=ON every target also carries libFuzzer's coverage, so that the fuzz targets and the
# ASan+UBSan suite share one build (build-san); ThreadSanitizer has a build of its own
# (build-tsan). -O1 keeps asserts on and the drives bearable; line tables alone are what the
# sanitizers' stack traces need (file:line) and build faster than -g (12m47s clean on 2 cores).
build_instrumented() {
  local dir="$1" sanitizers="$2" fuzz="$3"
  shift 3
  CC=clang-14 CXX=clang++-14 cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DGVIO_SANITIZE="$sanitizers" \
    -DGVIO_FUZZ="$fuzz" -DGVIO_WERROR=OFF -DGVIO_BUILD_TESTS=ON >/dev/null
  local targets=()
  for t in "$@"; do targets+=(--target "$t"); done
  cmake --build "$dir" -j "$JOBS" "${targets[@]}"
}

# Sanitizer reports end the program with an error (tests fail); known leaks of system libraries
# that gvio cannot free are suppressed, each with its reason, in tests/sanitizers/.
# intercept_tls_get_addr=0: LeakSanitizer's record of the dynamic TLS of Mesa's dlopen'ed modules
# goes stale and its leak check then crashes reading it ("Tracer caught signal 11"); without the
# record LSan does not scan dynamic TLS (no leak is missed by that: it can only report more).
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1:intercept_tls_get_addr=0"
export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

# The drives too slow to repeat under ASan on every change (./setup.sh sanitize quick and CI skip
# them): every test that takes more than 30 s under ASan on this 2-core machine class. The fault
# cases that run the whole 10 s drive (1.5-3.5 min each under ASan) are among them; the quick run
# keeps the fault cases refused at the input. The quick run is 3.5 min at -j2 once built; it was
# 20 min while the last 15 of these (CliMerge* to slurm_fleet, 34-250 s each) were still in it.
QUICK_SANITIZE_EXCLUDE='^(CliGnssFile|CliKalibr|CliLoops|CliLoopsNoRevisit|CliLoopsRepetitive|CliMap|CliMapLoop|CliMerge|CliMergeAlign|CliRenderCamera|CliRosbag|CliRos2Bag|CliRunDeterminism|CliRunEndToEnd|CliRunGnss|CliRunThreads|CliTimeOffset|VioDrive|SimEndToEnd|SimWorldRenderTest|SimWorldStyles|SimWorldStylesRender|MappingSim)\.|^FeatureTrackerTest\.TracksPersist|^FaultInputs\.(.*Skips|FiveSecond|ACameraBlind)|^FaultGnss\.(Kilometre|Forward)|^FaultOutput\.(FileSize|Sig)|^FaultRos2\.|^CliFleet\.(Runs|Retries)|^CliConsistencyImages\.(TheTrue|PosesMoved|TheVio)|^CliConsistencyImagesRevisits\.|^slurm_fleet$|^tutorial_|^viewer_browser$|^tiles3d_tools$'

# What runs on threads, for ThreadSanitizer: the ordered worker and prefetcher, the VIO tracking
# the next frame during the solve, and whole threaded runs of gvio (decoding ahead, keyframe work,
# the map's occupancy beside its clouds, a signal arriving mid-run).
TSAN_TESTS='(^|/)(OrderedWork.*|VioDrive\.TrackingAheadGivesTheSameResultsThroughRestarts|CliRunDeterminism\..*|FaultOutput\.Sigint.*)'
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$PWD/tests/sanitizers/tsan.supp"

# ./setup.sh sanitize: the whole suite under ASan + UBSan, then the threaded tests under TSan;
# quick: ASan + UBSan without the slow drives; thread: the TSan part alone; thread-quick: TSan over
# the ordered worker and prefetcher only (their own small binary: what CI has time for).
sanitize() {
  local exclude="${SANITIZE_EXCLUDE:-}"
  if [ "${1:-}" = thread-quick ]; then
    build_instrumented build-tsan thread OFF gvio_ordered_work_tests
    build-tsan/tests/gvio_ordered_work_tests
    return
  fi
  if [ "${1:-}" != thread ]; then
    [ "${1:-}" = quick ] && exclude="$QUICK_SANITIZE_EXCLUDE"
    build_instrumented build-san address,undefined ON
    ctest --test-dir build-san --output-on-failure -j "$JOBS" ${exclude:+-E "$exclude"}
  fi
  if [ "${1:-}" != quick ]; then
    build_instrumented build-tsan thread OFF gvio gvio_unit_tests gvio_fault_tests
    ctest --test-dir build-tsan --output-on-failure -j "$JOBS" -R "$TSAN_TESTS"
  fi
}

fuzz() {
  build_instrumented build-san address,undefined ON gvio_fuzz
  tests/fuzz/run_fuzzers.sh build-san "${1:-60}" "${@:2}"
}

install_packages
case "$mode" in test | viewer) npm_ci app/view/web ;; esac
[ "$mode" = test ] && npm_ci tests/tiles3d
case "$mode" in
  build) build ;;
  test)
    build
    ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS"
    ;;
  sanitize)
    sanitize "${2:-}"
    ;;
  fuzz)
    fuzz "${@:2}"
    ;;
  docs)
    # Strict: a broken link, a page missing from the nav or any other warning fails the build.
    # The generated references (docs/reference/) are checked against the program by ctest.
    # The benchmark tables are generated from the committed outputs (tests/bench/results): a page
    # that differs from them fails; the plots are drawn from them into the site's source (Debian's
    # python3 and matplotlib, not a python of the user's PATH).
    /usr/bin/python3 tests/tools/bench_results.py render --check
    /usr/bin/python3 tests/tools/bench_results.py plots docs/benchmarks/plots
    mkdocs build --strict --site-dir "$BUILD_DIR/site"
    python3 tests/tools/check_markdown_links.py README.md CHANGELOG.md
    ;;
  demo | viewer)
    build
    # Simulate 20 s of the embedded drive (stereo, IMU, SPP GNSS, exact truth), then validate it.
    mkdir -p out/demo
    "$BUILD_DIR/app/gvio" simulate --trajectory assets/demo/drive.tum --seconds 20 --out out/demo/drive --force
    "$BUILD_DIR/app/gvio" inspect --dataset out/demo/drive --json out/demo/inspect.json
    mkdir -p out/demo/run/render
    # GNSS graph fusion; the simulator's ENU origin and antenna lever arm make the fused trajectory
    # directly comparable with its truth (report.json evaluation_fused).
    "$BUILD_DIR/app/gvio" run --dataset out/demo/drive --gnss graph --out out/demo/run \
      --set fusion.origin=48.98253,8.39035,116.4 --set "fusion.lever_arm_b=[0,0,0.8]"
    # The views shown in the docs (docs/images/ holds copies): trajectory error, and the map from
    # above, in perspective, as OctoMap voxels and over a camera image.
    for view in error topdown perspective octomap; do
      "$BUILD_DIR/app/gvio" render --run out/demo/run --view "$view" --out "out/demo/run/render/$view.png"
    done
    # The map over the recorded left camera 12 s into the drive.
    "$BUILD_DIR/app/gvio" render --run out/demo/run --view camera --at 12 --out out/demo/run/render/camera.png
    # The map checked against every keyframe's recorded image (no ground truth needed).
    "$BUILD_DIR/app/gvio" consistency --run out/demo/run --images
    echo "setup: demo drive in out/demo/drive, run (trajectories, map.pcd/ply/las/bt/ot, report.json)" \
      "in out/demo/run, images in out/demo/run/render, the image check in out/demo/run/consistency_images"
    if [ "$mode" = viewer ]; then
      "$BUILD_DIR/app/gvio" view --run out/demo/run
      echo "setup: the viewer in out/demo/run/viewer: open index.html in a browser, or serve it" \
        "with $BUILD_DIR/app/gvio view --run out/demo/run --serve"
    fi
    ;;
  *)
    echo "usage: ./setup.sh [demo|viewer|test|build|sanitize [quick|thread|thread-quick]|fuzz [SECONDS [TARGET...]]]" >&2
    exit 2
    ;;
esac
