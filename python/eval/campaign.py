"""An evaluation campaign as data: the grid of its episodes, each a self-contained, serialisable task.

A campaign is scenarios x crowd models x planners (each with every point of a grid over runtime
parameters, for the planners that have them) x seeds, with one solver for the MPC planners. An
:class:`EpisodeTask` says everything a worker needs to run one episode anywhere: the scenario's name and
seed (scenarios are pure functions of them), the crowd model, the planner's registered name, its runtime
parameters and the factory that made it in the submitting process (so planners registered at run time,
in a script, run on workers that never saw the registration), the solver (:class:`SolverRef`: a spec,
built by each worker into its own cache, or a folder used as it is, with the spec digest both must have),
the episode settings and whether to keep the per-step trace. Its :attr:`~EpisodeTask.key` names the
episode in the results: the same key is the same episode, run once.

Recorded scenes replay their people whatever the crowd model: they enter the grid once per planner and
seed, with the crowd ``recorded``.
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field, replace
from typing import Any

from ..codegen.spec import Spec
from ..planners.interface import Planner
from ..sim.scenarios import CROWD_MODELS, make_scenario
from .episode import EpisodeConfig

ParamValue = int | float | tuple[float, ...]
RECORDED = "recorded"  # the crowd of a recorded scene
TRACES = ("none", "first", "all")  # which episodes keep their per-step trace


def format_value(value: ParamValue) -> str:
    """A parameter value as the grid writes it: ``50``, ``0.3``, vectors ``0.5:0.5:0:50``."""
    if isinstance(value, tuple):
        return ":".join(format_value(v) for v in value)
    return f"{value:g}" if isinstance(value, float) else str(value)


def parse_value(text: str, name: str) -> ParamValue:
    """``50`` -> 50, ``0.3`` -> 0.3, ``a:b:c`` -> (a, b, c); ``ValueError`` naming the parameter otherwise."""
    parts = text.split(":")
    try:
        numbers = [float(p) if any(c in p for c in ".eE") or p.lower() in ("inf", "nan") else int(p) for p in parts]
    except ValueError:
        raise ValueError(f"--grid {name}: {text!r} is not a number (vectors: entries separated by ':', e.g. "
                         "w_goal=0.5:0.5:0:50)") from None
    if any(isinstance(v, float) and not math.isfinite(v) for v in numbers):
        raise ValueError(f"--grid {name}: {text!r} is not a finite number")
    return tuple(float(v) for v in numbers) if len(numbers) > 1 else numbers[0]


def parse_grid(items: Sequence[str]) -> tuple[tuple[str, tuple[ParamValue, ...]], ...]:
    """``["q=10,50", "reaction_time=0.3,0.5"]`` -> ``(("q", (10, 50)), ("reaction_time", (0.3, 0.5)))``;
    ``ValueError`` naming the item that is not ``NAME=V1,V2,...`` or names a parameter twice."""
    grid: list[tuple[str, tuple[ParamValue, ...]]] = []
    for item in items:
        name, sep, values = item.partition("=")
        name = name.strip()
        if not sep or not name.isidentifier() or not values.strip():
            raise ValueError(f"--grid {item!r}: write NAME=V1,V2,... with a runtime parameter's name "
                             "(humanmpc-gen keys lists them), e.g. --grid q=10,50")
        if any(name == n for n, _ in grid):
            raise ValueError(f"--grid names {name} twice: give all its values in one NAME=V1,V2,...")
        parsed = tuple(parse_value(v.strip(), name) for v in values.split(","))
        if len(set(parsed)) != len(parsed):
            raise ValueError(f"--grid {item!r}: a value is repeated")
        grid.append((name, parsed))
    return tuple(grid)


def grid_points(grid: Sequence[tuple[str, Sequence[ParamValue]]]) -> list[tuple[tuple[str, ParamValue], ...]]:
    """Every combination of the grid's values, in order (one empty point for an empty grid)."""
    names = [n for n, _ in grid]
    return [tuple(zip(names, combo, strict=True)) for combo in itertools.product(*(v for _, v in grid))]


@dataclass(frozen=True)
class PlannerConfig:
    """A registered planner and the runtime parameters it runs with (none: its own)."""

    name: str
    params: tuple[tuple[str, ParamValue], ...] = ()

    @property
    def label(self) -> str:
        """``mpc`` or ``mpc[q=10,reaction_time=0.5]``: how tables and keys name it."""
        if not self.params:
            return self.name
        return f"{self.name}[{','.join(f'{k}={format_value(v)}' for k, v in self.params)}]"

    @property
    def params_json(self) -> str:
        return json.dumps({k: list(v) if isinstance(v, tuple) else v for k, v in self.params}, sort_keys=True)


@dataclass(frozen=True)
class SolverRef:
    """The solver of a task's MPC planners: ``spec``'s, generated and built by each worker into its own cache
    (None: the built-in default spec), or the built package in ``solver_dir`` (a folder every worker sees),
    used as it is; either way the spec digest ``digest`` it must have."""

    digest: str
    spec: Spec | None = None
    solver_dir: str | None = None
    source: str | None = None  # where the spec came from (a file name), for messages


@dataclass(frozen=True)
class EpisodeTask:
    """One episode, self-contained (module docstring)."""

    scenario: str
    crowd: str
    planner: PlannerConfig
    seed: int
    solver: SolverRef
    config: EpisodeConfig
    traces: bool = False
    factory: Callable[[], Planner] | None = field(default=None, compare=False, repr=False)

    @property
    def key(self) -> str:
        """``scenario/crowd/planner label/seed``: the episode's name in the results."""
        return f"{self.scenario}/{self.crowd}/{self.planner.label}/{self.seed}"

    @property
    def episode_config(self) -> EpisodeConfig:
        """The episode settings with this task's crowd model (recorded scenes ignore it)."""
        return replace(self.config, crowd_model=self.config.crowd_model if self.crowd == RECORDED else self.crowd)


@dataclass(frozen=True)
class Campaign:
    """The grid of a campaign (module docstring). ``tunable``: the planners that take runtime parameters
    (the grid applies to them; the others run once per scenario, crowd and seed)."""

    scenarios: tuple[str, ...]
    crowds: tuple[str, ...]
    planners: tuple[str, ...]
    seeds: tuple[int, ...]
    solver: SolverRef
    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    grid: tuple[tuple[str, tuple[ParamValue, ...]], ...] = ()
    tunable: frozenset[str] = frozenset()
    traces: str = "first"

    def __post_init__(self) -> None:
        for what, values in (("scenarios", self.scenarios), ("crowds", self.crowds), ("planners", self.planners),
                             ("seeds", self.seeds)):
            if not values:
                raise ValueError(f"a campaign needs at least one of its {what}")
            if len(set(values)) != len(values):
                raise ValueError(f"a campaign's {what} are given twice: {', '.join(map(str, values))}")
        bad = [c for c in self.crowds if c not in CROWD_MODELS]
        if bad:
            raise ValueError(f"unknown crowd model(s) {', '.join(bad)}; crowd models: {', '.join(CROWD_MODELS)}")
        if self.traces not in TRACES:
            raise ValueError(f"traces must be one of {', '.join(TRACES)}, got {self.traces!r}")
        if self.grid and not set(self.planners) & self.tunable:
            raise ValueError(f"--grid sets runtime parameters, which none of the planners {', '.join(self.planners)} "
                             f"takes; planners with runtime parameters: {', '.join(sorted(self.tunable)) or 'none'}")

    def planner_configs(self) -> list[PlannerConfig]:
        """Each planner once per grid point if it takes runtime parameters, else once."""
        out: list[PlannerConfig] = []
        for name in self.planners:
            points = grid_points(self.grid) if name in self.tunable else [()]
            out.extend(PlannerConfig(name, point) for point in points)
        return out

    def cells(self) -> list[tuple[str, str]]:
        """(scenario, crowd) pairs: simulated scenes with every crowd model, recorded ones with theirs."""
        out: list[tuple[str, str]] = []
        for scenario in self.scenarios:
            if make_scenario(scenario, self.seeds[0]).recorded:
                out.append((scenario, RECORDED))
            else:
                out.extend((scenario, crowd) for crowd in self.crowds)
        return out

    def tasks(self, factories: Mapping[str, Callable[[], Planner]] | None = None) -> list[EpisodeTask]:
        """Every episode of the grid; ``factories``: the planners' factories to ship with the tasks."""
        first = self.seeds[0]
        return [
            EpisodeTask(scenario, crowd, planner, seed, self.solver, self.config,
                        self.traces == "all" or (self.traces == "first" and seed == first),
                        (factories or {}).get(planner.name))
            for scenario, crowd in self.cells() for planner in self.planner_configs() for seed in self.seeds
        ]

    def description(self) -> dict[str, Any]:
        """What identifies the campaign in its folder (JSON): the same description, the same episodes."""
        cfg = self.config
        return {
            "scenarios": list(self.scenarios), "crowds": list(self.crowds), "planners": list(self.planners),
            "grid": {n: [list(v) if isinstance(v, tuple) else v for v in values] for n, values in self.grid},
            "seeds": list(self.seeds), "spec_digest": self.solver.digest,
            "solver_dir": self.solver.solver_dir, "traces": self.traces,
            "episode": {"dt": cfg.dt, "stop_on_collision": cfg.stop_on_collision,
                        "robot": asdict(cfg.robot), "social_force": asdict(cfg.social_force),
                        "orca": asdict(cfg.orca)},
        }
