#!/usr/bin/env bash
# Issue 18 end to end on a real Slurm cluster: a single-node cluster started here (munged,
# slurmctld and slurmd as root, a generated slurm.conf with proctrack/linuxproc, task/none and
# cgroup/v1, the way these containers allow), `gvio fleet --engine slurm` on three short simulated
# drives and a missing one, `gvio merge` of the fleet, then an unreachable controller. Every daemon
# it started is stopped by its pid. Skipped (exit 77) without Slurm or root.
#   usage: slurm_fleet_test.sh GVIO SOURCE_DIR
set -euo pipefail
gvio=$1
src=$2
. "$src/tests/fleet/test_cluster.sh"
work=$(mktemp -d /tmp/gvio_slurm_XXXXXX)
cleanup() {
  test_cluster_stop
  rm -rf "$work"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  test_cluster_logs "$work/cluster"
  exit 1
}

# --- the cluster
test_cluster_start "$work/cluster" || exit $?
started=("${test_cluster_pids[@]}")

# --- three short drives (graph fusion at the simulator's origin) and one that does not exist
geo="--set fusion.origin=48.98253,8.39035,116.4 --set fusion.lever_arm_b=[0,0,0.8]"
for seed in 1 2 3; do
  "$gvio" -q simulate --trajectory "$src/assets/demo/drive.tum" --seconds 10 --seed "$seed" \
    --out "$work/drive$seed" >/dev/null
done
{
  echo "# the fleet of the Slurm test"
  for seed in 1 2 3; do echo "drive$seed $geo"; done
  echo "missing_drive"
} >"$work/drives.txt"

set +e
"$gvio" fleet --drives "$work/drives.txt" --out "$work/fleet" --engine slurm --jobs 2 \
  --set fleet.slurm.cpus_per_task=1 --set fleet.slurm.mem_mb=2000 --set fleet.slurm.time_limit_min=10 \
  2>"$work/fleet.err"
rc=$?
set -e
cat "$work/fleet.err"
[ "$rc" -eq 2 ] || fail "gvio fleet exited $rc, expected 2 (one drive is missing)"
grep -q "missing_drive ($work/drives.txt:5) failed: .*missing_drive: dataset not found" \
  "$work/fleet.err" || fail "no one-line error for the missing drive"
grep -q '"complete": 3' "$work/fleet/fleet.json" || fail "fleet.json: not 3 drives complete"
grep -q '"failed": 1' "$work/fleet/fleet.json" || fail "fleet.json: not 1 drive failed"
grep -q '"slurm_jobs"' "$work/fleet/fleet.json" || fail "fleet.json: no Slurm job id"
for seed in 1 2 3; do
  grep -q '"status": "complete"' "$work/fleet/runs/drive$seed/report.json" ||
    fail "drive$seed: run folder not complete"
  [ -f "$work/fleet/tasks/drive$seed.json" ] || fail "drive$seed: no task record"
done
ls "$work"/fleet/slurm/attempt1_task*.out >/dev/null || fail "no Slurm task output"

# --- the fleet's runs merged into tiles
"$gvio" merge --runs "$work/fleet" --out "$work/map" --tile-size 50 || fail "gvio merge failed"
las=$(ls "$work"/map/tiles/*.las | wc -l)
pcd=$(ls "$work"/map/tiles/*.pcd | wc -l)
bt=$(ls "$work"/map/tiles/*.bt | wc -l)
[ "$las" -ge 2 ] && [ "$las" -eq "$pcd" ] && [ "$las" -eq "$bt" ] ||
  fail "tiles: $las LAS, $pcd PCD, $bt OctoMap files"
for id in 1 2 3; do
  grep -q "\"point_source_id\": $id" "$work/map/tiles.json" || fail "tiles.json: no drive $id"
done
grep -q '"epsg": 32632' "$work/map/tiles.json" || fail "tiles.json: not UTM zone 32N"
grep -q "x_resolution: 50" "$work/map/pointcloud_map_metadata.yaml" || fail "no Autoware index"

# --- a controller that is gone: one line, exit 2
kill "$test_cluster_ctld"
for _ in $(seq 50); do kill -0 "$test_cluster_ctld" 2>/dev/null || break; sleep 0.1; done
echo "missing_drive" >"$work/one.txt"
set +e
"$gvio" fleet --drives "$work/one.txt" --out "$work/fleet2" --engine slurm 2>"$work/fleet2.err"
rc=$?
set -e
cat "$work/fleet2.err"
[ "$rc" -eq 2 ] || fail "without a controller gvio fleet exited $rc, expected 2"
grep -q "slurm engine: the job was not submitted: .*Unable to contact slurm controller" \
  "$work/fleet2.err" || fail "no one-line error for the unreachable controller"

test_cluster_stop
for pid in "${started[@]}"; do ! kill -0 "$pid" 2>/dev/null || fail "daemon $pid still running"; done
echo "PASS: Slurm fleet of 3 drives (+1 missing), merged into $las tiles"
