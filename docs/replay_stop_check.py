"""Someone within d_h always stops the robot, on the recorded crowds: runs the `mpc` planner (the built-in
default spec's controller) over every recorded crossing (32 per scene) and counts the control steps at
which a person is within d_h of the robot and the steps among them without a protective stop (the
controller's decision of that step, from the state and people of that step). A second count: the periods
at whose end someone is within d_h of a robot that stood (below 0.05 m/s) through it with no stop in
force: a person who walked in after the decision (the next period's decision sees them). Prints one table
for docs/reliability.md. From the repository root after `make venv`, with the pedestrian data
(HUMANMPC_PEDESTRIANS or ../shared/data/pedestrians):

    .venv/bin/python docs/replay_stop_check.py [SCENE ...]      # default: the three scenes, a few minutes
"""

from __future__ import annotations

import sys
import time

import numpy as np

from humanmpc.eval.commands import choose_solver
from humanmpc.eval.episode import run_episode
from humanmpc.eval.metrics import person_distances
from humanmpc.planners.registry import make_planner
from humanmpc.sim.scenarios import RECORDED_CROSSINGS, make_scenario

SCENES = ("biwi_eth", "biwi_hotel", "crowds_zara01")


def main() -> None:
    scenes = sys.argv[1:] or list(SCENES)
    config = choose_solver(None, None)
    planner = make_planner("mpc")
    d_h = planner.controller.params["d_h"]
    print(f"| scene | crossings | control steps | steps with someone within d_h = {d_h} m | of those without a "
          "stop | walked within d_h of a standing robot during a period | closest approach [m] |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    total_close = total_open = 0
    for scene in scenes:
        steps = close = unstopped = walked_in = 0
        closest = np.inf
        start = time.monotonic()
        for seed in range(RECORDED_CROSSINGS):
            log = run_episode(make_scenario(scene, seed), planner, config)
            d = person_distances(log.states[:, :2], log.humans, log.present)  # (T + 1, K), inf where absent
            nearest = d[:-1].min(axis=1) if d.shape[1] else np.full(len(log.stops), np.inf)
            within = nearest < d_h
            after = d[1:].min(axis=1) if d.shape[1] else np.full(len(log.stops), np.inf)
            walked_in += int(((after < d_h) & ~within & ~log.stops & (np.abs(log.states[:-1, 3]) < 0.05)).sum())
            steps += len(log.stops)
            close += int(within.sum())
            unstopped += int((within & ~log.stops).sum())
            closest = min(closest, float(nearest.min()) if len(nearest) else np.inf)
            print(f"  {scene} crossing {seed}: {len(log.stops)} steps, {int(within.sum())} within d_h, "
                  f"{int((within & ~log.stops).sum())} without a stop ({time.monotonic() - start:.0f} s)",
                  file=sys.stderr)
        total_close += close
        total_open += unstopped
        print(f"| {scene} | {RECORDED_CROSSINGS} | {steps} | {close} | {unstopped} | {walked_in} | {closest:.2f} |")
    print(f"all scenes: {total_close} steps with someone within d_h, {total_open} without a stop")


if __name__ == "__main__":
    main()
