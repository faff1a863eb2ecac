/*
 * hm_status.h: the status codes of a QP solve and of a solver step, and the reasons for a
 * protective stop, and the outcomes of a controller step, as tables: one X(ID, value, name, message) row each. This is their single source:
 * the runtime's enums and messages expand these rows, and the generator reads this file
 * (humanmpc.codegen.status) for the public constants of the generated header (<NAME>_QP_SOLVED,
 * <NAME>_STATUS_OK, <NAME>_STOP_DEADLINE, ...), the manifest and the Python enums. The values are
 * part of the public C and Python API: never renumber a row.
 *
 * Rows are one line each, with a plain string message (the generator parses them).
 */
#ifndef HM_STATUS_H
#define HM_STATUS_H

/* What one QP solve ended with (ocp_qp_ipm, ocp_qp_hsde). */
#define HM_QP_STATUS_TABLE(X) \
    X(QP_NOT_RUN, -1, not_run, "no QP was solved in this step") \
    X(QP_SOLVED, 0, solved, "QP solved") \
    X(QP_MAX_ITER, 1, max_iter, "QP iteration limit reached before convergence") \
    X(QP_INFEASIBLE, 2, infeasible, "QP infeasible: no point satisfies the hard constraints") \
    X(QP_NUMERICAL, 3, numerical, "QP numerical failure: singular Newton system, no progress, or unbounded") \
    X(QP_NONFINITE, 4, nonfinite, "QP data or iterates not finite (NaN/Inf, or ng out of range)") \
    X(QP_TIMEOUT, 5, timeout, "QP stopped by the deadline hook")

/* What one solver step (RTI) or solve (full SQP) ended with. */
#define HM_STATUS_TABLE(X) \
    X(STATUS_OK, 0, solved, "solved") \
    X(STATUS_MAX_ITER, 1, max_iter, "iteration limit reached before the tolerance") \
    X(STATUS_QP_FAILED, 2, qp_failed, "the QP failed; no step taken") \
    X(STATUS_SKIPPED, 3, skipped, "nothing solved: a protective stop was decided before solving")

/* Why a protective stop is in force (monitor). */
#define HM_STOP_REASON_TABLE(X) \
    X(STOP_NONE, 0, none, "no stop") \
    X(STOP_INVALID_INPUT, 1, invalid_input, "protective stop: non-finite or absurd input (state, goal, humans, predictions or obstacle)") \
    X(STOP_INVALID_PARAMS, 2, invalid_params, "protective stop: runtime parameters non-finite or out of range") \
    X(STOP_DEADLINE, 3, deadline, "protective stop (C1): the solver missed its deadline") \
    X(STOP_QP_FAILED, 4, qp_failed, "protective stop (C1): the QP was not solved") \
    X(STOP_NONFINITE, 5, nonfinite, "protective stop (C1): non-finite number in the solution") \
    X(STOP_HUMAN_TOO_CLOSE, 6, human_too_close, "protective stop (C2): a human is within d_h of the robot") \
    X(STOP_UNSAFE_PLAN, 7, unsafe_plan, "protective stop (C2): the planned path comes within d_h of a human") \
    X(STOP_SEPARATION, 8, separation, "protective stop (speed and separation): at the commanded speed, braking after the reaction time would not stop the robot before a person closing in comes within d_h") \
    X(STOP_COMMAND_BOUNDS, 9, command_bounds, "protective stop (command guard): the command was not finite or left the bounds of v, omega or a") \
    X(STOP_CLOCK, 10, clock, "protective stop (clock fault): the clock ran backwards or did not advance over a step, so no deadline could be kept") \
    X(STOP_STATE_JUMP, 11, state_jump, "protective stop: the measured state jumped further since the last step than the bounds allow") \
    X(STOP_PREDICTED_CONTACT, 12, predicted_contact, "protective stop (speed and separation): following the plan for the reaction time and then braking, the robot would still be moving when it comes within d_h of a person's predicted position")

/* What a controller step ended with (controller.c): what the robot is doing, in one word. */
#define HM_OUTCOME_TABLE(X) \
    X(OUTCOME_FOLLOWING, 0, following, "following the path towards the goal") \
    X(OUTCOME_GOAL_REACHED, 1, goal_reached, "goal reached: braking to a standstill") \
    X(OUTCOME_STOPPED, 2, stopped, "protective stop in force: see stop_reason") \
    X(OUTCOME_STALLED, 3, stalled, "stalled: no progress towards the goal for stall_time seconds while not stopping") \
    X(OUTCOME_NO_GOAL, 4, no_goal, "no path and no goal given: braking to a standstill")

/* Row expanders: an enum constant HM_<ID> = value, and a switch case returning the message. */
#define HM_STATUS_ENUM_ROW(id, value, name, message) HM_##id = value,
#define HM_STATUS_CASE_ROW(id, value, name, message) \
    case HM_##id:                                   \
        return message;
#define HM_STATUS_COUNT_ROW(id, value, name, message) +1

#endif /* HM_STATUS_H */
