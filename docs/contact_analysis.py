"""Where the contacts of the recorded crossings happen (docs/evaluation.md, issue 23).

Runs the `mpc` planner (the built-in default spec's controller) over the recorded scenes' crossings
and prints one row per contact event (a person's entry within the contact distance, as the
evaluation counts them): the scene and crossing, the time, the fault (the evaluation's rule), the
robot's speed, the person's bearing from the robot's heading, the person's speed, the person's
distance one second earlier ("unseen" when they were not observed then) and the protective stops of
that second. Then the counts: events by fault, person-fault events with the robot standing, with a stop
in the last second, and with the person unseen a second before. Last, each crossing's closest approach
(what issue 23's median of the minimum distances is taken over): when, the robot's speed, the person's
bearing and speed, and whether the person had been observed in the period before ("appears": their
first observation is already the closest).

    .venv/bin/python docs/contact_analysis.py [SCENE ...]     # default: the three scenes, under a minute
    .venv/bin/python docs/contact_analysis.py --seeds 56 --deadline-ms 1000 \
        crowdnav_circle_20 crowdnav_square_20 crowdnav_square_10    # social force, held-out; about 1 min

Per scene it also prints the success rate and what it would be if contacts a person begins against a robot
at rest (|v| <= 0.05 m/s, the rule of fault's own threshold) did not count: the evaluation counts every
contact, and these are the contacts the robot cannot avoid once it must stand (someone within d_h).
"""

from __future__ import annotations

import argparse

import numpy as np

from humanmpc.eval.commands import choose_solver
from humanmpc.eval.episode import EpisodeLog, run_episode
from humanmpc.eval.metrics import MOVING_SPEED, compute_metrics, person_distances, rising_edges, robot_at_fault
from humanmpc.planners.registry import make_planner
from humanmpc.sim.scenarios import make_scenario

SCENES = ("biwi_eth", "biwi_hotel", "crowds_zara01")
CROSSINGS = 8  # crossings 0..7 of each scene: the ones issue 23 and the tables of docs/evaluation.md are on


def main() -> None:
    parser = argparse.ArgumentParser(description="Every contact of the `mpc` planner's episodes, and why.")
    parser.add_argument("scenes", nargs="*", default=list(SCENES), help="scenarios (default: the recorded three)")
    parser.add_argument("--seeds", type=int, default=CROSSINGS, help=f"episodes per scene (default {CROSSINGS})")
    parser.add_argument("--first-seed", type=int, default=0, help="the first seed (default 0)")
    parser.add_argument("--deadline-ms", type=float, default=None,
                        help="the controller's deadline [ms] (default: the spec's; 1000 makes a run load-proof)")
    args = parser.parse_args()
    scenes = args.scenes
    config = choose_solver(None, None)
    summaries: list[str] = []
    rows = []
    closest: list[str] = []
    print("| scene | crossing | t [s] | fault | robot speed [m/s] | bearing [deg] | person's speed [m/s] "
          "| distance 1 s before [m] | stops in that second |")
    print("|---|---:|---:|---|---:|---:|---:|---:|---|")
    for scene in scenes:
        successes = forgiven = 0
        for seed in range(args.first_seed, args.first_seed + args.seeds):
            planner = make_planner("mpc")
            if args.deadline_ms is not None:
                planner.controller.set_params(deadline_ms=args.deadline_ms)
            log = run_episode(make_scenario(scene, seed), planner, config)
            metrics = compute_metrics(log)
            only_at_rest = True  # every contact of the episode one a person began against the robot at rest
            touch = log.robot.radius + log.robot.human_radius  # the evaluation's contact distance
            distances = person_distances(log.states[:, :2], log.humans, log.present)
            contact = distances < touch
            fault = robot_at_fault(log.states, log.humans) & contact
            second = round(1.0 / log.dt)
            closest.append(closest_row(scene, seed, log, distances))
            for k in range(contact.shape[1]):
                for e in rising_edges(contact[:, k]):
                    x = log.states[e]
                    rel = log.humans[e, k] - x[:2]
                    bearing = (np.degrees(np.arctan2(rel[1], rel[0]) - x[2]) + 180.0) % 360.0 - 180.0
                    speed = (np.linalg.norm(log.humans[e, k] - log.humans[e - 1, k]) / log.dt
                             if e >= 1 and log.present[e - 1, k] else float("nan"))
                    b = max(e - second, 0)
                    before = (float(np.linalg.norm(log.humans[b, k] - log.states[b, :2]))
                              if log.present[b, k] else None)
                    stops = sorted({r for r in log.reasons[b:e] if r})
                    rows.append((bool(fault[e, k]), float(x[3]), before, bool(stops)))
                    only_at_rest &= not fault[e, k] and abs(x[3]) <= MOVING_SPEED
                    print(f"| {scene} | {seed} | {log.times[e]:.1f} | {'robot' if fault[e, k] else 'person'} "
                          f"| {x[3]:.2f} | {bearing:.0f} | {speed:.2f} "
                          f"| {'unseen' if before is None else f'{before:.2f}'} | {', '.join(stops) or '-'} |",
                          flush=True)
            successes += metrics.success
            forgiven += metrics.reached_goal and metrics.obstacle_collisions == 0 and only_at_rest
        summaries.append(f"| {scene} | {args.seeds} | {successes / args.seeds:.3f} | {forgiven / args.seeds:.3f} |")
    person = [r for r in rows if not r[0]]
    standing = [r for r in person if abs(r[1]) <= MOVING_SPEED]
    print(f"\ncontact events: {len(rows)} ({len(rows) - len(person)} robot's fault, {len(person)} the person's)")
    print(f"person's fault: robot standing in {len(standing)}, of which {sum(r[3] for r in standing)} with a "
          f"protective stop in the second before; person unseen a second before in "
          f"{sum(r[2] is None for r in person)}")
    print("\n| scene | crossing | min distance [m] | t [s] | robot speed [m/s] | bearing [deg] "
          "| person's speed [m/s] | observed the period before |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    print("\n".join(closest))
    print("\n| scene | episodes | success [fraction] | success if contacts a person began against a robot at rest "
          "did not count [fraction] |")
    print("|---|---:|---:|---:|")
    print("\n".join(summaries))


def closest_row(scene: str, seed: int, log: EpisodeLog, distances: np.ndarray) -> str:
    """The crossing's closest approach to anyone (distances: person_distances of the log), as a table row."""
    d = np.where(np.isfinite(distances), distances, np.inf)
    e, k = np.unravel_index(int(np.argmin(d)), d.shape)
    x = log.states[e]
    rel = log.humans[e, k] - x[:2]
    bearing = (np.degrees(np.arctan2(rel[1], rel[0]) - x[2]) + 180.0) % 360.0 - 180.0
    seen = e >= 1 and bool(log.present[e - 1, k])
    speed = f"{np.linalg.norm(log.humans[e, k] - log.humans[e - 1, k]) / log.dt:.2f}" if seen else "-"
    return (f"| {scene} | {seed} | {d[e, k]:.2f} | {log.times[e]:.1f} | {x[3]:.2f} | {bearing:.0f} | {speed} "
            f"| {'yes' if seen else 'no: appears'} |")


if __name__ == "__main__":
    main()
