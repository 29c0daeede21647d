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
for tool in sbatch scancel sinfo slurmctld slurmd munged; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIP: $tool not found (Debian's slurm-wlm and munge; ./setup.sh test installs them)"
    exit 77
  fi
done
if [ "$(id -u)" -ne 0 ]; then
  echo "SKIP: the test cluster's slurmd must run as root"
  exit 77
fi

work=$(mktemp -d /tmp/gvio_slurm_XXXXXX)
pids=()
stop_daemons() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
  done
  pids=()
}
cleanup() {
  stop_daemons
  rm -rf "$work"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  for log in "$work"/cluster/log/*; do echo "--- $log"; tail -5 "$log"; done
  exit 1
}

# --- the cluster
c=$work/cluster
mkdir -p "$c/munge" "$c/state" "$c/spool" "$c/log"
chmod 700 "$c/munge"
head -c 1024 /dev/urandom >"$c/munge/munge.key"
chmod 600 "$c/munge/munge.key"
munged --foreground --force --key-file="$c/munge/munge.key" --socket="$c/munge/munge.sock" \
  --pid-file="$c/munge/munged.pid" --log-file="$c/log/munged.log" --seed-file="$c/munge/seed" \
  >>"$c/log/munged.out" 2>&1 &
pids+=($!)
host=$(hostname -s)  # both daemons on the loopback: no DNS needed for the node's name
port=$((20000 + RANDOM % 30000))
memory_mb=$(($(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo) - 512))
cat >"$c/slurm.conf" <<CONF
ClusterName=gviotest
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$c/munge/munge.sock
CredType=cred/munge
StateSaveLocation=$c/state
SlurmdSpoolDir=$c/spool
SlurmctldPidFile=$c/slurmctld.pid
SlurmdPidFile=$c/slurmd.pid
SlurmctldLogFile=$c/log/slurmctld.log
SlurmdLogFile=$c/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SwitchType=switch/none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=$memory_mb State=UNKNOWN
PartitionName=gvio Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
echo "CgroupPlugin=cgroup/v1" >"$c/cgroup.conf"
export SLURM_CONF=$c/slurm.conf
sleep 1
slurmctld -D -f "$SLURM_CONF" >>"$c/log/slurmctld.out" 2>&1 &
ctld=$!
pids+=("$ctld")
slurmd -D -f "$SLURM_CONF" >>"$c/log/slurmd.out" 2>&1 &
pids+=($!)
for _ in $(seq 60); do
  [ "$(sinfo -h -o %T 2>/dev/null)" = idle ] && break
  sleep 0.5
done
[ "$(sinfo -h -o %T 2>/dev/null)" = idle ] || fail "the test cluster did not come up"
started=("${pids[@]}")
echo "cluster up: $host, port $port"

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
kill "$ctld"
for _ in $(seq 50); do kill -0 "$ctld" 2>/dev/null || break; sleep 0.1; done
echo "missing_drive" >"$work/one.txt"
set +e
"$gvio" fleet --drives "$work/one.txt" --out "$work/fleet2" --engine slurm 2>"$work/fleet2.err"
rc=$?
set -e
cat "$work/fleet2.err"
[ "$rc" -eq 2 ] || fail "without a controller gvio fleet exited $rc, expected 2"
grep -q "slurm engine: the job was not submitted: .*Unable to contact slurm controller" \
  "$work/fleet2.err" || fail "no one-line error for the unreachable controller"

stop_daemons
for pid in "${started[@]}"; do ! kill -0 "$pid" 2>/dev/null || fail "daemon $pid still running"; done
echo "PASS: Slurm fleet of 3 drives (+1 missing), merged into $las tiles"
