"""The cumulative ablation of the C controller (docs/evaluation.md), on the evaluation's seeds.

Starts from the paper's configuration (``MPCPlanner.paper``: its weights, Gauss-Newton, the goal pose
alone) and adds the controller's parts one at a time, ending at the spec's defaults (registered as
"mpc"); prints, per step and scenario, the contact events, the runs that reached the goal, the mean
minimum distance to humans, the mean time inside d_th and the mean time to the goal, and the same for
the DWB. Nothing here is chosen: the settings were fixed before (docs/weight_selection.py, seeds
100..139).

    .venv/bin/python docs/ablation.py [OUT_DIR]     # about 3 minutes with 2 workers
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np

from humanmpc.eval.evaluate import evaluate
from humanmpc.planners.mpc import MPCPlanner, paper_params
from humanmpc.planners.registry import register_planner
from humanmpc.sim.scenarios import SIMULATED_SCENARIOS as SCENARIOS

SEEDS = list(range(20))


def steps() -> dict[str, tuple[dict[str, Any], bool]]:
    """Each step: the runtime parameters that differ from the defaults, and whether the path is given."""
    paper = paper_params()
    def without(*keys: str) -> dict[str, Any]:
        return {k: v for k, v in paper.items() if k not in keys}
    return {
        "paper": (paper, False),
        "path": (without(), True),
        "speed_limit": (without("speed_limit", "lookahead"), True),
        "exact_hessian_slack": (without("speed_limit", "lookahead", "exact_hessian", "slack_l1"), True),
        "weights": (without("speed_limit", "lookahead", "exact_hessian", "slack_l1", "q", "w_goal"), True),
        "approach_loop": (without("speed_limit", "lookahead", "exact_hessian", "slack_l1", "q", "w_goal",
                                  "approach", "loop_ratio"), True),
        "defaults": ({}, True),
    }


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/ablation")
    configs = steps()
    for name, (params, path) in configs.items():
        register_planner(name, lambda p=params, g=path, n=name: MPCPlanner(params=p, global_path=g, name=n),
                         replace=True)
    result = evaluate(sorted(SCENARIOS), [*configs, "dwb"], SEEDS, out, workers=2, figures=False, progress=False)
    print("| step | " + " | ".join(sorted(SCENARIOS)) + " |")
    print("|---|" + "---|" * len(SCENARIOS))
    for name in [*configs, "dwb"]:
        cells = []
        for sc in sorted(SCENARIOS):
            rows = [r for r in result.rows if r["scenario"] == sc and r["planner"] == name]
            ttg = np.array([float(r["time_to_goal"]) for r in rows])
            cells.append(
                f"{sum(int(r['collisions']) for r in rows)} / {sum(bool(r['reached_goal']) for r in rows)} / "
                f"{np.mean([float(r['min_human_distance']) for r in rows]):.2f} / "
                f"{np.mean([float(r['time_within_dth']) for r in rows]):.1f} / "
                f"{np.nanmean(ttg) if np.isfinite(ttg).any() else float('nan'):.1f}"
            )
        print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
