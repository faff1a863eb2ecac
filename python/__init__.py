"""humanmpc: human-aware navigation MPC, generated as fixed-size C and driven from Python.

    import humanmpc
    solver = humanmpc.load("generated/paper")      # builds the library first if needed
    x_next, A, B = solver.model.dynamics(x, u)
"""

from .bindings import Dims, LoadError, load
from .codegen import __version__
from .results import StepResult
from .solver import Solver
from .status import QpStatus, Status, StopReason

__all__ = ["Dims", "LoadError", "QpStatus", "Solver", "Status", "StepResult", "StopReason", "__version__", "load"]
