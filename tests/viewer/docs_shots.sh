#!/usr/bin/env bash
# The screenshots of docs/cli/view.md, made from scratch: the demo run with keyframe 95 clicked
# (docs/images/viewer_demo.jpg) and two drives of the demo's street merged with gvio merge,
# coloured by drive (docs/images/viewer_fleet.jpg). The second drive sees the same world
# (--world-seed 1, the demo's) with its own noise (--seed 2).
# Needs ./setup.sh test or ./setup.sh viewer (node, the page's npm packages, chromium).
# usage: tests/viewer/docs_shots.sh [OUT_DIR]   (default out/docs_shots; images into docs/images)
set -euo pipefail
cd "$(dirname "$0")/../.."
gvio="${BUILD_DIR:-build}/app/gvio"
out="${1:-out/docs_shots}"
geo=(--set fusion.origin=48.98253,8.39035,116.4 --set "fusion.lever_arm_b=[0,0,0.8]")
mkdir -p "$out"
for seed in 1 2; do
  "$gvio" simulate --trajectory assets/demo/drive.tum --seconds 20 --seed "$seed" --world-seed 1 \
    --out "$out/drive$seed" --force
  "$gvio" run --dataset "$out/drive$seed" --gnss graph --out "$out/run$seed" "${geo[@]}" --no-progress
done
rm -rf "$out/map" "$out/site" "$out/map_site"
"$gvio" merge --runs "$out/run1" "$out/run2" --out "$out/map"
"$gvio" view --run "$out/run1" --out "$out/site"
"$gvio" view --run "$out/map" --out "$out/map_site"
node tests/viewer/docs_shot.mjs --site "$out/site" --keyframe 95 --shot docs/images/viewer_demo.jpg
node tests/viewer/docs_shot.mjs --site "$out/map_site" --color drive --shot docs/images/viewer_fleet.jpg
