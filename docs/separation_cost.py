"""What speed and separation costs in the controller step (docs/evaluation.md, round 4).

One controller package of the built-in default spec (with the bench's 30 tracks), driven through the
closed loops of `humanmpc-gen bench --controller 30` (3 seeds x 300 steps) twice per round, once with
`separation = 1` (the default) and once with `separation = 0` (the controller as it was before issue
23), alternating for ROUNDS rounds so that both see the same load on this shared machine. Prints the
step's mean, median, min, max and p99 (ms, pooled over the rounds) of both and their ratio. The loops
differ between the two (the bound changes what the robot does), as they would on a robot.

    .venv/bin/python docs/separation_cost.py [ROUNDS] [OUT_DIR]     # about 1 minute per round
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from humanmpc.bindings import load
from humanmpc.codegen.build import build
from humanmpc.codegen.generate import generate
from humanmpc.codegen.spec import Spec, resolve_spec
from humanmpc.compare.bench import TimingStats, pin_to_one_core
from humanmpc.compare.controller_bench import run_controller_loop

TRACKS, SEEDS, STEPS = 30, 3, 300


def main() -> None:
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    out = Path(sys.argv[2] if len(sys.argv) > 2 else "out/separation_cost")
    print(pin_to_one_core(), file=sys.stderr)
    data = Spec().to_dict()
    data["name"] = "separation_cost"
    data.setdefault("controller", {})["max_tracks"] = TRACKS
    solver_dir = generate(resolve_spec(data), out / "separation_cost", force=True)
    build(solver_dir)
    ctl = load(solver_dir).controller()
    samples: dict[int, list[float]] = {1: [], 0: []}
    recoveries: dict[int, int] = {1: 0, 0: 0}
    for r in range(rounds):
        for on in (1, 0):
            ctl.set_params(separation=on)
            for seed in range(SEEDS):
                loop = run_controller_loop(ctl, TRACKS, seed, STEPS)
                samples[on].extend(loop["step"])
                recoveries[on] += int(np.count_nonzero(np.asarray(loop["recovery"]) > 0))
        print(f"round {r + 1}/{rounds} done", file=sys.stderr)
    stats = {on: TimingStats.of(samples[on]) for on in (1, 0)}
    print(f"Controller step at {TRACKS} tracks, {rounds} rounds x {SEEDS} seeds x {STEPS} steps per setting:\n")
    print("| separation | mean [ms] | median [ms] | min [ms] | max [ms] | p99 [ms] | recovery SQPs |")
    print("|---|---|---|---|---|---|---|")
    for on in (1, 0):
        t = stats[on]
        print(f"| {'on' if on else 'off'} | {t.mean:.4f} | {t.median:.4f} | {t.min:.4f} | {t.max:.4f} | "
              f"{t.p99:.4f} | {recoveries[on]} |")
    on, off = stats[1], stats[0]
    print(f"| ratio on / off | {on.mean / off.mean:.3f} | {on.median / off.median:.3f} | {on.min / off.min:.3f} | "
          f"{on.max / off.max:.3f} | {on.p99 / off.p99:.3f} | |")


if __name__ == "__main__":
    main()
