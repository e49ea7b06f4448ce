#!/usr/bin/env bash
# A single-node Slurm cluster on this machine, without systemd, for testing
# `airlight submit slurm`: `tools/slurm-local.sh start` (as root) writes a
# munge key and a slurm.conf under /var/lib/airlight-slurm, starts munged,
# slurmctld and slurmd, and waits until the node is idle; `stop` ends them.
# Debian's packages (slurmctld slurmd slurm-client munge) ship no slurm.conf
# and their services do not start by themselves in a container.
set -euo pipefail

dir=/var/lib/airlight-slurm
conf=/etc/slurm/slurm.conf

start() {
  if [ "$(id -u)" -ne 0 ]; then
    echo "slurm-local.sh start: must run as root" >&2
    exit 1
  fi
  if scontrol ping 2>/dev/null | grep -q UP; then
    echo "slurm is already up"
    return
  fi
  mkdir -p "$dir"/{state,spool,log} /etc/munge /run/munge /var/log/munge /var/lib/munge
  if [ ! -s /etc/munge/munge.key ]; then
    head -c 1024 /dev/urandom > /etc/munge/munge.key
  fi
  chown -R munge:munge /etc/munge /run/munge /var/log/munge /var/lib/munge
  chmod 400 /etc/munge/munge.key
  if ! pgrep -x munged >/dev/null; then
    runuser -u munge -- /usr/sbin/munged
    touch "$dir/munged-started-here"
  fi
  chown -R slurm:slurm "$dir"
  local node cpus memory
  node=$(hostname -s)
  cpus=$(slurmd -C | sed -n 's/.*CPUs=\([0-9]*\).*/\1/p' | head -1)
  memory=$(slurmd -C | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' | head -1)
  mkdir -p /etc/slurm
  cat > "$conf" <<EOF
# Written by airlight's tools/slurm-local.sh: one node, for tests.
ClusterName=airlight-test
SlurmctldHost=$node
SlurmUser=slurm
AuthType=auth/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MinJobAge=300
NodeName=$node CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
  slurmctld
  slurmd
  for _ in $(seq 1 60); do
    if sinfo -h -o '%T' 2>/dev/null | grep -qE '^idle'; then
      echo "slurm is up: node $node, $cpus CPUs"
      return
    fi
    sleep 0.5
  done
  echo "slurm did not come up; logs in $dir/log" >&2
  exit 1
}

stop() {
  pkill -x slurmd 2>/dev/null || true
  pkill -x slurmctld 2>/dev/null || true
  if [ -e "$dir/munged-started-here" ]; then
    pkill -x munged 2>/dev/null || true
    rm -f "$dir/munged-started-here"
  fi
  for _ in $(seq 1 20); do
    pgrep -x slurmctld >/dev/null || pgrep -x slurmd >/dev/null || break
    sleep 0.25
  done
  echo "slurm stopped"
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  *) echo "usage: $0 start|stop" >&2; exit 2 ;;
esac
