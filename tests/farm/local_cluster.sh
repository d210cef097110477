#!/usr/bin/env bash
# A one-node Slurm cluster in a temporary folder, for tests and for trying scripts/farm.sh
# (docs/FARM.md). Source it, then:
#   start_cluster DIR    # munged, slurmctld and slurmd of this machine, their files under DIR;
#                        # exports SLURM_CONF; records the daemons' PIDs in CLUSTER_PIDS
#   stop_cluster         # stops exactly those PIDs
# Runs as root (SlurmUser=root, as the issue's recipe measured). Its own munged socket and
# free ports, so it does not touch a system munged or another cluster on the machine.
# Accounting: no slurmdbd; AccountingStorageType=accounting_storage/none (progress comes from
# squeue and scontrol's job records, kept MinJobAge seconds) and JobCompType=jobcomp/filetxt
# (one line per finished job in DIR/jobcomp.txt).
# For scheduling experiments (docs/FARM.md, "Scheduling latency"): CLUSTER_SCHEDULER_TYPE and
# CLUSTER_SCHEDULER_PARAMETERS replace SchedulerType/SchedulerParameters, CLUSTER_EXTRA_CONF adds
# slurm.conf lines.

CLUSTER_PIDS=()

cluster_free_port() {
  local p
  for p in $(seq "$1" "$(($1 + 200))"); do
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; then echo "$p"; return; fi
  done
  echo "$1"
}

start_cluster() {
  local dir="$1" host cpus mem_mb ctl_port d_port i
  mkdir -p "$dir"/{state,spool,log,munge}
  host=$(hostname -s)
  cpus=$(nproc)
  mem_mb=$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
  ctl_port=$(cluster_free_port $((20000 + $$ % 5000 * 2)))
  d_port=$(cluster_free_port $((ctl_port + 1)))

  # munge: the key the package made at install, a private socket.
  cp /etc/munge/munge.key "$dir/munge/munge.key"
  chmod 600 "$dir/munge/munge.key"
  chmod 700 "$dir/munge"
  munged --foreground --force --socket="$dir/munge/munge.socket" \
    --key-file="$dir/munge/munge.key" --pid-file="$dir/munge/munged.pid" \
    --log-file="$dir/log/munged.log" --seed-file="$dir/munge/munged.seed" \
    >"$dir/log/munged.out" 2>&1 &
  CLUSTER_PIDS+=($!)
  for i in $(seq 50); do [[ -S "$dir/munge/munge.socket" ]] && break; sleep 0.1; done

  cat >"$dir/slurm.conf" <<EOF
ClusterName=vtbake-local
SlurmctldHost=$host
SlurmctldPort=$ctl_port
SlurmdPort=$d_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=${CLUSTER_SCHEDULER_TYPE:-sched/backfill}
SchedulerParameters=${CLUSTER_SCHEDULER_PARAMETERS:-bf_interval=1,sched_interval=1}
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$dir/jobcomp.txt
MpiDefault=none
ReturnToService=2
MinJobAge=600
MessageTimeout=20
${CLUSTER_EXTRA_CONF:-}
NodeName=$host CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  export SLURM_CONF="$dir/slurm.conf"
  slurmctld -D -f "$SLURM_CONF" >"$dir/log/slurmctld.out" 2>&1 &
  CLUSTER_PIDS+=($!)
  slurmd -D -f "$SLURM_CONF" >"$dir/log/slurmd.out" 2>&1 &
  CLUSTER_PIDS+=($!)
  for i in $(seq 100); do
    if sinfo -h -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then return 0; fi
    sleep 0.2
  done
  echo "local_cluster: the node did not come up (logs in $dir/log)" >&2
  sinfo 2>&1 | tail -3 >&2
  tail -5 "$dir/log/slurmctld.log" "$dir/log/slurmd.log" >&2 2>/dev/null
  return 1
}

stop_cluster() {
  local pid i
  # Daemons in reverse order of start: slurmd, slurmctld, munged.
  for ((i = ${#CLUSTER_PIDS[@]} - 1; i >= 0; --i)); do
    pid=${CLUSTER_PIDS[i]}
    kill -TERM "$pid" 2>/dev/null || continue
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
  done
  CLUSTER_PIDS=()
}
