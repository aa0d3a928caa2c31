#!/bin/bash
# The thesis reproduction unsharded vs as 4 shards + merge, one thread each: CPU times into times.txt, and a check that the merged folder equals the unsharded one. Run from an empty folder: SQUEAL=/path/to/squeal bash bench/reproduce-shard-bench.sh
B=${SQUEAL:-target/release/squeal}
export RAYON_NUM_THREADS=1
t() { /usr/bin/time -f "$1 wall %e s user %U s sys %S s" "${@:2}" > /dev/null 2>>times.txt; }
t unsharded $B reproduce --out full
for k in 0 1 2 3; do t shard-$k/4 $B reproduce --shard $k/4 --out s$k; done
t merge $B merge s0 s1 s2 s3 --out merged
for f in table.csv conclusions.json report.md report.html map.png map.svg; do cmp full/$f merged/$f && echo "same $f" >> times.txt; done
diff -r full merged >/dev/null && echo "trees identical" >> times.txt
