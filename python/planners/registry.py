"""Planners by name: a factory per name, so the CLI and the evaluation can build them.

``register_planner("mpc", factory)`` adds a planner; the factory takes no argument and returns
a fresh :class:`~humanmpc.planners.interface.Planner`. The DWB baseline is registered as ``"dwb"``, the
generated C controller as ``"mpc"`` (the spec's defaults) and ``"mpc_paper"`` (the paper's parameters and
the goal pose alone; :meth:`~humanmpc.planners.mpc.MPCPlanner.paper`).
Evaluation workers are forked from the registering process, so registrations made before an
evaluation starts are visible in the workers.
"""

from __future__ import annotations

from collections.abc import Callable

from .dwb import DWBPlanner
from .interface import Planner

PlannerFactory = Callable[[], Planner]

_PLANNERS: dict[str, PlannerFactory] = {}


def register_planner(name: str, factory: PlannerFactory, *, replace: bool = False) -> None:
    """Make ``factory`` available as ``name``; re-registering needs ``replace=True``."""
    if not name or not name.replace("_", "").replace("-", "").isalnum():
        raise ValueError(f"planner names are non-empty words (letters, digits, '-', '_'), got {name!r}")
    if name in _PLANNERS and not replace:
        raise ValueError(f"a planner named {name!r} is already registered (pass replace=True to override)")
    _PLANNERS[name] = factory


def planner_names() -> list[str]:
    return sorted(_PLANNERS)


def make_planner(name: str) -> Planner:
    """A fresh planner for ``name``; ``ValueError`` listing the registered names otherwise."""
    try:
        factory = _PLANNERS[name]
    except KeyError:
        raise ValueError(f"unknown planner {name!r}; valid planners: {', '.join(planner_names())}") from None
    return factory()


def _make_mpc() -> Planner:
    # Imported here: loading the MPC generates and builds its solver when that is missing.
    from .mpc import MPCPlanner

    return MPCPlanner(name="mpc")


def _make_mpc_paper() -> Planner:
    from .mpc import MPCPlanner

    return MPCPlanner.paper(name="mpc_paper")


register_planner("dwb", DWBPlanner)
register_planner("mpc", _make_mpc)
register_planner("mpc_paper", _make_mpc_paper)
