/*
 * monitor.h: the feasibility and safety monitors of the paper (section "Feasibility and Safety
 * Monitors") and the protective stop they command (ISO 3691-4, ISO 13482).
 *
 *   inputs  non-finite or absurd state, goal, humans (positions, velocities), predictions, obstacle or
 *           parameters: nothing is
 *           computed from them.
 *   C1      the solver did not return a usable solution in time: the deadline passed (checked inside
 *           the QP iterations, not only around them), the QP was not solved (iteration limit,
 *           infeasible, numerical failure) or the solution holds a non-finite number.
 *   C2      the solution is not safe: the robot already is within d_h of a present human, or the
 *           planned path comes within d_h of a present human's current position (its nodes 1..N,
 *           and the state reached by applying u0 from the measured state, by the model).
 *   separation  (params.separation) the commanded speed is above the speed from which braking after
 *           the reaction time stops the robot before a present human closing in at their velocity
 *           (the input's humans_vel) comes within d_h (monitor_separation_speed). The OCP bounds its speeds the same
 *           way, so this fires when braking at the acceleration bound cannot keep the bound (a person
 *           appearing close, running at the robot) or for tracks the OCP does not see (the controller
 *           checks all of them).
 *
 * A protective stop brakes to standstill within the acceleration bound, without turning. After any
 * stop the solver starts the next step cold, so it recovers by itself once the situation clears and
 * gives then exactly what a fresh solver gives.
 */
#ifndef HM_MONITOR_H
#define HM_MONITOR_H

#include "hm_common.h"
#include "ocp_nlp_common.h" /* hm_input, hm_params */

/* Why a protective stop is in force: HM_STOP_NONE, HM_STOP_INVALID_INPUT, ... (rows of hm_status.h,
 * their single source; fixed values, part of the public C and Python API). */
enum hm_stop_reason { HM_STOP_REASON_TABLE(HM_STATUS_ENUM_ROW) };
#define HM_STOP_REASON_COUNT (0 HM_STOP_REASON_TABLE(HM_STATUS_COUNT_ROW))

/* The rules of the runtime parameters are the generator's table (humanmpc.codegen.params): the
 * including translation unit supplies them as hm_params_check(p), 0 when every rule holds, else 1 +
 * the index of the first broken one (the generated <name>_params_check). */

/* Magnitudes beyond which an input is absurd rather than merely unusual. */
#define HM_MONITOR_MAX_POSITION HM_R(1.0e5)   /* m */
#define HM_MONITOR_MAX_ANGLE HM_R(1.0e4)      /* rad: headings may wind, but not without bound */
#define HM_MONITOR_MAX_SPEED HM_R(100.0)      /* m/s */

/* 1 when v is finite; 1 when the point p[0], p[1] is finite and within HM_MONITOR_MAX_POSITION (the
 * controller checks its path, tracks and obstacle points with the same tests). */
HM_FUNC int monitor_finite(hm_real v);
HM_FUNC int monitor_position_ok(const hm_real *p);
HM_FUNC int monitor_check_input(const hm_input *in, int check_x0);
HM_FUNC int monitor_check_params(const hm_params *p);
HM_FUNC hm_real monitor_distance_now(const hm_input *in);

/* Speed and separation (ISO/TS 15066's protective separation, applied to people): the largest speed
 * v >= 0 along the heading (cos_t, sin_t) from p such that a robot that keeps v for t_r, then brakes
 * at a_brake > 0, stops before it comes within d_h of a person at h whose velocity vh closes in on
 * p. With d the distance, cos_phi the heading's cosine towards the person and c >= 0 the person's
 * closing speed, v keeps
 *     cos_phi (v t_r + v^2 / (2 a_brake)) + c (t_r + v / a_brake) <= d - d_h.
 * HM_INF when no speed up to v_cap needs bounding (a person who is not ahead, cos_phi <= 0, or far
 * enough); 0 when even a standstill does not keep d_h (c t_r >= d - d_h). */
HM_FUNC hm_real monitor_separation_speed(const hm_real *p, hm_real cos_t, hm_real sin_t, const hm_real *h,
                                         const hm_real *vh, hm_real d_h, hm_real t_r, hm_real a_brake,
                                         hm_real v_cap);

/* The stopping reach: how far a person closing in at speed_h (m/s) can be from a robot that moves at up to
 * v_cap, reacts after t_r and brakes at a_brake > 0, and still come within d_h of it before it stands:
 * d_h + v_cap t_r + v_cap^2 / (2 a_brake) + speed_h (t_r + v_cap / a_brake). Everyone within it must be
 * among the people the OCP sees. */
HM_FUNC hm_real monitor_stopping_reach(hm_real d_h, hm_real t_r, hm_real a_brake, hm_real v_cap, hm_real speed_h);

/* The smallest monitor_separation_speed over the present humans of in, for a robot at x (heading x[2]):
 * each human at node n's prediction (their current position at n = 0), closing at their velocity as
 * the input gives it (humans_vel: the track's, whatever the prediction's shape). HM_INF when none
 * binds below v_cap. The OCP's bounds (ocp_nlp_lin.c) and the command's check below. */
HM_FUNC hm_real monitor_separation_bound(const hm_input *in, const hm_params *p, const hm_real *x, int n,
                                         hm_real v_cap);

/* 1 when the commanded speed v is above the speed-and-separation bound by more than the QP's
 * tolerance (which keeps the same bound to it): braking could not keep the separation. */
HM_FUNC int monitor_separation_exceeded(hm_real v, hm_real bound, const hm_params *p);

/* 1 when the command v keeps speed and separation (above) from every present human of in, from the
 * measured state x0; always 1 without params.separation. */
HM_FUNC int monitor_check_separation(const hm_input *in, const hm_params *p, hm_real v);
HM_FUNC const char *monitor_stop_reason_message(int reason);

/* The command guard, the last test of every step, solve and feedback that did not stop: 1 when the
 * command (v = command[0], omega = command[1]) and u0 (a, omega) are finite and within the bounds of
 * the parameters (v_bounds, omega_bounds, a_bounds), to HM_MONITOR_COMMAND_TOL (the QP's interior
 * iterates keep the bounds only to its tolerance). A protective stop's command is a braking one by
 * construction, and may lie above v_bounds while the robot slows down from above them. */
#if defined(HM_REAL_IS_FLOAT)
#define HM_MONITOR_COMMAND_TOL HM_R(1.0e-4)
#else
#define HM_MONITOR_COMMAND_TOL HM_R(1.0e-6)
#endif
HM_FUNC int monitor_command_ok(const hm_params *p, const hm_output *out);

/* The state jump test: 1 when the measured state x can follow x_last, measured one step before, under
 * the bounds: the position moved at most 2 dt max(|v| over v_bounds, x_last, x) + HM_MONITOR_JUMP_POSITION
 * (two intervals: a missed period is no fault) and the speed changed by at most 2 dt max|a_bounds| +
 * HM_MONITOR_JUMP_SPEED. The tolerances cover localisation corrections and odometry noise; the heading
 * is not tested (a caller may wrap it). Only a solver that is warm compares: after a reset or a stop
 * that starts cold there is no plan to be misled. */
#define HM_MONITOR_JUMP_POSITION HM_R(0.5) /* m */
#define HM_MONITOR_JUMP_SPEED HM_R(0.5)    /* m/s */
HM_FUNC int monitor_state_follows(const hm_params *p, const hm_real *x_last, const hm_real *x);

/* 1 when the state x (px, py, theta, v) is finite and within the magnitudes above: what a protective
 * stop needs to brake from it. */
HM_FUNC int monitor_check_state(const hm_real *x);

#endif /* HM_MONITOR_H */
