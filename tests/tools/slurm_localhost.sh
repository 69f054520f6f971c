#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for the batch test (tests/tools/cli_batch_slurm_test.cc):
#   slurm_localhost.sh start DIR   munged, slurmctld and slurmd with every file under DIR; prints
#                                  `export SLURM_CONF=DIR/slurm.conf` on success
#   slurm_localhost.sh stop DIR    stops the three daemons this script started (by their pid files)
# Needs Debian's slurm-wlm and munge (apt-get install slurm-wlm munge) and root (slurmd starts the
# jobs as their user). Exit 77 (a skip for ctest) when they are absent or the cluster does not come
# up, with the reason on stderr and the daemons' logs left in DIR.
set -u
cmd="${1:-}"; dir="${2:-}"
[ -n "$cmd" ] && [ -n "$dir" ] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }
skip() { echo "SKIP: $*" >&2; exit 77; }

if [ "$cmd" = stop ]; then
  for p in slurmd slurmctld munged; do
    [ -f "$dir/$p.pid" ] && kill "$(cat "$dir/$p.pid")" 2>/dev/null
  done
  exit 0
fi

for tool in munged mungekey slurmctld slurmd sbatch squeue sinfo; do
  command -v "$tool" >/dev/null || skip "$tool not installed (apt-get install slurm-wlm munge)"
done
[ "$(id -u)" -eq 0 ] || skip "slurmd must run as root here"
mkdir -p "$dir/state" "$dir/spool" && chmod 700 "$dir"
mungekey --create --keyfile="$dir/munge.key" --force 2>/dev/null || skip "mungekey failed"
chmod 600 "$dir/munge.key"
munged --force --socket="$dir/munge.sock" --key-file="$dir/munge.key" --pid-file="$dir/munged.pid" \
  --log-file="$dir/munged.log" --seed-file="$dir/munged.seed" || skip "munged did not start ($dir/munged.log)"

node=$(hostname -s)
memory_mb=$(awk '/MemTotal/ {print int($2 / 1024 / 2)}' /proc/meminfo)
cpus=$(nproc)
# Free TCP ports for the two daemons (another Slurm on this machine keeps its own).
port=$(( 20000 + (RANDOM % 20000) ))
cat > "$dir/slurm.conf" <<CONF
ClusterName=aerocal
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge.sock
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
SlurmdTimeout=60
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory_mb State=UNKNOWN
PartitionName=batch Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$dir/slurm.conf"
slurmctld -i || skip "slurmctld did not start ($dir/slurmctld.log)"
slurmd || skip "slurmd did not start ($dir/slurmd.log)"
for _ in $(seq 60); do
  state=$(sinfo -h -N -o %t 2>/dev/null | head -n 1)
  case "$state" in idle*|mix*|alloc*) echo "export SLURM_CONF=$dir/slurm.conf"; exit 0 ;; esac
  sleep 1
done
skip "the node did not become idle within 60 s (state '${state:-none}'; logs in $dir)"
