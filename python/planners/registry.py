"""Planners by name: a factory per name, so the CLI and the evaluation can build them.

``register_planner("mpc", factory)`` adds a planner; the factory takes no argument and returns
a fresh :class:`~humanmpc.planners.interface.Planner`. The DWB baseline is registered as ``"dwb"``, the
generated C controller as ``"mpc"`` (the spec's defaults) and ``"mpc_paper"`` (the paper's parameters and
the goal pose alone; :meth:`~humanmpc.planners.mpc.MPCPlanner.paper`).
An evaluation ships each task's factory with it (:func:`planner_factory`; Dask pickles it, a function of
a script by value), so planners registered at run time run on workers that never registered them.

The two MPC planners load the solver chosen for this process by
:func:`~humanmpc.planners.solver_cache.select_solver` (re-exported here; the ``simulate``, ``evaluate``
and ``demo`` commands call it with their ``--spec`` / ``--solver-dir`` before any planner is made, and
an evaluation's workers make the same choice from the task's solver reference); without a choice, the
built-in default spec's solver in the tools' cache. A factory registered for another MPC configuration
honours the choice by loading ``ensure_solver()``.
"""

from __future__ import annotations

from collections.abc import Callable

from ..bindings import load
from ..solver import Solver
from .dwb import DWBPlanner
from .interface import Planner
from .solver_cache import ensure_solver
from .solver_cache import select_solver as select_solver

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


def planner_factory(name: str) -> PlannerFactory:
    """The factory registered as ``name``; ``ValueError`` listing the registered names otherwise."""
    try:
        return _PLANNERS[name]
    except KeyError:
        raise ValueError(f"unknown planner {name!r}; valid planners: {', '.join(planner_names())}") from None


def make_planner(name: str) -> Planner:
    """A fresh planner for ``name``; ``ValueError`` listing the registered names otherwise."""
    return planner_factory(name)()


def _selected_solver() -> Solver:
    """The chosen solver (select_solver), generated and built into the cache first when it is the tools'."""
    return load(ensure_solver(), build_if_needed=False)


def _make_mpc() -> Planner:
    from .mpc import MPCPlanner

    return MPCPlanner(_selected_solver(), name="mpc")


def _make_mpc_paper() -> Planner:
    from .mpc import MPCPlanner

    return MPCPlanner.paper(_selected_solver(), name="mpc_paper")


register_planner("dwb", DWBPlanner)
register_planner("mpc", _make_mpc)
register_planner("mpc_paper", _make_mpc_paper)
