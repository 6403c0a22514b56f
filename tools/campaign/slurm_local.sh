#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, all of its state in one scratch folder, for
# testing `convoy campaign --backend slurm` (docs/campaigns.md, "A one-node cluster").
#
#   tools/campaign/slurm_local.sh start SCRATCH_DIR   munged, slurmctld, slurmd; waits until
#                                                     sinfo shows the node idle
#   tools/campaign/slurm_local.sh stop SCRATCH_DIR    stops them by their pid files
#
# Then `export SLURM_CONF=SCRATCH_DIR/slurm.conf` (or `. SCRATCH_DIR/env.sh`) and sbatch,
# squeue, scontrol, sinfo talk to this cluster. Nothing outside SCRATCH_DIR is written: the
# config is SCRATCH_DIR/slurm.conf (never /etc/slurm/slurm.conf), munged gets its own socket
# there, and the controller and node daemon take two free TCP ports, so that several such
# clusters (and a system one) can run side by side. Both commands are re-runnable: start on a
# running cluster checks that it is up; stop on a stopped one does nothing.
#
# Runs as root (the daemons run as root; munged as the munge user, with /etc/munge/munge.key).
# Needs the Debian packages slurm-wlm slurmctld slurmd slurm-client munge (scripts/setup.sh).
set -euo pipefail

usage() { echo "usage: $0 start|stop SCRATCH_DIR" >&2; exit 2; }
[[ $# -eq 2 ]] || usage
cmd=$1
S=$(realpath -m "$2")
START_TIMEOUT_S=${SLURM_LOCAL_TIMEOUT:-60}

die() { echo "slurm_local: $*" >&2; exit 1; }

alive() {  # alive PIDFILE: the process named in it runs
  [[ -s $1 ]] && kill -0 "$(cat "$1")" 2>/dev/null
}

stop_one() {  # stop_one NAME PIDFILE
  local pidfile=$2 pid i
  alive "$pidfile" || { rm -f "$pidfile"; return 0; }
  pid=$(cat "$pidfile")
  kill "$pid" 2>/dev/null || true
  for i in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  if kill -0 "$pid" 2>/dev/null; then
    echo "slurm_local: $1 ($pid) did not stop in 10 s, killing it" >&2
    kill -9 "$pid" 2>/dev/null || true
  fi
  rm -f "$pidfile"
}

free_port() {
  /usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

wait_idle() {
  local deadline=$((SECONDS + START_TIMEOUT_S)) state=""
  while ((SECONDS < deadline)); do
    state=$(SLURM_CONF=$S/slurm.conf sinfo -h -N -o '%T' 2>/dev/null | head -1 || true)
    [[ $state == idle ]] && return 0
    sleep 0.5
  done
  die "the node is not idle after ${START_TIMEOUT_S} s (sinfo says '${state:-nothing}'); logs in $S/log"
}

start() {
  for tool in munged slurmctld slurmd sinfo; do
    command -v "$tool" >/dev/null || [[ -x /usr/sbin/$tool ]] ||
      die "$tool is not installed (apt-get install slurm-wlm slurmctld slurmd slurm-client munge)"
  done
  [[ -r /etc/munge/munge.key ]] || die "no /etc/munge/munge.key (the munge package makes one)"
  if alive "$S/slurmctld.pid" && alive "$S/slurmd.pid" && alive "$S/munge/munged.pid"; then
    wait_idle
    echo "slurm_local: already running ($S/slurm.conf)"
    return 0
  fi
  stop  # whatever half of it runs
  mkdir -p "$S"/{state,spool,log,munge}
  # munged runs as the munge user: it must reach its socket folder.
  chmod a+x "$S"
  chown munge:munge "$S/munge"
  chmod 711 "$S/munge"
  su -s /bin/sh munge -c "/usr/sbin/munged --socket=$S/munge/munge.socket \
      --pid-file=$S/munge/munged.pid --log-file=$S/munge/munged.log \
      --seed-file=$S/munge/munged.seed" || die "munged did not start (see $S/munge/munged.log)"

  local host ctld_port slurmd_port
  host=$(hostname -s)
  ctld_port=$(free_port)
  slurmd_port=$(free_port)
  while [[ $slurmd_port == "$ctld_port" ]]; do slurmd_port=$(free_port); done
  cat >"$S/slurm.conf" <<EOF
# Written by tools/campaign/slurm_local.sh: a one-node cluster in $S
ClusterName=convoy
SlurmctldHost=$host
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$S/munge/munge.socket
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$S/state
SlurmdSpoolDir=$S/spool
SlurmctldPidFile=$S/slurmctld.pid
SlurmdPidFile=$S/slurmd.pid
SlurmctldLogFile=$S/log/slurmctld.log
SlurmdLogFile=$S/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=$host CPUs=$(nproc) RealMemory=1000 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  echo "export SLURM_CONF=$S/slurm.conf" >"$S/env.sh"
  SLURM_CONF=$S/slurm.conf /usr/sbin/slurmctld -i || die "slurmctld did not start (see $S/log/slurmctld.log)"
  SLURM_CONF=$S/slurm.conf /usr/sbin/slurmd || die "slurmd did not start (see $S/log/slurmd.log)"
  wait_idle
  echo "slurm_local: node $host idle; export SLURM_CONF=$S/slurm.conf"
}

stop() {
  stop_one slurmd "$S/slurmd.pid"
  stop_one slurmctld "$S/slurmctld.pid"
  stop_one munged "$S/munge/munged.pid"
}

case $cmd in
  start) start ;;
  stop) stop; echo "slurm_local: stopped ($S)" ;;
  *) usage ;;
esac
