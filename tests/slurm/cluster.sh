#!/usr/bin/env bash
# A one-node Slurm cluster on loopback for the scale-out test (docs/scale-out.md):
# munge with its own key, slurmctld and slurmd as root, state in a scratch folder.
#   source tests/slurm/cluster.sh; cluster_start DIR; ...; cluster_stop
# Needs Debian's slurm-wlm and munge (apt-get install slurm-wlm munge).

cluster_start() {
  local dir="$1"
  mkdir -p "$dir"/{state,spool,munge,log}
  CLUSTER_DIR="$dir"
  local host cpus mem
  host="$(hostname -s)"
  cpus="$(nproc)"
  mem="$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)"
  # munge: a fresh key and socket of our own, so a munged already running is left alone.
  dd if=/dev/urandom bs=1 count=1024 of="$dir/munge/munge.key" status=none
  chmod 400 "$dir/munge/munge.key"
  chmod 700 "$dir/munge"
  MUNGE_SOCKET="$dir/munge/munge.socket"
  munged --key-file="$dir/munge/munge.key" --socket="$MUNGE_SOCKET" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/log/munged.log" \
    --seed-file="$dir/munge/seed" --force
  cat > "$dir/slurm.conf" <<CONF
ClusterName=photomontage-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$MUNGE_SOCKET
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MaxArraySize=10001
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
MinJobAge=300
KillWait=5
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$dir/slurm.conf"
  slurmctld -i
  slurmd
  local i
  for i in $(seq 1 60); do
    if sinfo -h -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then
      return 0
    fi
    sleep 1
  done
  echo "slurm did not come up; logs in $dir/log" >&2
  tail -20 "$dir/log/slurmctld.log" "$dir/log/slurmd.log" >&2 || true
  return 1
}

cluster_stop() {
  [ -n "${CLUSTER_DIR:-}" ] || return 0
  local f
  for f in slurmd.pid slurmctld.pid munge/munged.pid; do
    if [ -f "$CLUSTER_DIR/$f" ]; then
      kill "$(cat "$CLUSTER_DIR/$f")" 2>/dev/null || true
    fi
  done
  sleep 1
}
