#!/usr/bin/env bash
# Reproduce every CSV and PNG of bench/peers (RESULTS.md), then the timings
# (timing.sh). Needs: GNU Octave; NLvib's files at $NLVIB (default
# /tmp/nlvib, the repository's layout: SRC/, SRC/MechanicalSystems/); pyHarm
# in its own venv ($PYHARM_PY, default /tmp/pyharm-venv/bin/python, made by
# `python3 -m venv /tmp/pyharm-venv && /tmp/pyharm-venv/bin/pip install
# pyharm-os matplotlib`); squeal's release binary ($SQUEAL).
set -euo pipefail
cd "$(dirname "$0")/../.."
P=bench/peers
SQUEAL=${SQUEAL:-target/release/squeal}
export NLVIB=${NLVIB:-/tmp/nlvib}
PY=${PYHARM_PY:-/tmp/pyharm-venv/bin/python}
T=$(mktemp -d)

# 1. NLvib example 05 against squeal nma
octave --no-gui --quiet $P/nlvib05_run.m                                   # as the example: nlvib05_nlvib_hb.csv
NLVIB_TOL=1e-12 octave --no-gui --quiet $P/nlvib05_run.m                   # *_tight.csv
NLVIB_TOL=1e-12 NLVIB_DS=0.002 octave --no-gui --quiet $P/nlvib05_run.m    # *_tight_ds0.002.csv (dense)
NLVIB_TOL=1e-12 NLVIB_DS=0.002 NLVIB_LOG10A=-0.93:-0.79 octave --no-gui --quiet $P/nlvib05_run.m  # *_zoom.csv
NLVIB_TOL=1e-12 NLVIB_NTD=16384 octave --no-gui --quiet $P/nlvib05_run.m   # *_ntd16384.csv (AFT samples)
NLVIB_SHOOT=1 octave --no-gui --quiet $P/nlvib05_run.m                     # also nlvib05_nlvib_shoot.csv (~2 min)
"$SQUEAL" nma $P/nlvib05.toml --mode 1 --modal-amplitude 0.0316227766:10:106 --harmonics 21 --json \
  | "$PY" $P/squeal_json_to_csv.py > $P/nlvib05_squeal.csv
"$SQUEAL" nma $P/nlvib05.toml --mode 1 --modal-amplitude 0.12:0.16:41 --harmonics 21 --json \
  | "$PY" $P/squeal_json_to_csv.py > $P/nlvib05_squeal_zoom.csv
"$PY" $P/nlvib05_compare.py | tee $P/nlvib05_compare.txt

# 2. The forced Coulomb oscillator against pyHarm
"$SQUEAL" hb scenarios/lumped/coulomb-forced.toml --harmonics 20 --param shaker.freq_hz=9.6:15.2:57 --out "$T/dh"
cp "$T/dh/branch.csv" $P/coulomb_dh_squeal.csv
for e in 1e4 1e5 1e6 1e7 1e8; do
  "$PY" $P/pyharm_coulomb.py --H 20 --nti 1024 --eps $e --lo-hz 9.6 --hi-hz 15.2 --ds 0.6283185307 --runs 1 \
    --out $P/coulomb_dh_pyharm_eps${e}_nti1024.csv
done
"$SQUEAL" hb $P/coulomb-damped.toml --harmonics 20 --param shaker.freq_hz=9:24:76 --out "$T/cd"
cp "$T/cd/branch.csv" $P/coulomb_damped_squeal.csv
for e in 1e5 1e6 1e7 1e8; do
  "$PY" $P/pyharm_coulomb.py --H 20 --nti 256 --c 4 --eps $e --lo-hz 9 --hi-hz 24 --ds 1.2566370614 --runs 1 \
    --out $P/coulomb_damped_pyharm_eps${e}_nti256.csv
done
"$PY" $P/pyharm_coulomb.py --H 20 --nti 1024 --c 4 --eps 1e7 --lo-hz 9 --hi-hz 24 --ds 1.2566370614 --runs 1 \
  --out $P/coulomb_damped_pyharm_eps1e7_nti1024.csv
{ "$PY" $P/coulomb_compare.py dh; "$PY" $P/coulomb_compare.py damped; } | tee $P/coulomb_compare.txt
"$PY" $P/coulomb_compare.py plot
rm -rf "$T"

# 3. Times (appends to timing.csv; REPS=3 by default)
SQUEAL="$SQUEAL" PYHARM_PY="$PY" bash $P/timing.sh
