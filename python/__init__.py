"""humanmpc: human-aware navigation MPC, generated as fixed-size C and driven from Python.

    import humanmpc
    solver = humanmpc.load("generated/paper")      # builds the library first if needed
    x_next, A, B = solver.model.dynamics(x, u)
    ctl = solver.controller()                       # the navigation controller in C
    r = ctl.step(t, pose=(x, y, theta), v=v, omega=omega, goal=(gx, gy, gtheta), people=tracks)
"""

from .bindings import Dims, LoadError, load
from .codegen import __version__
from .controller import Controller
from .results import ControllerResult, StepResult
from .solver import Solver
from .status import Outcome, QpStatus, Status, StopReason

__all__ = ["Controller", "ControllerResult", "Dims", "LoadError", "Outcome", "QpStatus", "Solver", "Status",
           "StepResult", "StopReason", "__version__", "load"]
