"""Why the `mpc` planner orbits instead of waiting or going through (docs/evaluation.md, issue 23).

Runs one episode of the `mpc` planner (the built-in default spec's controller) and prints, once a
second, what the controller did: the robot's pose and speed, the carrot and the speed the OCP tracked,
the distance left, the stall timer, loop / recovery / stall flags, the nearest person, the
speed-and-separation bound along the robot's heading and along the straight line to the carrot, the
robot's heading off the carrot, the plan's end and the plan's goal terms (speed, position, terminal).

With a time T it stops at that period instead and prices the controller's plan against two plans a
robot could have made: turn to the carrot and drive to it at the bound's speed (at most v_ref), and
stop there. Every term of the OCP's cost is evaluated with the controller's parameters (the collision
potential on the people's constant-velocity predictions) and the bound's excess is reported.

    .venv/bin/python docs/orbit_analysis.py SCENARIO SEED [T]
    .venv/bin/python docs/orbit_analysis.py circle_crossing 169 13.0
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np

from humanmpc.eval.commands import choose_solver
from humanmpc.eval.episode import run_episode
from humanmpc.planners.interface import Observation, PlanResult
from humanmpc.planners.mpc import MPCPlanner
from humanmpc.planners.registry import make_planner
from humanmpc.sim.scenarios import make_scenario


def separation_speed(p: np.ndarray, heading: float, people: np.ndarray, velocities: np.ndarray,
                     params: dict[str, Any]) -> float:
    """monitor_separation_speed's bound (c_runtime/monitor.c) over people ahead of a robot at p."""
    c_t, s_t = np.cos(heading), np.sin(heading)
    d_h, t_r, a = params["d_h"], params["reaction_time"], -params["a_bounds"][0]
    best = np.inf
    for (hx, hy), (vx, vy) in zip(people, velocities, strict=True):
        dx, dy = hx - p[0], hy - p[1]
        if c_t * dx + s_t * dy <= 0.0:
            continue
        d = float(np.hypot(dx, dy))
        cos_phi = (c_t * dx + s_t * dy) / d
        c = max(-(vx * dx + vy * dy) / d, 0.0)
        alpha, beta, gamma = cos_phi / (2 * a), cos_phi * t_r + c / a, c * t_r - (d - d_h)
        best = min(best, 0.0 if gamma >= 0 else -2 * gamma / (beta + np.sqrt(beta * beta - 4 * alpha * gamma)))
    return best


def potential(d: np.ndarray, params: dict[str, Any]) -> np.ndarray:
    """The collision potential f(d) (codegen/ocp.py)."""
    q, d_th, k = params["q"], params["d_th"], params["kappa"]
    e = np.exp(-k * (np.maximum(d, d_th) - d_th))
    return np.where(d <= d_th, -(k * q / 4) * d + q / 2 + k * q * d_th / 4, q * e / (1 + e))


def plan_cost(x: np.ndarray, u: np.ndarray, g: np.ndarray, people: np.ndarray, velocities: np.ndarray,
              dt: float, params: dict[str, Any]) -> dict[str, float]:
    """The OCP's terms for the plan x (N + 1, 4), u (N, 2) and goal g, and the separation bound's excess."""
    w, wt, wu = np.asarray(params["w_goal"]), np.asarray(params["w_goal_terminal"]), np.asarray(params["w_control"])
    r = x[:-1] - g
    terms = {"speed": float(np.sum(w[3] * r[:, 3] ** 2)),
             "position": float(np.sum(w[0] * r[:, 0] ** 2 + w[1] * r[:, 1] ** 2 + w[2] * r[:, 2] ** 2)),
             "terminal": float(np.sum(wt * (x[-1] - g) ** 2)), "turn": float(np.sum(wu * u**2))}
    pot = 0.0
    for n in range(x.shape[0]):
        at = people + n * dt * velocities
        pot += float(potential(np.hypot(at[:, 0] - x[n, 0], at[:, 1] - x[n, 1]), params).sum())
    terms["potential"] = pot
    terms["total"] = sum(terms.values())
    excess = 0.0
    for n in range(1, x.shape[0]):
        at = people + (n - 1) * dt * velocities
        excess += max(x[n, 3] - separation_speed(x[n - 1, :2], x[n - 1, 2], at, velocities, params), 0.0)
    terms["bound excess"] = excess
    return terms


def to_carrot(x0: np.ndarray, g: np.ndarray, people: np.ndarray, velocities: np.ndarray, dt: float, n: int,
              cap: float, params: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """Turn on the spot to the carrot (braking first), then drive straight at min(cap, the bound)."""
    bearing = np.arctan2(g[1] - x0[1], g[0] - x0[0])
    bearing = x0[2] + (bearing - x0[2] + np.pi) % (2 * np.pi) - np.pi
    a_lo, a_hi = params["a_bounds"]
    w_lo, w_hi = params["omega_bounds"]
    x, u = np.zeros((n + 1, 4)), np.zeros((n, 2))
    x[0] = x0
    for k in range(n):
        s = x[k]
        err = bearing - s[2]
        at = people + k * dt * velocities
        speed = min(cap, separation_speed(s[:2], s[2], at, velocities, params)) if abs(err) < 0.3 else 0.0
        u[k] = np.clip((speed - s[3]) / dt, a_lo, a_hi), np.clip(err / dt, w_lo, w_hi)
        x[k + 1] = [s[0] + dt * s[3] * np.cos(s[2]), s[1] + dt * s[3] * np.sin(s[2]), s[2] + dt * u[k, 1],
                    max(s[3] + dt * u[k, 0], 0.0)]
    return x, u


def main() -> None:
    scenario, seed = sys.argv[1], int(sys.argv[2])
    at = float(sys.argv[3]) if len(sys.argv) > 3 else None
    planner = make_planner("mpc")
    assert isinstance(planner, MPCPlanner)
    params = planner.controller.params
    rows: list[str] = []
    moment: list[tuple[Observation, Any]] = []
    plan = planner.plan

    class StopError(Exception):
        """The period asked for has been reached."""

    def logged(obs: Observation) -> PlanResult:
        result = plan(obs)
        r = planner.last
        assert r is not None
        if at is not None and obs.time >= at - 1e-9:
            moment.append((obs, r))
            raise StopError
        if round(obs.time / obs.dt) % round(1.0 / obs.dt) == 0:
            x, g, p = obs.x, r.ocp_goal, r.plan
            to_g = np.arctan2(g[1] - x[1], g[0] - x[0])
            people = obs.humans_now
            near = float(np.min(np.hypot(*(people - x[:2]).T))) if len(people) else np.inf
            terms = plan_cost(p, r.controls, g, np.zeros((0, 2)), np.zeros((0, 2)), obs.dt, params)
            flags = "".join(f if on else "." for f, on in (("L", r.loop_detected), ("R", r.recovered),
                                                            ("S", r.stalled), ("P", r.stop)))
            rows.append(
                f"| {obs.time:.0f} | {x[0]:.2f}, {x[1]:.2f} | {np.degrees(x[2]):.0f} | {x[3]:.2f} "
                f"| {g[0]:.2f}, {g[1]:.2f} | {g[3]:.2f} | {r.distance_to_goal:.2f} | {r.time_without_progress:.1f} "
                f"| {flags} | {near:.2f} "
                f"| {separation_speed(x[:2], x[2], people, obs.humans_velocity, params):.2f} "
                f"| {separation_speed(x[:2], to_g, people, obs.humans_velocity, params):.2f} "
                f"| {np.degrees((x[2] - to_g + np.pi) % (2 * np.pi) - np.pi):.0f} | {p[-1, 0]:.2f}, {p[-1, 1]:.2f} "
                f"| {terms['speed']:.0f} | {terms['position']:.0f} | {terms['terminal']:.0f} |")
        return result

    planner.plan = logged
    try:
        log = run_episode(make_scenario(scenario, seed), planner, choose_solver(None, None))
    except StopError:
        log = None
    if at is None:
        assert log is not None
        print(f"{scenario} seed {seed}: {log.ended_by} at {log.times[-1]:.1f} s\n")
        print("| t [s] | robot [m] | heading [deg] | v [m/s] | carrot [m] | tracked v [m/s] | left [m] "
              "| no progress [s] | loop, recovered, stalled, stop | nearest [m] | bound ahead [m/s] "
              "| bound to carrot [m/s] | heading off carrot [deg] | plan's end [m] | speed term | position term "
              "| terminal term |")
        print("|" + "---|" * 17)
        print("\n".join(rows))
        return
    obs, r = moment[0]
    g = r.ocp_goal
    people, velocities = obs.humans_now, obs.humans_velocity
    # the controller's own state: its heading unwound like the carrot's (odometry's wraps at +-pi)
    print(f"{scenario} seed {seed} at t = {obs.time:.1f} s: robot {r.plan[0].round(2)}, carrot {g.round(2)}")
    for h, v in zip(people, velocities, strict=True):
        print(f"  person at {h.round(2)} walking {v.round(2)}, {np.hypot(*(h - obs.x[:2])):.2f} m away")
    n = r.controls.shape[0]
    candidates = [("the controller's plan", r.plan, r.controls)]
    for cap, name in ((params["v_ref"], "to the carrot at the bound's speed"), (0.0, "stop and wait")):
        candidates.append((name, *to_carrot(r.plan[0], g, people, velocities, obs.dt, n, cap, params)))
    print("\n| plan | speed | position | terminal | turn | potential | total | bound excess [m/s, summed] "
          "| end [m] |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|")
    for name, x, u in candidates:
        t = plan_cost(x, u, g, people, velocities, obs.dt, params)
        print(f"| {name} | {t['speed']:.0f} | {t['position']:.0f} | {t['terminal']:.0f} | {t['turn']:.0f} "
              f"| {t['potential']:.0f} | {t['total']:.0f} | {t['bound excess']:.2f} | {x[-1, 0]:.2f}, {x[-1, 1]:.2f} |")


if __name__ == "__main__":
    main()
