"""How the evaluation's collision-cost height q was chosen (docs/evaluation.md, "The weights").

Runs the evaluation's MPC (MPCPlannerConfig()) with q in QS and the DWB baseline on the tuning seeds
100..119 (disjoint from the evaluation's seeds 0..19) and counts, for each q, the comparisons with the
DWB it wins or ties: 4 scenarios x {collisions <=, success >=, min distance to humans >=, time inside
d_th <=}. The q with the most wins is taken (ties: fewer collisions in total, then the smaller q).

    .venv/bin/python docs/q_selection.py [OUT_DIR]     # about 6 minutes with 2 workers
"""

from __future__ import annotations

import sys
from pathlib import Path

from humanmpc.evaluate import evaluate
from humanmpc.mpc_planner import MPCPlanner, MPCPlannerConfig, with_params
from humanmpc.registry import register_planner
from humanmpc.scenarios import SCENARIOS

QS = (2.0, 5.0, 10.0, 20.0, 50.0, 100.0)
SEEDS = list(range(100, 120))
BETTER = {"collisions": -1, "success": 1, "min_human_distance": 1, "time_within_dth": -1}


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/q_selection")
    names = []
    for q in QS:
        name = f"mpc_q{q:g}"
        config = with_params(MPCPlannerConfig(), q=q)
        register_planner(name, lambda c=config, n=name: MPCPlanner(config=c, name=n), replace=True)
        names.append(name)
    result = evaluate(sorted(SCENARIOS), [*names, "dwb"], SEEDS, out, workers=2, figures=False, progress=False)
    table = {(str(s["scenario"]), str(s["planner"])): s for s in result.summary}
    ranking = []
    print("| q | " + " | ".join(f"{sc} coll / succ / min d / t<d_th" for sc in sorted(SCENARIOS)) + " | wins |")
    for q, name in zip(QS, names, strict=True):
        wins, cells, total_collisions = 0, [], 0.0
        for sc in sorted(SCENARIOS):
            mine, dwb = table[(sc, name)], table[(sc, "dwb")]
            for metric, sign in BETTER.items():
                wins += int(sign * (float(mine[f"{metric}_mean"]) - float(dwb[f"{metric}_mean"])) >= -1e-12)
            total_collisions += float(mine["collisions_mean"])
            cells.append(" / ".join(f"{float(mine[f'{m}_mean']):.3g}" for m in BETTER))
        ranking.append((-wins, total_collisions, q))
        print(f"| {q:g} | " + " | ".join(cells) + f" | {wins} |")
    cells = [" / ".join(f"{float(table[(sc, 'dwb')][f'{m}_mean']):.3g}" for m in BETTER) for sc in sorted(SCENARIOS)]
    print("| dwb | " + " | ".join(cells) + " | |")
    print(f"chosen: q = {min(ranking)[2]:g}")


if __name__ == "__main__":
    main()
