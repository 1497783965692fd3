#!/usr/bin/env bash
# A single-node Slurm on this machine, from Debian's slurm-wlm and munge (scripts/install_deps.sh
# installs them): munged, slurmctld and slurmd on localhost, every file in one temp folder, no
# systemd, no cgroups (facts: ../shared/docs/slurm_single_node.md). Needs root.
#   scripts/slurm-local.sh up [DIR]    start; prints `export SLURM_CONF=DIR/slurm.conf`
#   scripts/slurm-local.sh down [DIR]  stop (reverse order) by the pid files
# DIR defaults to ${CSLAM_SLURM_DIR:-/tmp/cslam-slurm}. Ports 16817/16818, away from a system Slurm's.
set -euo pipefail
cmd=${1:-}
DIR=${2:-${CSLAM_SLURM_DIR:-/tmp/cslam-slurm}}

stop_pid() {  # stop the process named in pid file $1, if it runs
  local f=$1
  [ -f "$f" ] || return 0
  local pid; pid=$(cat "$f")
  if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
    kill "$pid"
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  fi
  rm -f "$f"
}

case "$cmd" in
  up)
    for p in munged slurmctld slurmd sbatch; do
      command -v "$p" >/dev/null || { echo "slurm-local: $p not found; run scripts/install_deps.sh (slurm-wlm, munge)" >&2; exit 1; }
    done
    mkdir -p "$DIR"/{munge,state,spool,log}
    chmod 0700 "$DIR/munge"
    [ -f "$DIR/munge/munge.key" ] || { head -c 1024 /dev/urandom > "$DIR/munge/munge.key"; chmod 0400 "$DIR/munge/munge.key"; }
    host=$(hostname -s)
    cpus=$(nproc)
    mem=$(( $(free -m | awk '/^Mem:/{print $2}') * 9 / 10 ))
    cat > "$DIR/slurm.conf" <<CONF
ClusterName=cslamlocal
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
AuthInfo=socket=$DIR/munge/munge.socket
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/slurmctld.pid
SlurmdPidFile=$DIR/slurmd.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.log
ReturnToService=2
MpiDefault=none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
    munged --key-file="$DIR/munge/munge.key" --socket="$DIR/munge/munge.socket" \
      --pid-file="$DIR/munge/munged.pid" --log-file="$DIR/log/munged.log" \
      --seed-file="$DIR/munge/munged.seed" --force
    export SLURM_CONF="$DIR/slurm.conf"
    slurmctld -f "$SLURM_CONF"
    slurmd -f "$SLURM_CONF"
    for _ in $(seq 100); do
      sinfo -h -o %t 2>/dev/null | grep -q idle && { echo "export SLURM_CONF=$SLURM_CONF"; exit 0; }
      sleep 0.2
    done
    echo "slurm-local: the node did not come up idle; logs in $DIR/log" >&2
    sinfo >&2 || true
    exit 1
    ;;
  down)
    stop_pid "$DIR/slurmd.pid"
    stop_pid "$DIR/slurmctld.pid"
    stop_pid "$DIR/munge/munged.pid"
    ;;
  *)
    echo "usage: $0 up|down [DIR]" >&2
    exit 2
    ;;
esac
