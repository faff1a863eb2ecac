"""The cumulative ablation of docs/evaluation.md ("What changed in round 2"), on the evaluation's seeds.

Starts from the first round's evaluation configuration and adds this round's changes one at a time,
ending at MPCPlannerConfig() (registered as "mpc"); prints, per step and scenario, the contact events,
the runs that reached the goal, the mean minimum distance to humans, the mean time inside d_th and the
mean time to the goal, and the same for the DWB. Nothing here is chosen: the settings were fixed
before (docs/weight_selection.py, seeds 100..139).

    .venv/bin/python docs/ablation.py [OUT_DIR]     # about 3 minutes with 2 workers
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from humanmpc.eval.evaluate import evaluate
from humanmpc.planners.mpc import MPCPlanner, MPCPlannerConfig, with_params
from humanmpc.planners.registry import register_planner
from humanmpc.sim.scenarios import SCENARIOS

SEEDS = list(range(20))
PAPER_W_GOAL = (0.5, 0.5, 0.0, 250.0)


def steps() -> dict[str, MPCPlannerConfig]:
    final = MPCPlannerConfig()
    round1 = replace(with_params(final, w_goal=PAPER_W_GOAL), path_humans=True, loop_restart=None,
                     approach_position=None, approach_stop=None)
    static_path = replace(round1, path_humans=False)
    restart = replace(static_path, loop_restart=final.loop_restart)
    approach = replace(restart, approach_position=final.approach_position, approach_stop=final.approach_stop)
    return {"round1": round1, "static_path": static_path, "loop_restart": restart, "approach": approach,
            "w_v50": final}


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/ablation")
    configs = steps()
    for name, config in configs.items():
        register_planner(name, lambda c=config, n=name: MPCPlanner(config=c, name=n), replace=True)
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
