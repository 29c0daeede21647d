#!/usr/bin/env bash
# Issue 62: the demo run (as ./setup.sh demo makes it) through `gvio view`, then the page in
# headless chromium (viewer_test.mjs): no console error, pixels drawn, the run's trajectories
# and map points, the map coloured by the image check, deeper octree levels on moving in, a
# keyframe click with its image.
# Screenshots in WORK/shots. Exit 77 (skipped) without node, the page's npm packages or chromium.
# usage: viewer_browser.sh GVIO SOURCE_DIR WORK
set -euo pipefail
gvio="$1" src="$2" work="$3"
skip() { echo "skipped: $*"; exit 77; }
command -v node >/dev/null || skip "no node (./setup.sh test installs it)"
[ -d "$src/app/view/web/node_modules/playwright-core" ] || skip "no npm packages (./setup.sh test: npm ci)"
[ -x /usr/bin/chromium ] || skip "no chromium (./setup.sh test installs Debian's)"
rm -rf "$work"
mkdir -p "$work"
"$gvio" simulate --trajectory "$src/assets/demo/drive.tum" --seconds 20 --out "$work/drive" --force
"$gvio" run --dataset "$work/drive" --gnss graph --out "$work/run" \
  --set fusion.origin=48.98253,8.39035,116.4 --set "fusion.lever_arm_b=[0,0,0.8]"
# The image check's scores, which the page shows along the drive and on the map's points.
"$gvio" consistency --run "$work/run" --images --no-progress
"$gvio" view --run "$work/run" --out "$work/site"
# What the page must show: the run's trajectories and every point of map.pcd.
trajectories=()
[ -f "$work/run/trajectory.tum" ] && trajectories+=(fused)
[ -f "$work/run/trajectory_online.tum" ] && trajectories+=(online)
[ -f "$work/run/trajectory_vio.tum" ] && trajectories+=(vio)
[ -f "$work/run/groundtruth.tum" ] && [ -f "$work/run/georef.json" ] && trajectories+=(truth)
points=$(grep -a -m1 '^POINTS ' "$work/run/map.pcd" | cut -d' ' -f2)
# The same run as a merged map (gvio merge): its tiles' points and the drive's track.
"$gvio" merge --runs "$work/run" --out "$work/map"
"$gvio" view --run "$work/map"
map_points=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["points"])' "$work/map/tiles.json")
cd "$src"
node tests/viewer/viewer_test.mjs --site "$work/site" --shots "$work/shots" \
  --trajectories "$(IFS=,; echo "${trajectories[*]}")" --points "$points" --keyframes --plots 2 --image-check
node tests/viewer/viewer_test.mjs --site "$work/map/viewer" --shots "$work/shots/merged" \
  --trajectories "drive 1" --points "$map_points"
