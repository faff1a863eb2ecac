#!/usr/bin/env bash
# Where an RTI step's time goes: for each N_h, the default spec with humans.max = N_h is generated and
# tests/c/closed_loop.c drives it for STEPS steps with all N_h humans present ("fixed"), built with
# the host flags and -DOCP_QP_IPM_PROFILE, which times each part of every QP solve
# (ocp_qp_ipm.c: setup, passes A to E, finish) with clock_gettime. Prints microseconds per step.
# The clock reads add about 0.1 us per timed part (about 5 per QP iteration); compare runs made in
# one go, the machine is shared (docs/benchmarks.md).
#
# usage (from the repository root, after `make venv`): docs/pass_profile.sh [N_H ...]
#        STEPS=5000 SEEDS="1 2 3" docs/pass_profile.sh 5 30
set -euo pipefail
cd "$(dirname "$0")/.."
GEN=.venv/bin/humanmpc-gen
PY=.venv/bin/python
STEPS=${STEPS:-3000}
SEEDS=${SEEDS:-"1 2 3"}
read -r CC FLAGS < <($PY -c 'from humanmpc.codegen.build import compiler_and_flags as f; print(*f())')
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ $# -gt 0 ] || set -- 5 10 20 30
printf '| N_h | seed | QP iter | step | prepare | QP setup | A | B | C | D | E | QP finish | rest |\n'
printf '|---|---|---|---|---|---|---|---|---|---|---|---|---|\n'
for k in "$@"; do
  printf 'name: pp%s\nhumans: {max: %s}\n' "$k" "$k" > "$work/pp$k.yaml"
  "$GEN" generate "$work/pp$k.yaml" -o "$work/pp$k" --force > /dev/null 2>&1
  # shellcheck disable=SC2086
  "$CC" -std=c99 $FLAGS -D_POSIX_C_SOURCE=199309L -DOCP_QP_IPM_PROFILE -DSOLVER_HEADER="\"pp$k.h\"" \
    -DSOLVER_PREFIX="pp${k}_" -I "$work/pp$k" tests/c/closed_loop.c "$work/pp$k/pp$k.c" "$work/pp$k/pp${k}_model.c" \
    -lm -o "$work/loop$k"
  for seed in $SEEDS; do
    "$work/loop$k" "$STEPS" "$seed" 1000 fixed | $PY -c '
import json, sys
d = json.loads(sys.stdin.read().splitlines()[-1])
parts = ["prepare", "qp_setup", "qp_pass_a", "qp_pass_b", "qp_pass_c", "qp_pass_d", "qp_pass_e", "qp_finish"]
rest = d["step_us"] - sum(d[p + "_us"] for p in parts)
cells = [sys.argv[1], sys.argv[2], "%.2f" % d["qp_iterations_mean"], "%.1f" % d["step_us"]]
cells += ["%.1f" % d[p + "_us"] for p in parts] + ["%.1f" % rest]
print("| " + " | ".join(cells) + " |")' "$k" "$seed"
  done
done
printf '(microseconds per RTI step, %s steps per run; rest = the step outside the QP solves and the preparation)\n' "$STEPS"
