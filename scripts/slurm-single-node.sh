#!/usr/bin/env bash
# A real single-node Slurm on this machine, for the tests (tests/pipeline_slurm.rs) and
# for trying `weft run --executor slurm` without a cluster.
#
#   scripts/slurm-single-node.sh install   apt-get the Debian packages (needs root)
#   scripts/slurm-single-node.sh start     write the config, start munged, slurmctld, slurmd
#   scripts/slurm-single-node.sh status    the daemons' PIDs and `sinfo`
#   scripts/slurm-single-node.sh stop      stop the daemons this script started (by PID)
#
# Measured on Debian 12 (Slurm 22.05.8, packages slurmctld slurmd slurm-client munge), as
# root, without systemd. What the config needs and why:
#   SelectType=select/cons_tres + SelectTypeParameters=CR_Core_Memory + DefMemPerCPU:
#       without them a job takes the whole node and jobs run one at a time;
#   ProctrackType=proctrack/linuxproc + TaskPlugin=task/none: no cgroups needed;
#   CPUs and RealMemory: from `slurmd -C`;
#   MaxArraySize: array task ids must stay below it (weft splits larger sweeps);
#   SchedulerParameters=batch_sched_delay=0: dependants start ~1 s after their
#       dependency instead of ~3 s (measured).
# The config goes to /etc/slurm/slurm.conf, where sbatch, squeue and scancel look; a
# config this script did not write is never overwritten. State, logs and PID files live
# in $WEFT_SLURM_STATE (default /var/tmp/weft-slurm).
set -euo pipefail

state="${WEFT_SLURM_STATE:-/var/tmp/weft-slurm}"
conf=/etc/slurm/slurm.conf
marker="# written by weft scripts/slurm-single-node.sh"
SUDO=$([ "$(id -u)" = 0 ] || echo sudo)

die() { echo "slurm-single-node: $*" >&2; exit 1; }

pid_alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

install_pkgs() {
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq slurmctld slurmd slurm-client munge
}

write_conf() {
    if [ -f "$conf" ] && ! grep -qF "$marker" "$conf"; then
        die "$conf exists and was not written by this script; not touching a real cluster's config
  hint: move it aside, or use that cluster directly"
    fi
    local host node name
    host="$(hostname -s)"
    # `slurmd -C` prints this node's line: NodeName=... CPUs=... RealMemory=...
    node="$(slurmd -C | head -n1)"
    name="$(sed -n 's/^NodeName=\([^ ]*\).*/\1/p' <<<"$node")"
    [ -n "$name" ] || die "\`slurmd -C\` printed no NodeName line: $node"
    $SUDO mkdir -p "$state"/{ctld,slurmd,log} /etc/slurm
    $SUDO tee "$conf" >/dev/null <<EOF
$marker (for tests and trials; see the script)
ClusterName=weft
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$state/ctld
SlurmdSpoolDir=$state/slurmd
SlurmctldPidFile=$state/slurmctld.pid
SlurmdPidFile=$state/slurmd.pid
SlurmctldLogFile=$state/log/slurmctld.log
SlurmdLogFile=$state/log/slurmd.log
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
DefMemPerCPU=512
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SwitchType=switch/none
MpiDefault=none
ReturnToService=2
MaxArraySize=1001
# Cancelled jobs go quickly; finished jobs stay visible to squeue for 5 minutes.
KillWait=2
MinJobAge=300
SchedulerType=sched/backfill
# Dependent jobs start within a second of their dependency (the default delays batch
# scheduling by up to 3 s).
SchedulerParameters=batch_sched_delay=0
$node State=UNKNOWN
PartitionName=main Nodes=$name Default=YES MaxTime=INFINITE State=UP
EOF
}

start() {
    command -v slurmctld >/dev/null && command -v slurmd >/dev/null && command -v munged >/dev/null \
        || die "Slurm is not installed
  hint: $0 install   (Debian/Ubuntu: slurmctld slurmd slurm-client munge)"
    write_conf
    # munged as user munge, with its socket folder.
    $SUDO mkdir -p /run/munge && $SUDO chown munge:munge /run/munge && $SUDO chmod 755 /run/munge
    if [ ! -f /etc/munge/munge.key ]; then
        $SUDO mungekey --create 2>/dev/null || $SUDO create-munge-key
        $SUDO chown munge:munge /etc/munge/munge.key
    fi
    if ! pid_alive "$state/munged.pid"; then
        $SUDO runuser -u munge -- /usr/sbin/munged --pid-file=/run/munge/munged.pid
        for _ in $(seq 50); do [ -f /run/munge/munged.pid ] && break; sleep 0.1; done
        $SUDO cp /run/munge/munged.pid "$state/munged.pid"
    fi
    pid_alive "$state/slurmctld.pid" || $SUDO slurmctld
    pid_alive "$state/slurmd.pid" || $SUDO slurmd
    # Wait until the node takes jobs.
    for _ in $(seq 100); do
        if sinfo -h -o '%t' 2>/dev/null | grep -qE '^(idle|mix|alloc)'; then
            echo "slurm-single-node: up ($(sinfo -h -o '%N %c CPUs %m MB %t'))"
            return 0
        fi
        sleep 0.3
    done
    die "the node did not come up; see $state/log/slurmctld.log and $state/log/slurmd.log"
}

stop() {
    # Reverse order, each by the PID it wrote; wait for each to exit.
    for d in slurmd slurmctld munged; do
        local f="$state/$d.pid"
        if pid_alive "$f"; then
            local pid; pid="$(cat "$f")"
            $SUDO kill "$pid"
            for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
            kill -0 "$pid" 2>/dev/null && $SUDO kill -9 "$pid"
        fi
        $SUDO rm -f "$f"
    done
    echo "slurm-single-node: stopped"
}

status() {
    for d in munged slurmctld slurmd; do
        if pid_alive "$state/$d.pid"; then echo "$d: pid $(cat "$state/$d.pid")"; else echo "$d: not running"; fi
    done
    sinfo 2>/dev/null || true
}

case "${1:-}" in
    install) install_pkgs ;;
    start) start ;;
    stop) stop ;;
    status) status ;;
    *) echo "usage: $0 install|start|stop|status" >&2; exit 2 ;;
esac
