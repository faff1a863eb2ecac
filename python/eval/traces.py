"""Per-step traces of episodes as Arrow tables (stored as Parquet by :mod:`humanmpc.eval.store`), and back.

One row per logged sample (T + 1 rows for T control steps), in order:

========================  =====================================================================
``key``                   the episode (:attr:`humanmpc.eval.campaign.EpisodeTask.key`)
``sample``, ``t``         sample index, time [s]
``x``, ``y``, ``theta``,  the robot's state [m, m, rad, m/s]
``v``
``a``, ``omega``          the control applied over the step from this sample [m/s^2, rad/s]
                          (null on the last sample, after which no step was taken)
``stop``, ``reason``      protective stop of that step and its reason (null on the last sample)
``solve_ms``              the planner's time for that step [ms]
``obstacle_x/_y``         the obstacle point the planner was given [m]
``people_id``             ids of the people present (list)
``people_x/_y``           their positions [m] (lists, in the order of ``people_id``)
``people_vx/_vy``,        reactive crowds only (else null): their velocities, and the velocities the
``people_vx0/_vy0``       crowd model would have given them without the robot [m/s]
========================  =====================================================================

:func:`trace_to_log` rebuilds the :class:`~humanmpc.eval.episode.EpisodeLog` (without the plans) from a
trace and its scenario, so metrics and figures can be made again from the stored results; the metrics
of the rebuilt log are those of the episode.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..sim.robot import RobotModel
from ..sim.scenarios import Scenario
from .episode import EpisodeLog
from .extras import arrow

if TYPE_CHECKING:
    import pyarrow as pa


def log_to_trace(key: str, log: EpisodeLog) -> pa.Table:
    """The per-step trace of ``log`` (module docstring)."""
    pa, _ = arrow()
    n = log.states.shape[0]
    ids = log.human_ids if log.human_ids is not None else np.arange(log.humans.shape[1], dtype=np.int64)
    present = log.present

    def per_sample(values: np.ndarray | None) -> list[list[float] | None]:
        if values is None:
            return [None] * n
        return [values[t][present[t]].tolist() for t in range(n)]

    def padded(values: np.ndarray, fill: Any = None) -> list[Any]:
        return [*values.tolist(), fill]

    vel, vel0 = log.human_velocities, log.undisturbed_velocities
    columns: dict[str, Any] = {
        "key": [key] * n,
        "sample": np.arange(n, dtype=np.int64),
        "t": log.times,
        "x": log.states[:, 0], "y": log.states[:, 1], "theta": log.states[:, 2], "v": log.states[:, 3],
        "a": padded(log.controls[:, 0]), "omega": padded(log.controls[:, 1]),
        "stop": padded(log.stops), "reason": [*log.reasons, None],
        "solve_ms": padded(log.solve_ms),
        "obstacle_x": padded(log.obstacle_points[:, 0]), "obstacle_y": padded(log.obstacle_points[:, 1]),
        "people_id": [ids[present[t]].tolist() for t in range(n)],
        "people_x": per_sample(log.humans[..., 0]), "people_y": per_sample(log.humans[..., 1]),
        "people_vx": per_sample(None if vel is None else vel[..., 0]),
        "people_vy": per_sample(None if vel is None else vel[..., 1]),
        "people_vx0": per_sample(None if vel0 is None else vel0[..., 0]),
        "people_vy0": per_sample(None if vel0 is None else vel0[..., 1]),
    }
    schema = pa.schema([
        ("key", pa.string()), ("sample", pa.int64()), ("t", pa.float64()), ("x", pa.float64()),
        ("y", pa.float64()), ("theta", pa.float64()), ("v", pa.float64()), ("a", pa.float64()),
        ("omega", pa.float64()), ("stop", pa.bool_()), ("reason", pa.string()), ("solve_ms", pa.float64()),
        ("obstacle_x", pa.float64()), ("obstacle_y", pa.float64()), ("people_id", pa.list_(pa.int64())),
        *((name, pa.list_(pa.float64())) for name in ("people_x", "people_y", "people_vx", "people_vy",
                                                       "people_vx0", "people_vy0")),
    ])
    return pa.table(columns, schema=schema)


def trace_to_log(trace: pa.Table, scenario: Scenario, planner: str, ended_by: str, dt: float,
                 robot: RobotModel | None = None) -> EpisodeLog:
    """The episode log of a stored trace (module docstring); ``scenario`` gives the world, goal and limits,
    ``dt`` is the control period [s]."""
    d = trace.sort_by("sample").to_pydict()
    n = len(d["sample"])
    ids = np.unique(np.concatenate([np.asarray(i, dtype=np.int64) for i in d["people_id"]] or
                                   [np.zeros(0, dtype=np.int64)]))
    humans = np.full((n, ids.size, 2), np.nan)
    present = np.zeros((n, ids.size), dtype=bool)
    reactive = d["people_vx"][0] is not None
    vel = np.zeros((n, ids.size, 2)) if reactive else None
    vel0 = np.zeros((n, ids.size, 2)) if reactive else None
    for t in range(n):
        col = np.searchsorted(ids, np.asarray(d["people_id"][t], dtype=np.int64))
        humans[t, col, 0], humans[t, col, 1] = d["people_x"][t], d["people_y"][t]
        present[t, col] = True
        if vel is not None and vel0 is not None:
            vel[t, col, 0], vel[t, col, 1] = d["people_vx"][t], d["people_vy"][t]
            vel0[t, col, 0], vel0[t, col, 1] = d["people_vx0"][t], d["people_vy0"][t]
    steps = n - 1
    return EpisodeLog(
        scenario=scenario.name, seed=scenario.seed, planner=planner, dt=dt,
        world=scenario.world, robot=robot or RobotModel(), goal=np.asarray(scenario.goal, dtype=float),
        goal_tolerance=scenario.goal_tolerance, time_limit=scenario.time_limit, times=np.asarray(d["t"]),
        states=np.column_stack([d["x"], d["y"], d["theta"], d["v"]]),
        humans=humans, controls=np.column_stack([d["a"][:steps], d["omega"][:steps]]).reshape(-1, 2),
        obstacle_points=np.column_stack([d["obstacle_x"][:steps], d["obstacle_y"][:steps]]).reshape(-1, 2),
        stops=np.asarray(d["stop"][:steps], dtype=bool), reasons=list(d["reason"][:steps]),
        solve_ms=np.asarray(d["solve_ms"][:steps], dtype=float), plans=[None] * steps,
        reached_goal=ended_by == "goal", ended_by=ended_by,
        present_mask=None if bool(np.all(present)) else present, human_ids=ids,
        human_velocities=vel, undisturbed_velocities=vel0,
    )
