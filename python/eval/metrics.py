"""Social-navigation metrics of one episode.

Definitions (distances to humans are centre-to-centre, robot centre to human centre):

* collision with a human: centre distance < robot radius + human radius; with an obstacle:
  signed distance of the robot centre < robot radius. A collision *event* is an entry into
  contact (a rising edge over the logged samples; contact at the first sample counts). Only
  the people present at a sample count (the log's ``present`` mask; recorded crowds change);
* whose fault a contact with a human is: the robot's when, at that sample, it moves (|v| >
  0.05 m/s) with the person strictly within +-90 degrees of its direction of travel (its
  heading; it never reverses with the evaluation's limits, v >= 0), i.e. its velocity has a
  positive component towards the person; otherwise the person's (they walked into a robot that
  stood, or that moved away from or past them). *Events* are counted per person (one person's
  entry into contact; two people touched at once are two events) and attributed at their first
  sample; ``human_collisions`` counts entries into contact with anyone, so it is at most the sum
  of the two. *Steps* are logged samples (one per control period, the final state included) in
  contact with someone: the robot's fault if it is at fault towards anyone it touches, else
  the people's; the two step counts add up to the samples in contact with a human;
* freezing (no progress towards the goal for more than 5 s): the distance d from the robot's
  centre to the goal position is tracked against a reference, at first d at the start; *progress*
  is a sample at which d is at least 0.1 m below the reference, which then becomes that d (so
  progress means coming 0.1 m closer to the goal than the robot has been since its last
  progress: standing, creeping below 0.1 m per 5 s, circling or backing off are not progress).
  Every stretch between consecutive progress samples (and from the last one to the episode's
  end) that lasts more than 5 s is a freezing event; ``freezing_time`` is their total length;
* success: the goal was reached within the time limit with no collision event at all;
* time inside a distance band: ``dt`` times the number of control intervals whose starting
  sample has the nearest human in that band; ``intimate`` is d < 0.45 m, ``personal`` is
  0.45 m <= d < 1.2 m and ``social`` is 1.2 m <= d < 3.6 m (Hall's proxemic zones, on the centre
  distance d), ``within_dth`` is d < d_th (1.0 m); seconds;
* SPL (success weighted by path length, Anderson et al. 2018): ``success * l / max(p, l)`` with p the
  robot's path length and l the straight-line distance from its start to the goal's tolerance circle
  (``|start - goal| - goal_tolerance``): the shortest path when no obstacle stands between them, a
  lower bound otherwise (so SPL is pessimistic in cluttered scenes); 0..1;
* minimum time to collision (s): at every sample and for every person present, the time until the
  robot's disc and the person's would touch (centre distance robot radius + human radius) if both
  kept their velocities: the robot's ``v (cos theta, sin theta)``, the person's the backward
  difference of their last two logged positions (what a tracker sees; 0 at their first sample); 0
  in contact; the minimum over the episode, capped at ``TTC_CAP`` = 10 s (never on a collision
  course within 10 s reads 10 s);
* the people's disturbance, in crowds that react to the robot (simulated ones; NaN for recorded
  people, who do not): at every step the crowd model's velocity v of every person is compared with
  v0, the velocity the same model gives them over the same step from the same state without the
  robot (:attr:`EpisodeLog.undisturbed_velocities`). ``people_speed_change`` is the sum over the
  steps and people of ``| |v| - |v0| |`` (m/s: the speed changes the robot caused, in total), and
  ``people_heading_change`` the sum of the angle between v and v0 where both are faster than
  0.05 m/s (rad: the turning it caused, in total). A person the robot slowed from 1.2 to 0.4 m/s
  over a few steps adds 0.8 m/s, one it turned by 30 degrees adds 0.52 rad;
* protective stops: events (rising edges of the planner's ``stop`` flag), counted per reason
  of the first step of each event, and the time spent in protective stop (``stop_time``: dt
  times the control steps whose planner result was a stop);
* path irregularity (SocNavBench, after Guzzi et al. 2013): the sum over the logged samples of
  the absolute angle between the robot's heading and the direction to the goal, divided by
  the path length (rad/m; it depends on the sampling period, 0.1 s here; a sample exactly on
  the goal, where the direction is undefined, is skipped);
* jerk (SocNavBench "average jerk"): the mean norm of the third finite difference of the
  robot positions divided by dt^3 (m/s^3);
* turn-rate flips: the fraction of control steps whose applied turn rate omega differs from the
  previous step's by more than 2 rad/s (``omega_flip_rate``, 0..1; the first step has no previous
  one and counts as no flip); a Gauss-Newton RTI far from its goal throws omega between its bounds;
* planner time: mean, 99th percentile (linear interpolation) and maximum of the per-step
  planner time in ms.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field

import numpy as np
from numpy.typing import NDArray

from .episode import EpisodeLog

FloatArray = NDArray[np.float64]

INTIMATE = 0.45  # m, Hall's zones on the centre distance
PERSONAL = 1.2
SOCIAL = 3.6
TTC_CAP = 10.0  # s: a longer time to collision reads as this
DISTURBED_SPEED = 0.05  # m/s: below it a person's walking direction is not compared
D_TH = 1.0
MOVING_SPEED = 0.05  # m/s: above it the robot moves (contact attribution)
FREEZE_TIME = 5.0  # s without progress that make a freezing event
FREEZE_PROGRESS = 0.1  # m closer to the goal that make progress
OMEGA_FLIP = 2.0  # rad/s: a larger change of the turn rate between two steps is a flip


@dataclass(frozen=True)
class EpisodeMetrics:
    success: bool
    reached_goal: bool
    timeout: bool
    collisions: int
    human_collisions: int
    obstacle_collisions: int
    collision_time: float
    robot_fault_contacts: int
    person_fault_contacts: int
    robot_fault_steps: int
    person_fault_steps: int
    time_to_goal: float
    path_length: float
    spl: float
    min_human_distance: float
    min_time_to_collision: float
    time_within_dth: float
    time_intimate: float
    time_personal: float
    time_social: float
    protective_stops: int
    stop_time: float
    freezing_events: int
    freezing_time: float
    path_irregularity: float
    mean_jerk: float
    omega_flip_rate: float
    planner_ms_mean: float
    planner_ms_p99: float
    planner_ms_max: float
    people_speed_change: float
    people_heading_change: float
    stops_by_reason: dict[str, int] = field(default_factory=dict)

    def as_row(self) -> dict[str, float | int | bool | str]:
        """Flat mapping for tables (stops_by_reason as ``stops[reason]`` columns)."""
        row: dict[str, float | int | bool | str] = {k: v for k, v in asdict(self).items() if k != "stops_by_reason"}
        for reason, count in sorted(self.stops_by_reason.items()):
            row[f"stops[{reason}]"] = count
        return row


# The unit of every column of :meth:`EpisodeMetrics.as_row`, for the tables' headers ("yes/no": a flag;
# "events": entries into a state, counted; "steps": control periods of 0.1 s).
UNITS: dict[str, str] = {
    "success": "yes/no", "reached_goal": "yes/no", "timeout": "yes/no",
    "collisions": "events", "human_collisions": "events", "obstacle_collisions": "events", "collision_time": "s",
    "robot_fault_contacts": "events", "person_fault_contacts": "events",
    "robot_fault_steps": "steps", "person_fault_steps": "steps",
    "time_to_goal": "s", "path_length": "m", "spl": "0..1", "min_human_distance": "m",
    "min_time_to_collision": "s", "time_within_dth": "s", "time_intimate": "s", "time_personal": "s",
    "time_social": "s", "protective_stops": "events", "stop_time": "s", "freezing_events": "events",
    "freezing_time": "s", "path_irregularity": "rad/m", "mean_jerk": "m/s^3", "omega_flip_rate": "0..1",
    "planner_ms_mean": "ms", "planner_ms_p99": "ms", "planner_ms_max": "ms",
    "people_speed_change": "m/s", "people_heading_change": "rad",
}


def unit(column: str) -> str:
    """The unit of a metric column (``stops[reason]`` columns count events); KeyError for an unknown one."""
    return "events" if column.startswith("stops[") else UNITS[column]


def with_unit(column: str) -> str:
    """``time_social [s]``: a column's name with its unit, for a table's header."""
    return f"{column} [{unit(column)}]"


def rising_edges(flags: NDArray[np.bool_]) -> NDArray[np.int64]:
    """Indices where a boolean series switches on (index 0 if it starts on)."""
    f = np.asarray(flags, dtype=bool)
    if f.size == 0:
        return np.zeros(0, dtype=np.int64)
    prev = np.concatenate([[False], f[:-1]])
    return np.nonzero(f & ~prev)[0]


def path_length(positions: FloatArray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(positions, axis=0), axis=1)))


def person_distances(robot_xy: FloatArray, humans: FloatArray, present: NDArray[np.bool_] | None = None) -> FloatArray:
    """Distance from the robot (T, 2) to every person (T, K, 2) at every sample, (T, K); inf
    where the person is absent (``present`` False; None: everyone is present)."""
    d = np.linalg.norm(humans - robot_xy[:, None, :], axis=-1)
    return d if present is None else np.where(present, d, np.inf)


def human_distances(robot_xy: FloatArray, humans: FloatArray, present: NDArray[np.bool_] | None = None) -> FloatArray:
    """Distance from the robot to the nearest human present at every sample (inf without one)."""
    if humans.shape[1] == 0:
        return np.full(robot_xy.shape[0], np.inf)
    return person_distances(robot_xy, humans, present).min(axis=1)


@dataclass(frozen=True)
class ContactFaults:
    """Contacts with humans by fault (definitions in the module docstring)."""

    robot_events: int
    person_events: int
    robot_steps: int
    person_steps: int


def robot_at_fault(states: FloatArray, humans: FloatArray) -> NDArray[np.bool_]:
    """(T, K): the robot moves (|v| > MOVING_SPEED) with person k strictly within +-90 degrees of
    its direction of travel, i.e. its velocity has a positive component towards the person."""
    heading = np.stack([np.cos(states[:, 2]), np.sin(states[:, 2])], axis=1)
    velocity = states[:, 3:4] * heading
    with np.errstate(invalid="ignore"):  # an absent person's NaN compares False
        towards = np.einsum("tk,tpk->tp", velocity, humans - states[:, None, :2]) > 0.0
    return towards & (np.abs(states[:, 3]) > MOVING_SPEED)[:, None]


def attribute_contacts(
    states: FloatArray, humans: FloatArray, present: NDArray[np.bool_] | None, contact_distance: float
) -> ContactFaults:
    """Contact events (per person) and contact samples with humans, by fault."""
    contact = person_distances(states[:, :2], humans, present) < contact_distance  # (T, K)
    fault = robot_at_fault(states, humans) & contact
    robot_events = person_events = 0
    for k in range(contact.shape[1]):
        edges = rising_edges(contact[:, k])
        at_fault = int(np.count_nonzero(fault[edges, k]))
        robot_events += at_fault
        person_events += edges.size - at_fault
    robot_step = fault.any(axis=1)
    person_step = contact.any(axis=1) & ~robot_step
    return ContactFaults(robot_events, person_events, int(np.count_nonzero(robot_step)),
                         int(np.count_nonzero(person_step)))


def freezing(
    times: FloatArray, positions: FloatArray, goal_xy: FloatArray,
    progress: float = FREEZE_PROGRESS, longest: float = FREEZE_TIME,
) -> tuple[int, float]:
    """Freezing events (stretches without progress longer than ``longest`` s) and their total
    length (s); progress as defined in the module docstring."""
    d = np.linalg.norm(positions - goal_xy[None, :], axis=1)
    marks = [0]
    reference = d[0]
    for i in range(1, d.size):
        if d[i] <= reference - progress:
            marks.append(i)
            reference = d[i]
    if marks[-1] != d.size - 1:
        marks.append(d.size - 1)
    gaps = np.diff(times[marks])
    frozen = gaps > longest
    return int(np.count_nonzero(frozen)), float(np.sum(gaps[frozen]))


def time_in_band(distances: FloatArray, lo: float, hi: float, dt: float) -> float:
    """dt times the intervals whose starting sample has lo <= d < hi (last sample excluded)."""
    d = distances[:-1]
    return float(dt * np.count_nonzero((d >= lo) & (d < hi)))


def spl(success: bool, positions: FloatArray, goal_xy: FloatArray, goal_tolerance: float) -> float:
    """Success weighted by path length (module docstring)."""
    shortest = max(float(np.linalg.norm(goal_xy - positions[0])) - goal_tolerance, 0.0)
    taken = path_length(positions)
    if not success:
        return 0.0
    return 1.0 if max(taken, shortest) == 0.0 else shortest / max(taken, shortest)


def time_to_collision(rel_pos: FloatArray, rel_vel: FloatArray, radius: float) -> FloatArray:
    """Time until two discs touch (centre distance ``radius``) at constant velocities, elementwise over
    (..., 2) relative positions and velocities: 0 if they touch already, inf if they never will."""
    c = np.sum(rel_pos * rel_pos, axis=-1) - radius**2
    a = np.sum(rel_vel * rel_vel, axis=-1)
    b = 2.0 * np.sum(rel_pos * rel_vel, axis=-1)
    disc = b * b - 4.0 * a * c
    approaching = (a > 0) & (b < 0) & (disc >= 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = (-b - np.sqrt(np.where(approaching, disc, 0.0))) / (2.0 * np.where(approaching, a, 1.0))
    return np.where(c <= 0, 0.0, np.where(approaching, t, np.inf))


def tracked_velocities(humans: FloatArray, present: NDArray[np.bool_], dt: float) -> FloatArray:
    """(T, K, 2): each person's backward-difference velocity, 0 where they were not there a sample before."""
    v = np.zeros_like(humans)
    both = present[1:] & present[:-1]
    v[1:] = np.where(both[..., None], (humans[1:] - humans[:-1]) / dt, 0.0)
    return v


def min_time_to_collision(states: FloatArray, humans: FloatArray, present: NDArray[np.bool_], dt: float,
                          contact_distance: float) -> float:
    """The smallest time to collision with anyone present over the episode, capped at TTC_CAP (s)."""
    if humans.shape[1] == 0 or not np.any(present):
        return TTC_CAP
    robot_v = states[:, 3:4] * np.stack([np.cos(states[:, 2]), np.sin(states[:, 2])], axis=1)
    rel_pos = np.where(present[..., None], humans - states[:, None, :2], 1e9)
    rel_vel = tracked_velocities(np.where(present[..., None], humans, 0.0), present, dt) - robot_v[:, None, :]
    ttc = np.where(present, time_to_collision(rel_pos, rel_vel, contact_distance), np.inf)
    return float(min(np.min(ttc), TTC_CAP))


def people_disturbance(velocities: FloatArray | None, undisturbed: FloatArray | None) -> tuple[float, float]:
    """Total speed change (m/s) and heading change (rad) the robot caused the people (module docstring);
    NaN, NaN for a crowd that does not react to the robot."""
    if velocities is None or undisturbed is None:
        return float("nan"), float("nan")
    v, v0 = velocities[1:], undisturbed[1:]
    s, s0 = np.linalg.norm(v, axis=-1), np.linalg.norm(v0, axis=-1)
    moving = (s > DISTURBED_SPEED) & (s0 > DISTURBED_SPEED)
    cross = v[..., 0] * v0[..., 1] - v[..., 1] * v0[..., 0]
    angle = np.where(moving, np.abs(np.arctan2(cross, np.sum(v * v0, axis=-1))), 0.0)  # exactly 0 for v = v0
    return float(np.sum(np.abs(s - s0))), float(np.sum(angle))


def path_irregularity(states: FloatArray, goal_xy: FloatArray) -> float:
    to_goal = goal_xy[None, :] - states[:, :2]
    dist = np.linalg.norm(to_goal, axis=1)
    defined = dist > 1e-6  # on the goal itself the direction to it is undefined
    heading = np.stack([np.cos(states[:, 2]), np.sin(states[:, 2])], axis=1)
    cos = np.sum(to_goal * heading, axis=1)[defined] / dist[defined]
    total = float(np.sum(np.arccos(np.clip(cos, -1.0, 1.0))))
    return total / (path_length(states[:, :2]) + 1e-10)


def mean_jerk(positions: FloatArray, dt: float) -> float:
    if positions.shape[0] < 4:
        return 0.0
    jerk = np.diff(positions, n=3, axis=0) / dt**3
    return float(np.mean(np.linalg.norm(jerk, axis=1)))


def omega_flip_rate(controls: FloatArray) -> float:
    """Fraction of the steps (rows of (a, omega) controls) whose omega jumps by more than OMEGA_FLIP."""
    if controls.shape[0] == 0:
        return 0.0
    flips = np.abs(np.diff(controls[:, 1])) > OMEGA_FLIP
    return float(np.count_nonzero(flips)) / controls.shape[0]


def timing_stats(solve_ms: FloatArray) -> tuple[float, float, float]:
    if solve_ms.size == 0:
        return (float("nan"),) * 3
    return float(np.mean(solve_ms)), float(np.percentile(solve_ms, 99)), float(np.max(solve_ms))


def stop_events(stops: NDArray[np.bool_], reasons: Sequence[str | None]) -> dict[str, int]:
    return dict(Counter(str(reasons[i] or "unspecified") for i in rising_edges(stops)))


def compute_metrics(log: EpisodeLog) -> EpisodeMetrics:
    """All metrics of one episode."""
    xy = log.states[:, :2]
    robot = log.robot
    d_h = human_distances(xy, log.humans, log.present)
    faults = attribute_contacts(log.states, log.humans, log.present, robot.radius + robot.human_radius)
    freezing_events, freezing_time = freezing(log.times, xy, log.goal[:2])
    human_contact = d_h < robot.radius + robot.human_radius
    obstacle_contact = log.world.signed_distance(xy) < robot.radius
    contact = human_contact | obstacle_contact
    h_events = len(rising_edges(human_contact))
    o_events = len(rising_edges(obstacle_contact))
    n_events = len(rising_edges(contact))
    mean_ms, p99_ms, max_ms = timing_stats(log.solve_ms)
    reasons = stop_events(log.stops, log.reasons)
    success = bool(log.reached_goal and n_events == 0)
    speed_change, heading_change = people_disturbance(log.human_velocities, log.undisturbed_velocities)
    return EpisodeMetrics(
        success=success,
        reached_goal=bool(log.reached_goal),
        timeout=log.ended_by == "time_limit",
        collisions=n_events,
        human_collisions=h_events,
        obstacle_collisions=o_events,
        collision_time=float(log.dt * np.count_nonzero(contact[:-1])),
        robot_fault_contacts=faults.robot_events,
        person_fault_contacts=faults.person_events,
        robot_fault_steps=faults.robot_steps,
        person_fault_steps=faults.person_steps,
        time_to_goal=float(log.times[-1]) if log.reached_goal else float("nan"),
        path_length=path_length(xy),
        spl=spl(success, xy, log.goal[:2], log.goal_tolerance),
        min_human_distance=float(np.min(d_h)),
        min_time_to_collision=min_time_to_collision(log.states, log.humans, log.present, log.dt,
                                                    robot.radius + robot.human_radius),
        time_within_dth=time_in_band(d_h, 0.0, D_TH, log.dt),
        time_intimate=time_in_band(d_h, 0.0, INTIMATE, log.dt),
        time_personal=time_in_band(d_h, INTIMATE, PERSONAL, log.dt),
        time_social=time_in_band(d_h, PERSONAL, SOCIAL, log.dt),
        protective_stops=int(sum(reasons.values())),
        stop_time=float(log.dt * np.count_nonzero(log.stops)),
        freezing_events=freezing_events,
        freezing_time=freezing_time,
        path_irregularity=path_irregularity(log.states, log.goal[:2]),
        mean_jerk=mean_jerk(xy, log.dt),
        omega_flip_rate=omega_flip_rate(log.controls),
        planner_ms_mean=mean_ms,
        planner_ms_p99=p99_ms,
        planner_ms_max=max_ms,
        people_speed_change=speed_change,
        people_heading_change=heading_change,
        stops_by_reason=reasons,
    )
