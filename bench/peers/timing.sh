#!/usr/bin/env bash
# Wall-clock times of the three tools on the cases of RESULTS.md, each run
# REPS times (default 3); appends to bench/peers/timing.csv:
#   tool,case,config,points,rep,wall_s,cpu_s,internal_s
# internal_s: NLvib's own tic/toc around solve_and_continue; pyHarm's
# Maestro.operate() of the warm (second) run in the process; empty for squeal
# (its wall time is the whole command).
# Env: SQUEAL (binary), NLVIB (NLvib checkout), PYHARM_PY (pyHarm's python).
set -euo pipefail
cd "$(dirname "$0")/../.."
P=bench/peers
SQUEAL=${SQUEAL:-target/release/squeal}
NLVIB=${NLVIB:-/tmp/nlvib}
PY=${PYHARM_PY:-/tmp/pyharm-venv/bin/python}
REPS=${REPS:-3}
OUT=$P/timing.csv
T=$(mktemp -d)
[ -f "$OUT" ] || echo "tool,case,config,points,rep,wall_s,cpu_s,internal_s" > "$OUT"
tm() { /usr/bin/time -f "%e %U %S" -o "$T/time" "$@" > "$T/out" 2> "$T/err"; read -r w u s < "$T/time"; echo "$w $(echo "$u + $s" | bc)"; }

for rep in $(seq "$REPS"); do
  # 1. NLvib example 05, HB part as the example runs it (H = 21, Ntd = 1024)
  read -r w c < <(tm env NLVIB="$NLVIB" octave --no-gui --quiet $P/nlvib05_run.m)
  n=$(grep -o 'points=[0-9]*' "$T/out" | cut -d= -f2); i=$(grep -o 'time_s=[0-9.]*' "$T/out" | cut -d= -f2)
  echo "nlvib,nlvib05,H21 Ntd1024 default fsolve,$n,$rep,$w,$c,$i" >> "$OUT"
  read -r w c < <(tm env NLVIB="$NLVIB" NLVIB_TOL=1e-12 octave --no-gui --quiet $P/nlvib05_run.m)
  n=$(grep -o 'points=[0-9]*' "$T/out" | cut -d= -f2); i=$(grep -o 'time_s=[0-9.]*' "$T/out" | cut -d= -f2)
  echo "nlvib,nlvib05,H21 Ntd1024 fsolve tol 1e-12,$n,$rep,$w,$c,$i" >> "$OUT"
  read -r w c < <(tm "$SQUEAL" nma $P/nlvib05.toml --mode 1 --modal-amplitude 0.0316227766:10:106 --harmonics 21 --json)
  echo "squeal,nlvib05,H21 nma,106,$rep,$w,$c," >> "$OUT"

  # 2. Coulomb oscillator, Den Hartog (c = 0), 9.6…15.2 Hz
  rm -rf "$T/dh"
  read -r w c < <(tm "$SQUEAL" hb scenarios/lumped/coulomb-forced.toml --harmonics 20 --param shaker.freq_hz=9.6:15.2:57 --out "$T/dh")
  echo "squeal,coulomb_dh,H20 hb --param (with Floquet per point),$(($(wc -l < "$T/dh/branch.csv") - 1)),$rep,$w,$c," >> "$OUT"
  for nti in 256 1024; do
    read -r w c < <(tm "$PY" $P/pyharm_coulomb.py --H 20 --nti $nti --eps 1e7 --lo-hz 9.6 --hi-hz 15.2 --ds 0.6283185307 --out "$T/p.csv")
    n=$(grep -o 'points=[0-9]*' "$T/out" | cut -d= -f2); i=$(grep -o 'times_s=[0-9.,]*' "$T/out" | cut -d, -f2)
    echo "pyharm,coulomb_dh,H20 nti$nti eps1e7,$n,$rep,$w,$c,$i" >> "$OUT"
  done

  # 3. Coulomb + viscous (c = 4), 9…24 Hz through resonance
  rm -rf "$T/cd"
  read -r w c < <(tm "$SQUEAL" hb $P/coulomb-damped.toml --harmonics 20 --param shaker.freq_hz=9:24:76 --out "$T/cd")
  echo "squeal,coulomb_damped,H20 hb --param (with Floquet per point),$(($(wc -l < "$T/cd/branch.csv") - 1)),$rep,$w,$c," >> "$OUT"
  for nti in 256 1024; do
    read -r w c < <(tm "$PY" $P/pyharm_coulomb.py --H 20 --nti $nti --c 4 --eps 1e7 --lo-hz 9 --hi-hz 24 --ds 1.2566370614 --out "$T/p.csv")
    n=$(grep -o 'points=[0-9]*' "$T/out" | cut -d= -f2); i=$(grep -o 'times_s=[0-9.,]*' "$T/out" | cut -d, -f2)
    echo "pyharm,coulomb_damped,H20 nti$nti eps1e7,$n,$rep,$w,$c,$i" >> "$OUT"
  done
done
rm -rf "$T"
