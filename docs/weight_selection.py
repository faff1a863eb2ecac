"""How the evaluation's speed-tracking weight and collision-cost height were chosen (docs/evaluation.md).

Runs the evaluation's MPC (the C controller with the spec's defaults, everything but the two weights)
for every w_v (the stage weight on (v - v_ref)^2, w_goal[3]; the paper's 250) in W_SPEED and every q
(the height of the collision potential; the paper's 2) in QS, and the DWB baseline, on the tuning
seeds 100..139 (disjoint from the evaluation's seeds 0..19). For each pair it counts the comparisons
with the DWB it wins or ties: 4 scenarios x {collisions <=, goal reached >=, min distance to humans >=,
time inside d_th <=}. The pair with the most is taken; ties: fewer contact events in total, then more
goals reached, then the paper's side (larger w_v, then smaller q).

    .venv/bin/python docs/weight_selection.py [OUT_DIR]     # about 10 minutes with 2 workers
"""

from __future__ import annotations

import sys
from pathlib import Path

from humanmpc.eval.evaluate import evaluate
from humanmpc.planners.mpc import MPCPlanner
from humanmpc.planners.registry import register_planner
from humanmpc.sim.scenarios import SIMULATED_SCENARIOS as SCENARIOS

W_SPEED = (250.0, 100.0, 50.0, 25.0)
QS = (20.0, 50.0, 100.0)
SEEDS = list(range(100, 140))
BETTER = {"collisions": -1, "reached_goal": 1, "min_human_distance": 1, "time_within_dth": -1}


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/weight_selection")
    w_goal = (0.5, 0.5, 0.0)
    names: dict[str, tuple[float, float]] = {}
    for w in W_SPEED:
        for q in QS:
            name = f"mpc_w{w:g}_q{q:g}"
            params = {"w_goal": (*w_goal, w), "q": q}
            register_planner(name, lambda p=params, n=name: MPCPlanner(params=p, name=n), replace=True)
            names[name] = (w, q)
    result = evaluate(sorted(SCENARIOS), [*names, "dwb"], SEEDS, out, workers=2, figures=False, progress=False)
    table: dict[tuple[str, str], dict[str, float]] = {}
    for row in result.rows:
        cell = table.setdefault((str(row["scenario"]), str(row["planner"])), {k: 0.0 for k in BETTER})
        for metric in BETTER:
            cell[metric] += float(row[metric]) / len(SEEDS)
    ranking = []
    print("| w_v | q | " + " | ".join(f"{sc}: contacts / reached / min d / t<d_th" for sc in sorted(SCENARIOS))
          + " | wins or ties |")
    print("|---|---|" + "---|" * len(SCENARIOS) + "---|")
    for name, (w, q) in names.items():
        wins, cells, contacts, reached = 0, [], 0.0, 0.0
        for sc in sorted(SCENARIOS):
            mine, dwb = table[(sc, name)], table[(sc, "dwb")]
            wins += sum(int(sign * (mine[m] - dwb[m]) >= -1e-12) for m, sign in BETTER.items())
            contacts += mine["collisions"]
            reached += mine["reached_goal"]
            cells.append(" / ".join(f"{mine[m]:.3g}" for m in BETTER))
        ranking.append(((-wins, round(contacts, 9), -round(reached, 9), -w, q), name))
        print(f"| {w:g} | {q:g} | " + " | ".join(cells) + f" | {wins} |")
    cells = [" / ".join(f"{table[(sc, 'dwb')][m]:.3g}" for m in BETTER) for sc in sorted(SCENARIOS)]
    print("| dwb | | " + " | ".join(cells) + " | |")
    w, q = names[min(ranking)[1]]
    print(f"chosen: w_v = {w:g}, q = {q:g}")


if __name__ == "__main__":
    main()
