#!/bin/sh
# Build and run the CVODE peer of BENCHMARKS.md (issue 16). Not part of CI.
# Needs Debian's libsundials-dev (apt-get install libsundials-dev).
#   sh bench/cvode_discpad.sh [adams|bdf|erk] [t_end] [reps]
set -e
here=$(dirname "$0")
out=${TMPDIR:-/tmp}/cvode_discpad
cc -O2 -o "$out" "$here/cvode_discpad.c" \
    -lsundials_cvode -lsundials_arkode -lsundials_nvecserial -lsundials_sunlinsoldense \
    -lsundials_sunmatrixdense -lsundials_sunnonlinsolfixedpoint -lm
"$out" "$@"
