#!/usr/bin/env bash
# A one-node SLURM cluster on this machine, for `drumflow sweep` tests and trials.
#
# Writes /etc/slurm/slurm.conf for one node named after `hostname -s` (its CPUs and memory
# from `slurmd -C`), then starts munged, slurmctld and slurmd and waits until `sinfo` shows
# the node idle. Idempotent: a second call finds the daemons running and only waits.
# It never overwrites a slurm.conf it did not write (a real cluster's). Needs root (or sudo)
# and the Debian packages slurmctld slurmd munge slurm-client (scripts/install.sh).
#
# Choices for a container without systemd or cgroups (Debian 12, SLURM 22.05):
#   ProctrackType=proctrack/linuxproc   processes found through the parent-pid tree, no cgroups
#   TaskPlugin=task/none                no CPU binding (cgroups/affinity not available)
#   AccountingStorageType=none          no slurmdbd: `sacct` does not work; drumflow falls
#                                       back to `scontrol show job` (kept MinJobAge = 1 h)
#   JobCompType=jobcomp/filetxt         one line per finished job in /var/log/slurm/jobcomp.log
#   SlurmUser=root                      the daemons run as root here (CI containers)
#   KillWait=5                          scancel's SIGTERM -> SIGKILL grace, s (default 30)
#
# Usage: scripts/slurm_localhost.sh [--stop]
set -euo pipefail

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
CONF=/etc/slurm/slurm.conf
MARK="# written by drumflow scripts/slurm_localhost.sh"
node="$(hostname -s)"

stop() {
  # Only the daemons this script starts, by their pid files.
  for pidfile in /run/slurmd.pid /run/slurmctld.pid /run/munge/munged.pid; do
    if [ -f "$pidfile" ]; then $SUDO kill "$(cat "$pidfile")" 2>/dev/null || true; fi
  done
}

if [ "${1:-}" = "--stop" ]; then stop; exit 0; fi

for exe in slurmctld slurmd munged sinfo sbatch; do
  if ! command -v "$exe" >/dev/null && [ ! -x "/usr/sbin/$exe" ]; then
    echo "slurm_localhost: $exe not installed; run scripts/install.sh" >&2
    exit 3
  fi
done

if [ -f "$CONF" ] && ! grep -qF "$MARK" "$CONF"; then
  echo "slurm_localhost: $CONF exists and was not written by this script; not touching it" >&2
  exit 4
fi

# The node line as slurmd sees the hardware (CPUs, sockets, cores, threads, memory).
hw="$(/usr/sbin/slurmd -C | head -n 1)"
want="$(cat <<EOF
$MARK
ClusterName=drumflow-local
SlurmctldHost=$node
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=/var/log/slurm/jobcomp.log
MinJobAge=3600
KillWait=5
ReturnToService=2
MpiDefault=none
$hw State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
)"
restart=0
if [ ! -f "$CONF" ] || [ "$(cat "$CONF")" != "$want" ]; then
  $SUDO mkdir -p /etc/slurm
  echo "$want" | $SUDO tee "$CONF" >/dev/null
  restart=1
fi
$SUDO mkdir -p /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
$SUDO mkdir -p /run/munge && $SUDO chown munge:munge /run/munge && $SUDO chmod 0755 /run/munge

running() { [ -f "$1" ] && $SUDO kill -0 "$(cat "$1")" 2>/dev/null; }

if ! running /run/munge/munged.pid; then
  $SUDO runuser -u munge -- /usr/sbin/munged
fi
if [ "$restart" = 1 ]; then
  # A changed configuration: restart the SLURM daemons so they read it.
  for pidfile in /run/slurmd.pid /run/slurmctld.pid; do
    if running "$pidfile"; then $SUDO kill "$(cat "$pidfile")"; sleep 1; fi
  done
fi
if ! running /run/slurmctld.pid; then $SUDO /usr/sbin/slurmctld; fi
if ! running /run/slurmd.pid; then $SUDO /usr/sbin/slurmd; fi

# Wait for the node to register and become idle (or mixed/allocated: busy with jobs).
for _ in $(seq 1 60); do
  state="$(sinfo -h -n "$node" -o %T 2>/dev/null | head -n 1 || true)"
  case "$state" in
    idle|mixed|allocated|completing) echo "slurm_localhost: node $node $state"; exit 0 ;;
    down*|drain*|"not_responding"*)
      $SUDO scontrol update nodename="$node" state=resume 2>/dev/null || true ;;
  esac
  sleep 1
done
echo "slurm_localhost: node $node did not become idle (state '${state:-none}'); see /var/log/slurm/" >&2
exit 5
