#!/usr/bin/env bash
# Issue 62: a run's and a merged map's 3D Tiles (gvio export --to 3dtiles) read by Cesium's
# 3d-tiles-tools (check_tiles3d.mjs). Exit 77 (skipped) without node or the tools (./setup.sh
# test installs them from this folder's lock file).
# usage: check_tiles3d.sh GVIO SOURCE_DIR WORK
set -euo pipefail
gvio="$1" src="$2" work="$3"
command -v node >/dev/null || { echo "skipped: no node"; exit 77; }
[ -x "$src/tests/tiles3d/node_modules/.bin/3d-tiles-tools" ] ||
  { echo "skipped: no 3d-tiles-tools (./setup.sh test: npm ci in tests/tiles3d)"; exit 77; }
rm -rf "$work"
mkdir -p "$work"
"$gvio" simulate --trajectory "$src/assets/demo/drive.tum" --seconds 8 --out "$work/drive" --force
"$gvio" run --dataset "$work/drive" --gnss graph --out "$work/run" --set fusion.origin=48.98253,8.39035,116.4
"$gvio" export --run "$work/run" --to 3dtiles
"$gvio" merge --runs "$work/run" --out "$work/map"
"$gvio" export --run "$work/map" --to 3dtiles
node "$src/tests/tiles3d/check_tiles3d.mjs" "$work/run/3dtiles" "$work/check_run"
node "$src/tests/tiles3d/check_tiles3d.mjs" "$work/map/3dtiles" "$work/check_map"
