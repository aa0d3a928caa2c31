#!/usr/bin/env bash
# Sharding and merging cost (BENCHMARKS.md, "Shards, merge and SLURM"): a
# transient map of 400 points unsharded, as 2 and 4 shards run one after the
# other on one thread (CPU time: the overhead of sharding + merging), and as
# a 2-task and a 4-task array on a local single-node SLURM (wall time).
# Run as root from the repository: SQUEAL=target/release/squeal bench/slurm-bench.sh
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SQUEAL=$(realpath "${SQUEAL:-$ROOT/target/release/squeal}")
STUDY=(map disc-pad --x V=0.5:20:20 --y N=100:3000:20 --transient)
. "$ROOT/.ci/slurm-local.sh"
slurm_install
D=$(mktemp -d /tmp/squeal-bench.XXXXXX)
trap 'slurm_stop "$D"; rm -rf "$D"' EXIT INT TERM
mkdir -p "$D/work" && cd "$D/work"
TIMEFORMAT='%R %U %S'
cpu() { # wall user sys of a command → "wall cpu"
    local t
    t=$( { time "$@" >/dev/null; } 2>&1 | tail -1)
    awk '{printf "%.2f %.2f\n", $1, $2 + $3}' <<<"$t"
}
export RAYON_NUM_THREADS=1
read -r W1 C1 < <(cpu "$SQUEAL" "${STUDY[@]}" --out full1)
echo "unsharded, 1 thread: wall $W1 s, cpu $C1 s"
for n in 2 4; do
    total=0
    for k in $(seq 0 $((n - 1))); do
        read -r _ c < <(cpu "$SQUEAL" "${STUDY[@]}" --shard "$k/$n" --out "s$n/shard-$k/map")
        total=$(awk -v a="$total" -v b="$c" 'BEGIN{print a+b}')
    done
    read -r _ cm < <(cpu "$SQUEAL" merge $(for k in $(seq 0 $((n - 1))); do echo "s$n/shard-$k/map"; done) --out "m$n")
    cmp full1/map.csv "m$n/map.csv"
    echo "$n shards one after the other: cpu $total s + merge $cm s; overhead $(awk -v s="$total" -v m="$cm" -v u="$C1" 'BEGIN{printf "%.1f", 100*(s+m-u)/u}') %"
done
unset RAYON_NUM_THREADS
read -r W2 _ < <(cpu "$SQUEAL" "${STUDY[@]}" --out full)
echo "unsharded, 2 threads: wall $W2 s"
slurm_start "$D"
for n in 2 4; do
    t0=$(date +%s.%N)
    OUT=$("$SQUEAL" slurm "${STUDY[@]}" --tasks "$n" --cpus-per-task 1 --out "a$n" --submit)
    MERGE=$(sed -n 's/.*merge job \([0-9]*\).*/\1/p' <<<"$OUT")
    while [ -n "$(squeue -h -j "$MERGE" 2>/dev/null || true)" ]; do sleep 0.2; done
    t1=$(date +%s.%N)
    cmp full/map.csv "a$n/map.csv"
    echo "SLURM array of $n tasks (1 CPU each, node of 2 CPUs) + merge job: wall $(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.2f", b-a}') s"
done
