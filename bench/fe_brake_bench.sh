#!/usr/bin/env bash
# The FE ring-disc brake of examples/fe-brake at a given size: squeal's
# `stability` (steady sliding + every eigenvalue of the 2n state matrix +
# the real-mode composition of the growing modes) against SciPy doing the
# same linear algebra (examples/fe-brake/cea.py: one dense solve, LAPACK's
# eig of the state matrix). One run each, wall time; the ratio printed.
#
# Then the levers (issue 26 §4): `squeal stability` with its lever search
# against SciPy doing the same linear algebra as many times as squeal made
# analyses (cea.py --repeat N: steady solve, M^-1, state matrix, eigvals).
#
#   bench/fe_brake_bench.sh 61     # 187 dofs
#   bench/fe_brake_bench.sh 300    # 904 dofs
#
# Needs python3 with numpy and scipy (PYTHON=... to choose it) and a
# release build of squeal (SQUEAL=..., default target/release/squeal).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
elements="${1:-61}"
python="${PYTHON:-python3}"
squeal="${SQUEAL:-$here/target/release/squeal}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$python" "$here/examples/fe-brake/make_brake.py" --elements "$elements" --out "$work" >/dev/null
sc="$work/two-pad/brake-dmig.toml"
n=$((3 * elements + 4))
t0=$(date +%s.%N)
"$squeal" stability "$sc" --set modal.dense_max_dofs=100000 --json --no-levers >"$work/squeal.json"
t1=$(date +%s.%N)
"$python" "$here/examples/fe-brake/cea.py" "$work/two-pad/brake.toml" >"$work/scipy.json"
t2=$(date +%s.%N)
"$python" - "$work/squeal.json" "$work/scipy.json" "$n" "$t0" "$t1" "$t2" <<'PY'
import json, sys
a = json.load(open(sys.argv[1]))["eigenvalues"][0]
b = json.load(open(sys.argv[2]))["eigenvalues"][0]
n, t0, t1, t2 = int(sys.argv[3]), *map(float, sys.argv[4:])
rel = abs(complex(a["re"], abs(a["im"])) - complex(b[0], abs(b[1]))) / abs(complex(*b))
print(f"{n} dofs: squeal {t1 - t0:.2f} s, SciPy {t2 - t1:.2f} s, ratio {(t2 - t1) / (t1 - t0):.2f}; "
      f"leading eigenvalue {a['re']:+.6e} ± {abs(a['im']):.6e}i, relative difference {rel:.1e}")
PY
t0=$(date +%s.%N)
"$squeal" stability "$sc" --set modal.dense_max_dofs=100000 --json >"$work/levers.json"
t1=$(date +%s.%N)
count=$("$python" -c 'import json,sys; print(json.load(open(sys.argv[1]))["lever_analyses"])' "$work/levers.json")
"$python" "$here/examples/fe-brake/cea.py" "$work/two-pad/brake.toml" --repeat "$count" >/dev/null
t2=$(date +%s.%N)
"$python" - "$work/levers.json" "$n" "$count" "$t0" "$t1" "$t2" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
n, count, t0, t1, t2 = int(sys.argv[2]), int(sys.argv[3]), *map(float, sys.argv[4:])
print(f"{n} dofs, levers ({len(d['sensitivities'])} sensitivities, {len(d['levers'])} levers, "
      f"{count} analyses): squeal {t1 - t0:.2f} s, SciPy's {count} analyses {t2 - t1:.2f} s, "
      f"ratio {(t2 - t1) / (t1 - t0):.2f}")
PY
