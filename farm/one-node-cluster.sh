#!/usr/bin/env bash
# Starts (or stops) a one-node Slurm cluster on this machine, without systemd, for testing
# the farm scripts: munged, slurmctld and slurmd, all state under one folder. Needs root
# (slurmd runs jobs as their users) and Debian's slurm-wlm and munge.
#
#   eval "$(farm/one-node-cluster.sh start DIR)"   # prints `export SLURM_CONF=...`
#   farm/one-node-cluster.sh stop DIR
set -euo pipefail

action=${1:-} dir=${2:-}
if [ -z "$action" ] || [ -z "$dir" ]; then
    echo "usage: $0 start|stop DIR" >&2
    exit 2
fi
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
conf=$dir/slurm.conf

stop() {
    for pidfile in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munged.pid"; do
        if [ -s "$pidfile" ]; then kill "$(cat "$pidfile")" 2> /dev/null || true; fi
    done
}

if [ "$action" = stop ]; then
    stop
    exit 0
fi
[ "$action" = start ] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }
for p in munged slurmctld slurmd; do
    command -v $p > /dev/null || [ -x /usr/sbin/$p ] || { echo "error: $p not found (Debian: slurm-wlm, munge)" >&2; exit 2; }
done
export PATH=$PATH:/usr/sbin

host=$(hostname -s)
cpus=$(nproc)
# Ports chosen from the folder's name, so that two clusters on one machine do not meet.
base=$((20000 + $(printf '%s' "$dir" | cksum | cut -d' ' -f1) % 20000))
mkdir -p "$dir/state" "$dir/spool" "$dir/munge"
if [ ! -s "$dir/munge/munge.key" ]; then
    dd if=/dev/urandom of="$dir/munge/munge.key" bs=1 count=1024 status=none
fi
chmod 700 "$dir/munge"
chmod 600 "$dir/munge/munge.key"
socket=$dir/munge/munge.socket
cat > "$conf" <<CONF
ClusterName=plenum
SlurmctldHost=$host
SlurmUser=root
SlurmctldPort=$base
SlurmdPort=$((base + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SlurmdTimeout=30
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF

munged --force --key-file="$dir/munge/munge.key" --socket="$socket" \
    --pid-file="$dir/munged.pid" --log-file="$dir/munged.log" --seed-file="$dir/munge/seed"
export SLURM_CONF=$conf
slurmctld -f "$conf"
slurmd -f "$conf"
# Ready when the node takes jobs.
for _ in $(seq 1 60); do
    state=$(sinfo -h -N -o %T 2> /dev/null || true)
    case $state in idle*|mixed*|allocated*) break ;; esac
    sleep 0.5
done
case $state in
    idle*|mixed*|allocated*) ;;
    *)
        echo "error: the node did not come up (state '$state'); logs in $dir" >&2
        stop
        exit 1
        ;;
esac
echo "export SLURM_CONF=$(printf '%q' "$conf")"
