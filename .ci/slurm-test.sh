#!/usr/bin/env bash
# The real-SLURM test (called by .ci/run after `cargo test`): start MUNGE and
# a single-node SLURM (slurmctld + slurmd, as root) under a temporary folder,
# submit `squeal slurm map --submit`'s job array and its dependent merge job,
# wait for them, and compare the merged map with the unsharded one byte for
# byte. The daemons it started are stopped whatever happens (trap).
# Uses the squeal that `cargo test` built (SQUEAL=… to choose another).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SQUEAL=${SQUEAL:-${CARGO_TARGET_DIR:-$ROOT/target}/debug/squeal}
say() { echo "slurm-test: $*"; }
[ -x "$SQUEAL" ] || { say "no squeal at $SQUEAL (run cargo test first)"; exit 1; }
[ "$(id -u)" = 0 ] || { say "must run as root (apt-get, SlurmUser=root)"; exit 1; }
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
    || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
    say "installing slurm-wlm and munge"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq slurm-wlm munge >/dev/null
fi
PATH=$PATH:/usr/sbin:/sbin

D=$(mktemp -d /tmp/squeal-slurm.XXXXXX)
cleanup() {
    local rc=$?
    for f in "$D/slurmd.pid" "$D/slurmctld.pid" "$D/munge/munged.pid"; do
        if [ -s "$f" ]; then kill "$(cat "$f")" 2>/dev/null || true; fi
    done
    sleep 2
    if [ "$rc" != 0 ]; then
        say "FAILED; logs:"
        tail -n 20 "$D"/log/*.log "$D"/work/*-slurm/*.log 2>/dev/null || true
    fi
    rm -rf "$D"
    exit "$rc"
}
trap cleanup EXIT INT TERM

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
sinfo -h -o %t | grep -q idle || { say "the node never became idle"; exit 1; }

cd "$D/work"
STUDY=(map belt --x V=2:16:4 --y c=0.05:1:3 --transient --duration 1.5)
"$SQUEAL" "${STUDY[@]}" --out full >/dev/null
OUT=$("$SQUEAL" slurm "${STUDY[@]}" --tasks 3 --cpus-per-task 1 --time 10:00 --out merged --submit)
echo "$OUT"
MERGE=$(echo "$OUT" | sed -n 's/.*merge job \([0-9]*\).*/\1/p')
[ -n "$MERGE" ] || { say "no merge job id"; exit 1; }
for _ in $(seq 300); do
    STATE=$(squeue -h -j "$MERGE" -o '%T %r' 2>/dev/null || true)
    [ -z "$STATE" ] && break
    case "$STATE" in *DependencyNeverSatisfied*) say "merge job cannot run: $STATE"; exit 1 ;; esac
    sleep 1
done
[ -z "$(squeue -h -j "$MERGE" 2>/dev/null || true)" ] || { say "jobs still queued after 300 s"; exit 1; }
for f in map.csv map.png map.svg transient.png transient.svg; do
    cmp "full/$f" "merged/$f" || { say "merged $f differs from the unsharded run"; exit 1; }
done
cat merged-slurm/merge.log
say "ok: the merged map equals the unsharded one byte for byte"
