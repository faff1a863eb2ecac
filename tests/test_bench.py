"""The benchmark's statistics (humanmpc-gen bench): what is pooled over which steps."""

from __future__ import annotations

import math

from humanmpc.compare.bench import markdown_table, summarize


def _samples(statuses: list[int], c_ms: list[float], reasons: list[int]) -> dict[str, list[float]]:
    n = len(statuses)
    return {
        "c_ms": c_ms, "py_ms": [t + 0.01 for t in c_ms], "prep_ms": [0.1 * t for t in c_ms],
        "qp_iter": [0.0 if s == -1 else 12.0 for s in statuses], "qp_status": [float(s) for s in statuses],
        "dist": [1.0 + i for i in range(n)], "reason": [float(r) for r in reasons],
    }


def test_solved_step_times_leave_out_stops_and_failed_qps_and_the_overall_mean_keeps_them() -> None:
    # a stop before the QP (cheap), two solved QPs, one failed QP (stop qp_failed)
    res = summarize(5, 1, _samples([-1, 0, 0, 3], [0.02, 0.2, 0.3, 0.5], [6, 0, 0, 4]))
    assert math.isclose(res.c_total_ms.mean, (0.02 + 0.2 + 0.3 + 0.5) / 4)
    assert res.c_solved_ms is not None and res.python_solved_ms is not None
    assert math.isclose(res.c_solved_ms.mean, 0.25) and math.isclose(res.c_solved_ms.max, 0.3)
    assert math.isclose(res.python_solved_ms.mean, 0.26)
    assert res.qp_status == {"not_run": 1, "solved": 2, "numerical": 1}
    assert math.isclose(res.solved_fraction, 2 / 3)  # of the steps where a QP ran
    assert res.stops == {"human_too_close": 1, "qp_failed": 1}
    assert "| 0.250 / 0.260 |" in markdown_table([res])


def test_a_run_without_a_solved_qp_reports_none_for_the_solved_steps() -> None:
    res = summarize(5, 1, _samples([-1, -1], [0.02, 0.03], [6, 6]))
    assert res.c_solved_ms is None and res.python_solved_ms is None
    assert res.solved_fraction == 0.0
    assert "| none |" in markdown_table([res])
