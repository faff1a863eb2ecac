#!/usr/bin/env bash
# The work of the controller's step against its number of candidate plans, counted: the controller bench's
# closed loop (humanmpc-gen bench --controller 30: 30 tracked people, N_h = 10) for one seed, under
# valgrind's callgrind, which counts the same on a quiet or a loaded machine (the bench's wall clock does
# not). For each number of plans the default spec with controller.candidates = K (and the bench's
# max_tracks) is generated and built (portable -O2); the count is controller_plan's inclusive one (the
# plans, recoveries and the controller's own work but for the input checks and the output) per period.
# Generous deadline: valgrind is slow, and a deadline stop would change the loop.
#
# usage (from the repository root, after `make venv`): docs/candidate_work.sh [K ...]
#        STEPS=100 SEED=1 docs/candidate_work.sh 1 4
set -euo pipefail
cd "$(dirname "$0")/.."
PY=.venv/bin/python
STEPS=${STEPS:-300}
SEED=${SEED:-0}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ $# -gt 0 ] || set -- 1 2 4 8
printf '| candidate plans | instructions / period [M] | periods | outcomes |\n|---:|---:|---:|---|\n'
for k in "$@"; do
  "$PY" - "$work/c$k" "$k" <<'PY'
import sys
from pathlib import Path
from humanmpc.codegen.build import build
from humanmpc.codegen.generate import generate
from humanmpc.codegen.spec import Spec, resolve_spec
data = Spec().to_dict()
data["name"] = f"c{sys.argv[2]}"
data.setdefault("controller", {}).update(max_tracks=32, candidates=int(sys.argv[2]))
build(generate(resolve_spec(data), Path(sys.argv[1]), force=True, log=lambda _m: None), log=lambda _m: None)
PY
  valgrind --tool=callgrind --trace-children=yes --callgrind-out-file="$work/cg$k.%p" "$PY" - "$work/c$k" \
    "$STEPS" "$SEED" > "$work/log$k" 2> /dev/null <<'PY'
import sys
from collections import Counter
from humanmpc.bindings import load
from humanmpc.compare.controller_bench import run_controller_loop
from humanmpc.status import OUTCOME_NAMES
ctl = load(sys.argv[1]).controller()
ctl.set_params(deadline_ms=1e4)
out = run_controller_loop(ctl, 30, int(sys.argv[3]), int(sys.argv[2]))
print(", ".join(f"{OUTCOME_NAMES[int(o)]} {n}" for o, n in sorted(Counter(out["outcome"]).items())))
PY
  total=$(callgrind_annotate --inclusive=yes "$work"/cg$k.* 2> /dev/null | grep -E ':controller_plan ' | head -1 \
    | awk '{gsub(",", "", $1); print $1}')
  printf '| %s | %.2f | %s | %s |\n' "$k" "$(echo "$total / $STEPS / 1000000" | bc -l)" "$STEPS" "$(cat "$work/log$k")"
done
