#!/usr/bin/env bash
# Bit-identity of the generated C across a change: tests/c/closed_loop.c drives a generated solver
# for STEPS steps per seed (a changing random crowd, NaNs injected now and then) and prints an FNV-1a
# hash of the state and the command of every step. Two trees that print the same hashes took the
# same steps bit for bit. Solvers: the default spec (double, N_h = 10), N_h = 5, and the default spec
# in float. A generous deadline keeps the clock out of the trajectory.
#
# usage (from the repository root, after `make venv`): docs/bit_identity.sh [SEED ...]
#        STEPS=2000 docs/bit_identity.sh 1 2 3 > before.txt   # then again after the change; diff
set -euo pipefail
cd "$(dirname "$0")/.."
GEN=.venv/bin/humanmpc-gen
STEPS=${STEPS:-2000}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ $# -gt 0 ] || set -- 1 2 3
printf 'name: bi_paper\n' > "$work/bi_paper.yaml"
printf 'name: bi_nh5\nhumans: {max: 5}\n' > "$work/bi_nh5.yaml"
printf 'name: bi_float\nprecision: float\n' > "$work/bi_float.yaml"
for s in bi_paper bi_nh5 bi_float; do
  "$GEN" generate "$work/$s.yaml" -o "$work/$s" --force > /dev/null 2>&1
  cc -std=c99 -O2 -DSOLVER_HEADER="\"$s.h\"" -DSOLVER_PREFIX="${s}_" -I "$work/$s" tests/c/closed_loop.c \
    "$work/$s/$s.c" "$work/$s/${s}_model.c" -lm -o "$work/loop_$s"
  for seed in "$@"; do
    hash=$("$work/loop_$s" "$STEPS" "$seed" 1e5 | sed -n 's/.*"xu_hash": "\([0-9a-f]*\)".*/\1/p')
    printf '%-9s seed %s, %s steps: %s\n' "$s" "$seed" "$STEPS" "$hash"
  done
done
