#!/usr/bin/env bash
# The work of single RTI steps, counted: how far the costliest step of a closed loop is above the mean
# (issue 20's "bounded worst case", docs/benchmarks.md), in instructions, which valgrind's callgrind
# counts the same on a quiet or a loaded machine (the bench's wall clock adds the machine's outliers).
# For each N_h: the default spec with humans.max = N_h is generated; tests/c/closed_loop.c, built with
# portable -O2 and -DCLOSED_LOOP_TRACE (a line per step: SQP iterations, QP iterations, solves, rows,
# stop reason), drives it for STEPS steps with all N_h people present, under callgrind with a dump after
# every <name>_solver_step; each dump's total is that step's instructions (the loop's own bookkeeping
# between two steps, a few thousand instructions, included).
# Prints, per N_h: the mean, median, p99 and largest step, the largest over the mean, the mean of the
# steps that took the braking retry (two linearisations and two QPs) and of the others, and what the
# three costliest steps did.
#
# usage (from the repository root, after `make venv`): docs/step_work.sh [N_H ...]
#        STEPS=3000 SEED=2 docs/step_work.sh 30
set -euo pipefail
cd "$(dirname "$0")/.."
GEN=.venv/bin/humanmpc-gen
PY=.venv/bin/python
STEPS=${STEPS:-1500}
SEED=${SEED:-1}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ $# -gt 0 ] || set -- 10 30 100
printf '| N_h | steps | mean [M instr.] | median | p99 | max | max / mean | braking-retry steps: count, mean | other steps: mean | costliest steps: SQP it., QP it., QP solves, rows |\n'
printf '|---:|---:|---:|---:|---:|---:|---:|---|---:|---|\n'
for k in "$@"; do
  name="sw$k"
  printf 'name: %s\nhumans: {max: %s}\n' "$name" "$k" > "$work/$name.yaml"
  "$GEN" generate "$work/$name.yaml" -o "$work/$name" --force > /dev/null 2>&1
  cc -std=c99 -O2 -DCLOSED_LOOP_TRACE -DSOLVER_HEADER="\"$name.h\"" -DSOLVER_PREFIX="${name}_" -I "$work/$name" \
    tests/c/closed_loop.c "$work/$name/$name.c" "$work/$name/${name}_model.c" -lm -o "$work/loop$k"
  mkdir "$work/dumps$k"
  valgrind --tool=callgrind --dump-after="${name}_solver_step" --callgrind-out-file="$work/dumps$k/cg" \
    "$work/loop$k" "$STEPS" "$SEED" 100000 fixed > /dev/null 2> "$work/trace$k"
  "$PY" - "$k" "$work/dumps$k" "$work/trace$k" <<'PY'
import glob
import statistics
import sys

k, dumps, trace = sys.argv[1], sys.argv[2], sys.argv[3]
files = sorted(glob.glob(dumps + "/cg.*"), key=lambda f: int(f.rsplit(".", 1)[1]))
work = []
for f in files:
    with open(f) as fh:
        work.append(next(int(line.split()[1]) for line in fh if line.startswith("totals:")))
steps = [line.split()[2:] for line in open(trace) if line.startswith("trace ")]
if len(work) < len(steps):
    sys.exit(f"N_h = {k}: {len(work)} dumps for {len(steps)} steps")
work = work[:len(steps)]
order = sorted(work)
mean = statistics.mean(work)
retry = [w for w, s in zip(work, steps, strict=True) if s[0] == "2"]
other = [w for w, s in zip(work, steps, strict=True) if s[0] != "2"]
top = sorted(range(len(work)), key=lambda i: -work[i])[:3]
M = 1e6
print(f"| {k} | {len(work)} | {mean / M:.3f} | {statistics.median(work) / M:.3f} "
      f"| {order[min(len(order) - 1, int(0.99 * len(order)))] / M:.3f} | {order[-1] / M:.3f} | {order[-1] / mean:.2f} "
      f"| {len(retry)}, {statistics.mean(retry) / M if retry else 0.0:.3f} | {statistics.mean(other) / M:.3f} | "
      + "; ".join(f"{work[i] / M:.2f} M: {', '.join(steps[i][:4])}" for i in top) + " |")
PY
done
