"""The main job (make demo): the paper's "crossing group" scenario with the MPC and the DWB baseline
(any other registered scenario by name, e.g. a recorded crowd).

Takes the MPC planners' solver chosen for this process (``humanmpc.planners.solver_cache``: by default the
built-in default spec's, generated and built into the tools' cache when it is not there yet), runs the
planners on the same seeded scenario (the MPC in the evaluation's configuration and in the paper's,
docs/evaluation.md, and the DWB), prints their metrics side by side and a timing summary, and writes
the figure.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..planners.registry import make_planner
from ..planners.solver_cache import ensure_solver
from ..sim.scenarios import make_scenario
from .episode import EpisodeConfig, EpisodeLog, run_episode
from .metrics import compute_metrics, with_unit
from .plots import plot_episodes

SCENARIO = "crossing_group"  # the default; any registered scenario by name
PLANNERS = ("mpc", "mpc_paper", "dwb")


def _fmt(value: object) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return "n/a" if np.isnan(value) else f"{value:.3g}"
    return str(value)


def side_by_side(rows: Mapping[str, Mapping[str, object]]) -> str:
    names = list(rows)
    keys = [k for k in rows[names[0]] if k not in ("scenario", "seed", "planner")]
    labels = {k: with_unit(k) for k in keys}
    width = max(len(label) for label in [*labels.values(), "metric [unit]"])
    lines = [f"{'metric [unit]':<{width}}  " + "  ".join(f"{n:>12}" for n in names)]
    lines.append("-" * len(lines[0]))
    for k in keys:
        lines.append(f"{labels[k]:<{width}}  " + "  ".join(f"{_fmt(rows[n].get(k)):>12}" for n in names))
    return "\n".join(lines)


def timing_summary(logs: dict[str, EpisodeLog]) -> str:
    lines = ["planner time per control step [ms]: mean / median / p99 / max over the episode"]
    for name, log in logs.items():
        t = log.solve_ms
        lines.append(f"  {name:>9}: {t.mean():.3f} / {np.median(t):.3f} / {np.percentile(t, 99):.3f} / "
                     f"{t.max():.3f}  ({t.size} steps)")
    return "\n".join(lines)


def run_demo(seed: int = 0, out_dir: Path = Path("out/demo"), scenario_name: str = SCENARIO,
             config: EpisodeConfig | None = None) -> Path:
    """The demo with the chosen solver; ``config``: the episodes' settings."""
    say = lambda m: print(m, file=sys.stderr)  # noqa: E731
    started = time.perf_counter()
    scenario = make_scenario(scenario_name, seed)  # a wrong name or seed fails before the solver is built
    solver_dir = ensure_solver()
    say(f"[demo] solver: {solver_dir}")
    logs: dict[str, EpisodeLog] = {}
    for name in PLANNERS:
        planner = make_planner(name)
        say(f"[demo] {scenario_name} seed {seed}: running {name} ...")
        logs[name] = run_episode(scenario, planner, config)
    rows = {name: compute_metrics(log).as_row() for name, log in logs.items()}
    crowd = "recorded people" if scenario.recorded else f"{(config or EpisodeConfig()).crowd_model} crowd"
    print(f"\n{scenario_name}, seed {seed}: HuMAN-MPC (generated C, SQP-RTI) vs the DWB baseline")
    print("mpc: the evaluation's configuration (global-path carrot, loop restart, exact-Hessian RTI, "
          "q = 50, w_v = 50, ...); "
          "mpc_paper: the paper's parameters and the final goal (docs/evaluation.md)\n")
    print(side_by_side(rows))
    print()
    print(timing_summary(logs))
    figure = plot_episodes(list(logs.values()), Path(out_dir) / f"{scenario_name}_seed{seed}.png",
                           title=f"{scenario_name}, {crowd}, seed {seed}: the MPC (evaluation's configuration), "
                           "the MPC in the paper's configuration, the DWB baseline")
    print(f"\nfigure: {figure.resolve()}")
    say(f"[demo] done in {time.perf_counter() - started:.1f} s")
    return figure
