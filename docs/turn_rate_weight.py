"""How the default weight on the turn rate (weights.control[1]) was chosen (docs/evaluation.md).

With no cost on omega, the real-time iteration (one QP per period) throws the turn rate between
opposite signs from one step to the next (5..8 % of the steps, |delta omega| > 2 rad/s, on the tuning
seeds). This runs the C controller with the spec's defaults but w_control = (0, w) for every w in
WEIGHTS on the tuning seeds 100..109 (disjoint from the evaluation's 0..19), with the Levenberg-Marquardt
term of the QP as the alternative damping, and prints per scenario the contact events, the runs that
reached the goal, the mean minimum distance to people, the mean time inside d_th, the mean time to the
goal, the flip rate and the freezing time. The smallest weight with flips below 1 % of the steps in
every scenario was taken: w = 2.

    .venv/bin/python docs/turn_rate_weight.py [OUT_DIR]     # about 10 minutes with 1 worker
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np

from humanmpc.eval.evaluate import evaluate
from humanmpc.planners.mpc import MPCPlanner
from humanmpc.planners.registry import register_planner
from humanmpc.sim.scenarios import SIMULATED_SCENARIOS

WEIGHTS = (0.0, 1.0, 2.0, 3.0, 10.0)
SEEDS = list(range(100, 110))


def configs() -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {f"w_omega_{w:g}": {"w_control": (0.0, w)} for w in WEIGHTS}
    for reg in (0.1, 1.0, 5.0):
        out[f"lm_{reg:g}".replace(".", "p")] = {"w_control": (0.0, 0.0), "regularization": reg}
    return out


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/turn_rate_weight")
    runs = configs()
    for name, params in runs.items():
        register_planner(name, lambda p=params, n=name: MPCPlanner(params=p, name=n), replace=True)
    result = evaluate(list(SIMULATED_SCENARIOS), list(runs), SEEDS, out, workers=1, figures=False, progress=False)
    print("| config | scenario | contacts | reached | min d [m] | t < d_th [s] | time to goal [s] | flips [%] "
          "| freezing [s] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name in runs:
        for sc in SIMULATED_SCENARIOS:
            rows = [r for r in result.rows if r["planner"] == name and r["scenario"] == sc]

            def mean(key: str, rows: list[Any] = rows) -> float:
                return float(np.nanmean([float(r[key]) for r in rows]))

            print(f"| {name} | {sc} | {sum(int(r['collisions']) for r in rows)} | "
                  f"{sum(bool(r['reached_goal']) for r in rows)} | {mean('min_human_distance'):.3f} | "
                  f"{mean('time_within_dth'):.2f} | {mean('time_to_goal'):.1f} | {100 * mean('omega_flip_rate'):.2f} | "
                  f"{mean('freezing_time'):.2f} |")


if __name__ == "__main__":
    main()
