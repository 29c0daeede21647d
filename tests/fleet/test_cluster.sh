# A single-node Slurm cluster of its own for the tests (sourced, not run): munged, slurmctld and
# slurmd as root on the loopback address, with a generated slurm.conf (proctrack/linuxproc,
# task/none, cgroup/v1: what these containers allow) and SLURM_CONF exported, so that sbatch,
# sinfo and scancel reach it and never a cluster of the machine's own.
#
#   . tests/fleet/test_cluster.sh
#   test_cluster_start DIR || exit $?   # 77 (skip) without Slurm, munge or root; 1 if it failed
#   ...                                 # test_cluster_ctld: the controller's pid
#   test_cluster_stop                   # every daemon it started, by its pid

test_cluster_pids=()
test_cluster_ctld=

test_cluster_stop() {
  local pid
  for pid in "${test_cluster_pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${test_cluster_pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
  done
  test_cluster_pids=()
}

# The last lines of each daemon's log, for a test's failure message.
test_cluster_logs() {
  local log
  for log in "$1"/log/*; do echo "--- $log"; tail -5 "$log"; done
}

test_cluster_start() {
  local c=$1 tool
  for tool in sbatch scancel sinfo slurmctld slurmd munged; do
    if ! command -v "$tool" >/dev/null; then
      echo "SKIP: $tool not found (Debian's slurm-wlm and munge; ./setup.sh test installs them)"
      return 77
    fi
  done
  if [ "$(id -u)" -ne 0 ]; then
    echo "SKIP: the test cluster's slurmd must run as root"
    return 77
  fi
  mkdir -p "$c/munge" "$c/state" "$c/spool" "$c/log"
  chmod 700 "$c/munge"
  head -c 1024 /dev/urandom >"$c/munge/munge.key"
  chmod 600 "$c/munge/munge.key"
  munged --foreground --force --key-file="$c/munge/munge.key" --socket="$c/munge/munge.sock" \
    --pid-file="$c/munge/munged.pid" --log-file="$c/log/munged.log" --seed-file="$c/munge/seed" \
    >>"$c/log/munged.out" 2>&1 &
  test_cluster_pids+=($!)
  local host port memory_mb
  host=$(hostname -s) # both daemons on the loopback: no DNS needed for the node's name
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
  test_cluster_ctld=$!
  test_cluster_pids+=("$test_cluster_ctld")
  slurmd -D -f "$SLURM_CONF" >>"$c/log/slurmd.out" 2>&1 &
  test_cluster_pids+=($!)
  for _ in $(seq 60); do
    [ "$(sinfo -h -o %T 2>/dev/null)" = idle ] && break
    sleep 0.5
  done
  if [ "$(sinfo -h -o %T 2>/dev/null)" != idle ]; then
    echo "the test cluster did not come up"
    test_cluster_logs "$c"
    return 1
  fi
  echo "test cluster up: $host, port $port"
}
