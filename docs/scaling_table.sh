#!/usr/bin/env bash
# Memory and instructions of the generated solver against N_h and N (docs/benchmarks.md, issue 20): for
# each (N_h, N, T) the default spec with humans.max = N_h and horizon {N, T} is generated in double and in
# float; tests/c/closed_loop.c (built with -DDT=T/N: one shooting interval per step) drives the double
# solver in a crowd of N_h people, all present, for SIM_SECONDS of simulated time, compiled with portable
# -O2 and counted by valgrind's callgrind (repeatable on a shared machine); the solver struct's size is
# the closed loop's sizeof of <name>_solver (all memory of a solver: nothing is allocated at run time).
# The QP row capacity is the spec's default (solver.qp_rows): the table gives it, the most rows a QP of
# the loop had, and the QPs that had more (they held the rows of smallest margin).
#
# usage (from the repository root, after `make venv`): docs/scaling_table.sh
#        SIM_SECONDS=10 docs/scaling_table.sh "10 50 5" "10 200 5"     # rows "N_h N T"
set -euo pipefail
cd "$(dirname "$0")/.."
GEN=.venv/bin/humanmpc-gen
SIM_SECONDS=${SIM_SECONDS:-30}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [ $# -eq 0 ]; then
  # N_h at the default horizon; N at the default T = 5 s (finer intervals) and at dt = 0.1 s (longer horizons)
  set -- "5 50 5" "10 50 5" "30 50 5" "60 50 5" "100 50 5" \
         "10 25 5" "10 100 5" "10 200 5" "10 25 2.5" "10 100 10" "10 200 20"
fi
printf '| N_h | N | T [s] | dt [s] | QP rows: capacity / most / QPs beyond | solver struct, double [B] | float [B] | instructions / RTI step | QP iterations / step | steps |\n'
printf '|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|\n'
for row in "$@"; do
  read -r k n T <<< "$row"
  dt=$(awk -v T="$T" -v n="$n" 'BEGIN { printf "%.17g", T / n }')
  steps=$(awk -v s="$SIM_SECONDS" -v dt="$dt" 'BEGIN { printf "%d", s / dt + 0.5 }')
  for prec in double float; do
    name="st${k}_${n}_${prec:0:1}"
    printf 'name: %s\nprecision: %s\nhumans: {max: %s}\nhorizon: {N: %s, T: %s}\n' "$name" "$prec" "$k" "$n" "$T" \
      > "$work/$name.yaml"
    "$GEN" generate "$work/$name.yaml" -o "$work/$name" --force > /dev/null 2>&1
    cc -std=c99 -O2 -DDT="$dt" -DSOLVER_HEADER="\"$name.h\"" -DSOLVER_PREFIX="${name}_" -I "$work/$name" \
      tests/c/closed_loop.c "$work/$name/$name.c" "$work/$name/${name}_model.c" -lm -o "$work/loop_$name"
  done
  d="st${k}_${n}_d"
  f="st${k}_${n}_f"
  valgrind --tool=callgrind --callgrind-out-file="$work/cg_$d" "$work/loop_$d" "$steps" 1 100000 fixed \
    > "$work/out_$d.json" 2> /dev/null
  "$work/loop_$f" 1 1 100000 fixed > "$work/out_$f.json"
  total=$(callgrind_annotate "$work/cg_$d" | awk '/PROGRAM TOTALS/ {gsub(",", "", $1); print $1}')
  field() { sed -n "s/.*\"$1\": \"*\([0-9a-f.]*\).*/\1/p" "$2"; }
  cap=$(sed -n "s/^#define ${d^^}_QP_ROWS \([0-9]*\).*/\1/p" "$work/$d/$d.h")
  printf '| %s | %s | %s | %s | %s / %s / %s | %s | %s | %s | %s | %s |\n' "$k" "$n" "$T" "$(awk -v x="$dt" 'BEGIN { printf "%g", x }')" \
    "$cap" "$(field qp_rows_max "$work/out_$d.json")" "$(field qp_rows_capped "$work/out_$d.json")" \
    "$(field solver_bytes "$work/out_$d.json")" "$(field solver_bytes "$work/out_$f.json")" \
    "$((total / steps))" "$(field qp_iterations_mean "$work/out_$d.json")" "$steps"
done
