# Start and stop a single-node SLURM (MUNGE, slurmctld, slurmd, as root)
# whose state lives under one folder. Sourced by .ci/slurm-test.sh and
# bench/slurm-bench.sh. A configuration known to work on Debian: SlurmUser=root,
# proctrack/linuxproc, task/none, select/cons_tres with CR_Core, a local MUNGE
# key, one node named after `hostname` with CPUs=2.

# slurm_install: install slurm-wlm and munge if missing (root, apt-get).
slurm_install() {
    PATH=$PATH:/usr/sbin:/sbin
    if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
        || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
        echo "installing slurm-wlm and munge"
        export DEBIAN_FRONTEND=noninteractive
        apt-get update -qq
        apt-get install -y -qq slurm-wlm munge >/dev/null
    fi
}

# slurm_start D: start the daemons with their state in D; exports SLURM_CONF;
# returns once the node is idle.
slurm_start() {
    local D=$1 SOCK HOST
    mkdir -p "$D"/{state,spool,log,munge,work}
    chmod 700 "$D/munge"
    dd if=/dev/urandom of="$D/munge/munge.key" bs=1024 count=1 status=none
    chmod 400 "$D/munge/munge.key"
    SOCK="$D/munge/munge.socket"
    munged --key-file="$D/munge/munge.key" --socket="$SOCK" --pid-file="$D/munge/munged.pid" \
        --log-file="$D/log/munged.log" --seed-file="$D/munge/seed" --force
    HOST=$(hostname -s)
    cat >"$D/slurm.conf" <<CONF
ClusterName=squealci
SlurmctldHost=$HOST
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$SOCK
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
StateSaveLocation=$D/state
SlurmdSpoolDir=$D/spool
SlurmctldPidFile=$D/slurmctld.pid
SlurmdPidFile=$D/slurmd.pid
SlurmctldLogFile=$D/log/slurmctld.log
SlurmdLogFile=$D/log/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$HOST CPUs=2 State=UNKNOWN
PartitionName=debug Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
    export SLURM_CONF="$D/slurm.conf"
    slurmctld -f "$D/slurm.conf"
    slurmd -f "$D/slurm.conf"
    for _ in $(seq 60); do
        if sinfo -h -o %t 2>/dev/null | grep -q idle; then break; fi
        sleep 1
    done
    sinfo -h -o %t | grep -q idle || { echo "slurm: the node never became idle" >&2; return 1; }
}

# slurm_stop D: stop the daemons slurm_start D started (by their PID files).
slurm_stop() {
    local D=$1 f
    for f in "$D/slurmd.pid" "$D/slurmctld.pid" "$D/munge/munged.pid"; do
        if [ -s "$f" ]; then kill "$(cat "$f")" 2>/dev/null || true; fi
    done
    sleep 2
}
