"""Seeded, reproducible evaluation scenarios: simulated crowds and recorded ones.

Every scenario is a pure function of its seed and gives the world, the crowd, the robot's start
state and goal, and a time limit.

**Simulated** (``SIMULATED_SCENARIOS``; any seed, ``numpy.random.default_rng(seed)``): the crowd's
initial state and waypoints for the social force model. Humans start walking at their desired
speed towards their first waypoint and walk back and forth between their waypoints for the
whole episode (so the scene stays busy however long the robot needs). Desired walking speeds
are drawn from U(0.9, 1.3) m/s around the 1.1-1.3 m/s usually measured for people walking
indoors; the social force model caps the speed at 1.3 times the desired one (Helbing & Molnár).

**CrowdNav** (``CROWDNAV_SCENARIOS``: ``crowdnav_circle_N`` and ``crowdnav_square_N`` for N = 5, 10 and
20 people; any seed): CrowdNav's circle and square crossings (Chen et al. 2019): every person walks at
1 m/s from a random start to their own goal and stays there; the robot crosses from (0, -4) to (0, 4) m
within 30 s. Short episodes, for campaigns of thousands.

Simulated people move by a crowd model (:data:`CROWD_MODELS`, :meth:`Scenario.start_crowd`): the social
force model (:mod:`humanmpc.sim.crowd`, the default) or ORCA (:mod:`humanmpc.sim.orca`); the scenario
fixes where they start and go, the model how they walk there and react to each other and to the robot.

**Recorded** (``RECORDED_SCENARIOS``: ``biwi_eth``, ``biwi_hotel``, ``crowds_zara01``; seeds
``0..RECORDED_CROSSINGS - 1``): real pedestrians replayed as recorded, whatever the robot does
(:mod:`humanmpc.sim.recorded`), in an empty world whose bounds cover every annotated position
with a 1 m margin (the recordings have no static obstacles). The robot crosses the scene along
its main walking direction, the principal axis of all annotated positions, on the line through
their median: from the 10th to the 90th percentile of the positions along that axis (the part
of the scene people walk through), so a crossing is 10.7 m (hotel) to 13.5 m (eth) long. Seed ``s`` is crossing
``s``: start time ``s // 2``, direction ``s % 2`` (0: towards increasing position along the
axis, oriented so that its larger component is positive; 1: back). The first four start times
(crossings 0..7, the hardest, which the earliest measurements used) are one per quarter of the recording's
admissible starts (those that leave ``RECORDED_TIME_LIMIT`` of recording), the busiest in it: the
largest mean number of people present over the crossing's nominal duration (its length at v_ref,
sampled every 0.4 s), among the start times at which nobody is within 1 m of either end of the
crossing (ties: the earliest). The other twelve (crossings 8..31: rates with intervals rather
than counts over eight) are the busiest of those start times, taken in turn, that begin at least
one nominal duration after or before every start time already taken, so that no two crossings
of a scene start in the same crowd.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .crowd import Crowd, CrowdSpec, HumanCrowd
from .orca import OrcaCrowd, OrcaParams
from .recorded import ANNOTATION_PERIOD, RecordedCrowd, RecordedCrowdSpec, Recording, load_recording
from .social_force import SocialForceParams
from .world import Circle, Obstacle, Polygon, World

FloatArray = NDArray[np.float64]

V_REF = 0.8  # the robot's preferred cruising speed in every scenario (m/s)

CROWD_MODELS = ("social_force", "orca")  # how simulated people move (recorded people are replayed)


@dataclass(frozen=True)
class Scenario:
    """Everything an episode needs to start."""

    name: str
    seed: int
    world: World
    crowd: CrowdSpec | RecordedCrowdSpec  # simulated (social force) or recorded (replayed)
    robot_start: FloatArray  # [px, py, theta, v]
    goal: FloatArray  # [gx, gy, gtheta, v_ref]
    time_limit: float
    goal_tolerance: float = 0.3

    @property
    def recorded(self) -> bool:
        """Whether the people are replayed from a recording (they then ignore the robot and the crowd model)."""
        return isinstance(self.crowd, RecordedCrowdSpec)

    def start_crowd(self, social_force: SocialForceParams | None = None, model: str = "social_force",
                    orca: OrcaParams | None = None) -> HumanCrowd:
        """The crowd of a new episode: the simulated people moved by ``model`` (:data:`CROWD_MODELS`: the
        social force model run with ``social_force``, whose ``dt`` is the period of a step, or ORCA with
        ``orca``), or the recorded people replayed at that period whatever the model."""
        params = social_force or SocialForceParams()
        if isinstance(self.crowd, RecordedCrowdSpec):
            return RecordedCrowd(self.crowd, params.dt)
        if model == "social_force":
            return Crowd(self.crowd, self.world, params)
        if model == "orca":
            return OrcaCrowd(self.crowd, self.world, orca or OrcaParams(dt=params.dt))
        raise ValueError(f"unknown crowd model {model!r}; crowd models: {', '.join(CROWD_MODELS)}")


def _heading(a: FloatArray, b: FloatArray) -> float:
    d = b - a
    return float(np.arctan2(d[1], d[0]))


def _robot(start: FloatArray, goal: FloatArray) -> tuple[FloatArray, FloatArray]:
    th = _heading(start, goal)
    return np.array([start[0], start[1], th, 0.0]), np.array([goal[0], goal[1], th, V_REF])


def _walking(positions: FloatArray, first_goals: FloatArray, speeds: FloatArray) -> FloatArray:
    d = first_goals - positions
    return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9) * speeds[:, None]


def _sample_free(
    rng: np.random.Generator, world: World, lo: float, hi: float, clearance: float, avoid: list[FloatArray], sep: float
) -> FloatArray:
    for _ in range(10_000):
        p = rng.uniform(lo, hi, 2)
        if world.contains_free_disc(p, clearance) and all(np.linalg.norm(p - q) >= sep for q in avoid):
            return p
    raise RuntimeError("scenario sampling failed to place a point; the scene is too crowded for its area")


def random_crowded_cluttered(seed: int) -> Scenario:
    """The paper's scene: 10 humans between random start and goal points, 5 random static
    obstacles (discs and rotated boxes), robot start and goal on opposite sides of the area."""
    rng = np.random.default_rng(seed)
    half = 7.0
    phi = rng.uniform(-np.pi, np.pi)
    direction = np.array([np.cos(phi), np.sin(phi)])
    r_start, r_goal = -5.5 * direction, 5.5 * direction
    obstacles: list[Obstacle] = []
    centres: list[FloatArray] = []
    while len(obstacles) < 5:
        c = rng.uniform(-4.5, 4.5, 2)
        if min(np.linalg.norm(c - r_start), np.linalg.norm(c - r_goal)) < 2.0:
            continue
        if any(np.linalg.norm(c - q) < 2.2 for q in centres):
            continue
        if rng.uniform() < 0.5:
            obstacles.append(Circle((float(c[0]), float(c[1])), float(rng.uniform(0.3, 0.7))))
        else:
            w, h = rng.uniform(0.5, 1.5), rng.uniform(0.3, 1.0)
            obstacles.append(Polygon.rectangle((float(c[0]), float(c[1])), w, h, float(rng.uniform(0, np.pi))))
        centres.append(c)
    world = World(tuple(obstacles), (-half, half, -half, half))
    starts: list[FloatArray] = []
    goals: list[FloatArray] = []
    for _ in range(10):
        s = _sample_free(rng, world, -6.0, 6.0, 0.5, [*starts, r_start], 1.2)
        g = s
        while np.linalg.norm(g - s) < 5.0:
            g = _sample_free(rng, world, -6.0, 6.0, 0.5, [], 0.0)
        starts.append(s)
        goals.append(g)
    pos, gl = np.array(starts), np.array(goals)
    speeds = rng.uniform(0.9, 1.3, 10)
    crowd = CrowdSpec.build(
        pos, [np.stack([g, s]) for s, g in zip(pos, gl, strict=True)], speeds,
        velocities=_walking(pos, gl, speeds), loop=True,
    )
    x0, goal = _robot(r_start, r_goal)
    return Scenario("random_crowded_cluttered", seed, world, crowd, x0, goal, time_limit=60.0)


def crossing_group(seed: int) -> Scenario:
    """A group of 9 (3 x 3 formation) walking back and forth across the robot's way."""
    rng = np.random.default_rng(seed)
    world = World((), (-8.0, 8.0, -8.0, 8.0))
    r_start, r_goal = np.array([0.0, -6.0]), np.array([0.0, 6.0])
    spacing = 0.8
    offsets = np.array([[i * spacing, j * spacing] for i in (-1, 0, 1) for j in (-1, 0, 1)])
    offsets += rng.normal(0.0, 0.05, offsets.shape)
    y0 = rng.uniform(-1.0, 1.0)
    x0 = rng.uniform(-6.5, -3.0)
    sign = 1.0 if rng.uniform() < 0.5 else -1.0
    centre = np.array([sign * x0, y0])
    pos = centre + offsets
    far = np.array([-sign * 7.0, y0]) + offsets
    near = np.array([sign * 7.0, y0]) + offsets
    speed = rng.uniform(0.9, 1.1)
    speeds = speed + rng.uniform(-0.05, 0.05, 9)
    crowd = CrowdSpec.build(
        pos, [np.stack([f, n]) for f, n in zip(far, near, strict=True)], speeds,
        velocities=_walking(pos, far, speeds), loop=True, groups=[tuple(range(9))],
    )
    x_start, goal = _robot(r_start, r_goal)
    return Scenario("crossing_group", seed, world, crowd, x_start, goal, time_limit=60.0)


def circle_crossing(seed: int) -> Scenario:
    """8 humans on a circle of radius 4.5 m walking to the antipodes and back; the robot
    crosses the circle from south to north."""
    rng = np.random.default_rng(seed)
    world = World((), (-7.0, 7.0, -7.0, 7.0))
    radius = 4.5
    angles: list[float] = []
    while len(angles) < 8:
        a = rng.uniform(-np.pi, np.pi)
        if min(abs(np.angle(np.exp(1j * (a - b)))) for b in (np.pi / 2, -np.pi / 2)) < 0.5:
            continue
        if any(abs(np.angle(np.exp(1j * (a - b)))) < 0.3 for b in angles):
            continue
        angles.append(a)
    ang = np.array(angles)
    pos = radius * np.stack([np.cos(ang), np.sin(ang)], axis=1)
    goals = -pos + rng.normal(0.0, 0.2, pos.shape)
    speeds = rng.uniform(0.9, 1.3, 8)
    crowd = CrowdSpec.build(
        pos, [np.stack([g, s]) for s, g in zip(pos, goals, strict=True)], speeds,
        velocities=_walking(pos, goals, speeds), loop=True,
    )
    x0, goal = _robot(np.array([0.0, -radius]), np.array([0.0, radius]))
    return Scenario("circle_crossing", seed, world, crowd, x0, goal, time_limit=40.0)


def corridor(seed: int) -> Scenario:
    """A 3 m wide, 20 m long corridor; 5 people walk towards the robot and back."""
    rng = np.random.default_rng(seed)
    width, length, wall = 3.0, 20.0, 0.2
    walls = (
        Polygon.rectangle((0.0, width / 2 + wall / 2), length, wall),
        Polygon.rectangle((0.0, -width / 2 - wall / 2), length, wall),
    )
    world = World(walls, (-length / 2 - 0.5, length / 2 + 0.5, -width / 2 - 1.0, width / 2 + 1.0))
    starts: list[FloatArray] = []
    while len(starts) < 5:
        p = np.array([rng.uniform(1.0, 9.0), rng.uniform(-0.8, 0.8)])
        if all(np.linalg.norm(p - q) >= 1.0 for q in starts):
            starts.append(p)
    pos = np.array(starts)
    far = np.stack([np.full(5, -9.5), rng.uniform(-0.8, 0.8, 5)], axis=1)
    back = np.stack([np.full(5, 9.5), rng.uniform(-0.8, 0.8, 5)], axis=1)
    speeds = rng.uniform(0.9, 1.3, 5)
    crowd = CrowdSpec.build(
        pos, [np.stack([f, b]) for f, b in zip(far, back, strict=True)], speeds,
        velocities=_walking(pos, far, speeds), loop=True,
    )
    x0, goal = _robot(np.array([-8.5, 0.0]), np.array([8.5, 0.0]))
    return Scenario("corridor", seed, world, crowd, x0, goal, time_limit=60.0)


# CrowdNav's scenes (Chen et al. 2019, crowd_sim): people placed at random, each walking at 1 m/s to their
# own goal and stopping there; the robot crosses from (0, -4) to (0, 4). In 5, 10 and 20 people.
CROWDNAV_SIZES = (5, 10, 20)
CROWDNAV_RADIUS = 4.0  # m: the circle of the circle crossing (and the robot's start and goal distance)
CROWDNAV_SQUARE = 10.0  # m: the square of the square crossing
CROWDNAV_SPEED = 1.0  # m/s: every person's desired speed (CrowdNav's v_pref)
CROWDNAV_GAP = 0.7  # m between two people's starts, and two goals: 2 x 0.25 m radius + CrowdNav's 0.2 m discomfort
CROWDNAV_ROBOT_GAP = 1.2  # m between a person's start or goal and the robot's start or goal
CROWDNAV_TIME_LIMIT = 30.0  # s (CrowdNav: 25 s at 1 m/s; the robot cruises at 0.8 m/s here)


def _crowdnav_place(draw: Callable[[], FloatArray], taken: list[FloatArray], robot: list[FloatArray]) -> FloatArray:
    for _ in range(10_000):
        p = draw()
        if all(np.linalg.norm(p - q) >= CROWDNAV_GAP for q in taken) and \
                all(np.linalg.norm(p - q) >= CROWDNAV_ROBOT_GAP for q in robot):
            return p
    raise RuntimeError("CrowdNav scenario: no free place left for a person after 10,000 draws")


def _crowdnav_scenario(name: str, seed: int, starts: list[FloatArray], goals: list[FloatArray],
                       half: float) -> Scenario:
    pos = np.array(starts).reshape(-1, 2)
    crowd = CrowdSpec.build(pos, [g[None] for g in goals], CROWDNAV_SPEED)  # at rest, a final goal each
    x0, goal = _robot(np.array([0.0, -CROWDNAV_RADIUS]), np.array([0.0, CROWDNAV_RADIUS]))
    return Scenario(name, seed, World((), (-half, half, -half, half)), crowd, x0, goal,
                    time_limit=CROWDNAV_TIME_LIMIT)


def crowdnav_circle(people: int, seed: int) -> Scenario:
    """CrowdNav's circle crossing: ``people`` start on a circle of radius 4 m (each coordinate moved by
    U(-0.5, 0.5) m) and walk to the antipode of their start; starts at least 0.7 m from every other
    person's start and goal, 1.2 m from the robot's start and goal."""
    rng = np.random.default_rng(seed)
    robot = [np.array([0.0, -CROWDNAV_RADIUS]), np.array([0.0, CROWDNAV_RADIUS])]
    starts: list[FloatArray] = []

    def draw() -> FloatArray:
        angle = rng.uniform(0.0, 2 * np.pi)
        noise = rng.uniform(-0.5, 0.5, 2) * CROWDNAV_SPEED
        return CROWDNAV_RADIUS * np.array([np.cos(angle), np.sin(angle)]) + noise

    for _ in range(people):
        starts.append(_crowdnav_place(draw, [*starts, *(-q for q in starts)], robot))
    return _crowdnav_scenario(f"crowdnav_circle_{people}", seed, starts, [-q for q in starts],
                              CROWDNAV_RADIUS + 2.0)


def crowdnav_square(people: int, seed: int) -> Scenario:
    """CrowdNav's square crossing: each of ``people`` starts at random in one half of a 10 m square (left
    or right, at even odds) and walks to a random point of the other half; starts at least 0.7 m apart,
    goals too, both 1.2 m from the robot's start and goal."""
    rng = np.random.default_rng(seed)
    robot = [np.array([0.0, -CROWDNAV_RADIUS]), np.array([0.0, CROWDNAV_RADIUS])]
    w = CROWDNAV_SQUARE
    starts: list[FloatArray] = []
    goals: list[FloatArray] = []
    def in_half(side: float) -> Callable[[], FloatArray]:
        return lambda: np.array([rng.uniform() * w * 0.5 * side, (rng.uniform() - 0.5) * w])

    for _ in range(people):
        sign = -1.0 if rng.uniform() > 0.5 else 1.0
        starts.append(_crowdnav_place(in_half(sign), starts, robot))
        goals.append(_crowdnav_place(in_half(-sign), goals, robot))
    return _crowdnav_scenario(f"crowdnav_square_{people}", seed, starts, goals, w / 2 + 1.0)


RECORDED_CROSSINGS = 32  # per recorded scene: 16 start times x 2 directions
RECORDED_TIME_LIMIT = 60.0  # s
_START_TIMES = RECORDED_CROSSINGS // 2
_QUARTER_STARTS = 4  # the first start times, one per quarter of the recording (crossings 0..7)
_ENDS_QUANTILES = (0.10, 0.90)  # the crossing's ends, along the scene's main walking direction
_FREE_AT_ENDS = 1.0  # m: nobody this close to an end of the crossing at its start time
_WORLD_MARGIN = 1.0  # m around every annotated position


@dataclass(frozen=True)
class Crossings:
    """Where and when the robot crosses a recorded scene (module docstring)."""

    ends: FloatArray  # (2, 2): the crossing's two ends, direction 0 goes from ends[0] to ends[1]
    start_times: FloatArray  # (_START_TIMES,) recording times (s)
    bounds: tuple[float, float, float, float]

    def crossing(self, index: int) -> tuple[float, FloatArray, FloatArray]:
        """Start time (recording time, s), start and goal positions of crossing ``index``."""
        t0 = float(self.start_times[index // 2])
        a, b = self.ends if index % 2 == 0 else self.ends[::-1]
        return t0, a.copy(), b.copy()


def plan_crossings(recording: Recording, time_limit: float = RECORDED_TIME_LIMIT) -> Crossings:
    """The crossings of a recorded scene (the rule is in the module docstring); ``ValueError`` if
    the recording is too short or too crowded at its ends to give them."""
    pts = recording.annotations()
    if pts.shape[0] < 3:
        raise ValueError(f"{recording.name}: too few annotations ({pts.shape[0]}) to lay out a crossing")
    centre = np.median(pts, axis=0)
    _, vecs = np.linalg.eigh(np.cov((pts - pts.mean(axis=0)).T))
    axis = vecs[:, -1] * (1.0 if vecs[np.argmax(np.abs(vecs[:, -1])), -1] > 0 else -1.0)
    along = (pts - centre) @ axis
    lo, hi = np.quantile(along, _ENDS_QUANTILES)
    ends = np.stack([centre + lo * axis, centre + hi * axis])
    first, last = recording.duration
    latest = last - time_limit
    if latest < first:
        raise ValueError(f"{recording.name}: the recording lasts {last - first:.1f} s, shorter than the crossing's "
                         f"time limit {time_limit:.1f} s")
    n_cand = int(np.floor((latest - first) / ANNOTATION_PERIOD + 1e-9)) + 1
    candidates = np.round(first + ANNOTATION_PERIOD * np.arange(n_cand), 9)
    window = ANNOTATION_PERIOD * np.arange(int(np.ceil((hi - lo) / V_REF / ANNOTATION_PERIOD)) + 1)
    busy = recording.present(candidates[:, None] + window[None, :]).sum(axis=-1).mean(axis=-1)
    free = np.ones(candidates.shape, dtype=bool)
    for j, t in enumerate(candidates):
        _, pos = recording.at(float(t))
        if pos.shape[0]:
            free[j] = np.linalg.norm(pos[:, None, :] - ends[None], axis=-1).min() >= _FREE_AT_ENDS
    starts: list[float] = []
    for block in np.array_split(np.arange(candidates.size), _QUARTER_STARTS):
        ok = block[free[block]]
        if ok.size == 0:
            raise ValueError(f"{recording.name}: no start time in [{candidates[block[0]]:.1f}, "
                             f"{candidates[block[-1]]:.1f}] s leaves both ends of the crossing free")
        starts.append(float(candidates[ok[np.argmax(busy[ok])]]))
    apart = (hi - lo) / V_REF  # the nominal duration: crossings this far apart start in other crowds
    for j in np.argsort(-busy, kind="stable"):  # busiest first, the earliest of equals
        if len(starts) == _START_TIMES:
            break
        if free[j] and all(abs(float(candidates[j]) - t) >= apart for t in starts):
            starts.append(float(candidates[j]))
    if len(starts) < _START_TIMES:
        raise ValueError(f"{recording.name}: only {len(starts)} start times {apart:.1f} s apart leave both ends of "
                         f"the crossing free; {_START_TIMES} are needed")
    xmin, ymin = np.minimum(pts.min(axis=0), ends.min(axis=0)) - _WORLD_MARGIN
    xmax, ymax = np.maximum(pts.max(axis=0), ends.max(axis=0)) + _WORLD_MARGIN
    return Crossings(ends, np.array(starts), (float(xmin), float(xmax), float(ymin), float(ymax)))


@functools.lru_cache(maxsize=8)
def _crossings(name: str) -> Crossings:
    return plan_crossings(load_recording(name))


def recorded_scene(name: str, seed: int) -> Scenario:
    """Crossing ``seed`` of the recorded scene ``name`` (module docstring)."""
    if not 0 <= seed < RECORDED_CROSSINGS:
        raise ValueError(f"{name} is a recorded scene with {RECORDED_CROSSINGS} crossings: "
                         f"seeds 0..{RECORDED_CROSSINGS - 1}, got {seed}")
    recording = load_recording(name)
    plan = _crossings(name)
    t0, start, goal = plan.crossing(seed)
    x0, g = _robot(start, goal)
    return Scenario(name, seed, World((), plan.bounds), RecordedCrowdSpec(recording, t0), x0, g,
                    time_limit=RECORDED_TIME_LIMIT)


SIMULATED_SCENARIOS = ("circle_crossing", "corridor", "crossing_group", "random_crowded_cluttered")
CROWDNAV_SCENARIOS = tuple(f"crowdnav_{kind}_{n}" for kind in ("circle", "square") for n in CROWDNAV_SIZES)
RECORDED_SCENARIOS = ("biwi_eth", "biwi_hotel", "crowds_zara01")

SCENARIOS: dict[str, Callable[[int], Scenario]] = {
    "random_crowded_cluttered": random_crowded_cluttered,
    "crossing_group": crossing_group,
    "circle_crossing": circle_crossing,
    "corridor": corridor,
    **{f"crowdnav_circle_{n}": functools.partial(crowdnav_circle, n) for n in CROWDNAV_SIZES},
    **{f"crowdnav_square_{n}": functools.partial(crowdnav_square, n) for n in CROWDNAV_SIZES},
    **{name: functools.partial(recorded_scene, name) for name in RECORDED_SCENARIOS},
}


def scenario_seeds(name: str) -> int | None:
    """How many seeds scenario ``name`` has (``None``: any seed >= 0 is a scenario)."""
    return RECORDED_CROSSINGS if name in RECORDED_SCENARIOS else None


def check_seeds(name: str, seeds: Sequence[int]) -> None:
    """``ValueError`` saying which seeds scenario ``name`` has, if ``seeds`` holds another one."""
    count = scenario_seeds(name)
    bad = [int(s) for s in seeds if int(s) < 0 or (count is not None and int(s) >= count)]
    if bad:
        valid = "seeds >= 0" if count is None else f"seeds 0..{count - 1} (its crossings)"
        raise ValueError(f"scenario {name} has {valid}; got seed(s) {', '.join(map(str, bad[:5]))}"
                         + (" ..." if len(bad) > 5 else ""))


def make_scenario(name: str, seed: int) -> Scenario:
    """The scenario ``name`` for ``seed``; ``ValueError`` listing the valid names (or seeds) otherwise."""
    try:
        factory = SCENARIOS[name]
    except KeyError:
        raise ValueError(f"unknown scenario {name!r}; valid scenarios: {', '.join(sorted(SCENARIOS))}") from None
    check_seeds(name, [seed])
    return factory(int(seed))
