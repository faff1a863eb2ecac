#!/usr/bin/env bash
# Instructions per RTI step of the generated solver, counted by valgrind's callgrind: repeatable on a
# shared, noisy machine (docs/benchmarks.md). For each N_h: the default spec with humans.max = N_h is
# generated, tests/c/closed_loop.c drives it for STEPS steps with all N_h humans present ("fixed"),
# compiled with portable -O2 (valgrind does not run AVX-512 code).
#
# usage (from the repository root, after `make venv`): docs/instruction_counts.sh [N_H ...]
#        STEPS=300 docs/instruction_counts.sh 5 30
set -euo pipefail
cd "$(dirname "$0")/.."
GEN=.venv/bin/humanmpc-gen
STEPS=${STEPS:-300}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ $# -gt 0 ] || set -- 5 10 20 30
for k in "$@"; do
  printf 'name: ic%s\nhumans: {max: %s}\n' "$k" "$k" > "$work/ic$k.yaml"
  "$GEN" generate "$work/ic$k.yaml" -o "$work/ic$k" --force > /dev/null 2>&1
  cc -std=c99 -O2 -DSOLVER_HEADER="\"ic$k.h\"" -DSOLVER_PREFIX="ic${k}_" -I "$work/ic$k" tests/c/closed_loop.c \
    "$work/ic$k/ic$k.c" "$work/ic$k/ic${k}_model.c" -lm -o "$work/loop$k"
  valgrind --tool=callgrind --callgrind-out-file="$work/cg$k" "$work/loop$k" "$STEPS" 1 1000 fixed \
    > "$work/out$k.json" 2> /dev/null
  total=$(callgrind_annotate "$work/cg$k" | awk '/PROGRAM TOTALS/ {gsub(",", "", $1); print $1}')
  iters=$(sed -n 's/.*"qp_iterations_mean": \([0-9.]*\).*/\1/p' "$work/out$k.json")
  printf 'N_h = %2s: %9d instructions per RTI step, %s QP iterations per step (%s steps)\n' \
    "$k" $((total / STEPS)) "$iters" "$STEPS"
done
