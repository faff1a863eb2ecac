"""The controller step's worst case against its deadline: what the controller spends around the solver, and
whether a step that ends after params.deadline_ms is a protective stop. Prints one table (units in its
header) for docs/reliability.md. Run from the repository root after `make venv`:

    .venv/bin/python docs/controller_overhead.py [STEPS]

Worst-case inputs: every capacity full (256 path points, 32 tracks with covariances, 256 obstacle points),
people walking across the robot's way, the default spec's solver; deadline_ms = 2.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

import humanmpc
from humanmpc.codegen.build import build
from humanmpc.codegen.generate import generate
from humanmpc.codegen.spec import resolve_spec

DT = 0.1


def main(steps: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        out = generate(resolve_spec({"name": "overhead"}), Path(tmp) / "overhead", force=True, log=lambda _m: None)
        build(out, log=lambda _m: None)
        ctl = humanmpc.load(out).controller()
        ctl.set_params(deadline_ms=2.0)
        rng = np.random.default_rng(1)
        m, p, k = ctl.max_tracks, ctl.max_path_points, ctl.max_obstacle_points
        path = np.column_stack([np.linspace(0.0, 20.0, p), 0.5 * np.sin(np.linspace(0.0, 6.0, p))])
        total, around, late, late_stopped = [], [], 0, 0
        x = np.array([0.0, 0.0, 0.0, 0.0])
        for i in range(steps):
            if i % 200 == 0:
                ctl.reset()
                x[:] = 0.0
            people = np.column_stack([x[0] + rng.uniform(1.0, 8.0, m), rng.uniform(-4.0, 4.0, m),
                                      rng.uniform(-0.5, 0.5, m), rng.uniform(-1.2, 1.2, m)])
            cov = np.tile([0.05, 0.0, 0.05], (m, 1))
            walls = np.column_stack([np.linspace(x[0] - 2, x[0] + 10, k), np.where(np.arange(k) % 2, 2.5, -2.5)])
            r = ctl.step(i * DT, pose=x[:3], v=x[3], path=path, people=people, covariances=cov, obstacles=walls)
            total.append(r.time_ms)
            around.append(r.time_ms - r.time_solver_ms - r.time_recovery_ms)
            if r.time_ms > 2.0:
                late += 1
                late_stopped += bool(r.stop)
            v = float(r.command[0])
            x[2] += DT * float(r.command[1])
            x[0] += DT * v * np.cos(x[2])
            x[1] += DT * v * np.sin(x[2])
            x[3] = v
    t, a = np.array(total), np.array(around)
    print(f"{steps} controller steps, capacities full ({m} tracks, {p} path points, {k} obstacle points), "
          "deadline_ms = 2")
    print("| quantity | mean [ms] | median [ms] | p99 [ms] | max [ms] |")
    print("|---|---|---|---|---|")
    for name, v in (("whole controller step", t), ("around the solver (controller's own work)", a)):
        print(f"| {name} | {v.mean():.3f} | {np.median(v):.3f} | {np.percentile(v, 99):.3f} | {v.max():.3f} |")
    print(f"steps over the 2 ms deadline: {late}; of those a protective stop: {late_stopped}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 2000)
