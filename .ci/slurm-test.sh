#!/usr/bin/env bash
# The real-SLURM test (called by .ci/run after `cargo test --release`): start MUNGE and
# a single-node SLURM (slurmctld + slurmd, as root) under a temporary folder,
# submit `squeal slurm map --submit`'s job array and its dependent merge job,
# wait for them, and compare the merged map with the unsharded one byte for
# byte. The daemons it started are stopped whatever happens (trap).
# Uses the squeal that `cargo test --release` built (SQUEAL=… to choose another).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SQUEAL=${SQUEAL:-${CARGO_TARGET_DIR:-$ROOT/target}/release/squeal}
say() { echo "slurm-test: $*"; }
[ -x "$SQUEAL" ] || { say "no squeal at $SQUEAL (run cargo test --release first)"; exit 1; }
[ "$(id -u)" = 0 ] || { say "must run as root (apt-get, SlurmUser=root)"; exit 1; }
# shellcheck source=slurm-local.sh
. "$ROOT/.ci/slurm-local.sh"
slurm_install

D=$(mktemp -d /tmp/squeal-slurm.XXXXXX)
cleanup() {
    local rc=$?
    slurm_stop "$D"
    if [ "$rc" != 0 ]; then
        say "FAILED; logs:"
        tail -n 20 "$D"/log/*.log "$D"/work/*-slurm/*.log 2>/dev/null || true
    fi
    rm -rf "$D"
    exit "$rc"
}
trap cleanup EXIT INT TERM

slurm_start "$D"

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
# One task lost: rerun it alone (README's recipe), merge again.
rm -rf merged-slurm/shard-1
sbatch --wait --array=1 merged-slurm/array.sh >/dev/null
sbatch --wait merged-slurm/merge.sh >/dev/null
cmp full/map.csv merged/map.csv || { say "map after rerunning task 1 differs"; exit 1; }
say "ok: the merged map equals the unsharded one byte for byte"
