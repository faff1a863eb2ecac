"""The solver's status codes, QP status codes and stop reasons, by name."""

from __future__ import annotations

STATUS_NAMES = {0: "solved", 1: "max_iter", 2: "qp_failed", 3: "skipped"}
STOP_REASONS = {
    0: None,
    1: "invalid_input",
    2: "invalid_params",
    3: "deadline",
    4: "qp_failed",
    5: "nonfinite",
    6: "human_too_close",
    7: "unsafe_plan",
}
QP_STATUS_NAMES = {
    -1: "not_run", 0: "solved", 1: "max_iter", 2: "infeasible", 3: "numerical", 4: "nonfinite", 5: "timeout",
}
