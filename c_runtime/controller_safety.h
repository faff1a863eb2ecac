/*
 * controller_safety.h: the safety decisions of a control period, in one place (controller_safety.c).
 *
 * The solver's monitors (monitor.h: the inputs, C1, C2, speed and separation on the N_h people it sees,
 * the command guard) judge the real-time iteration's plan. Around them the controller hands the robot
 * plans of its own (braking at the goal or without one, the turn in place at the goal, a recovery's) and
 * sees more people than the solver. Whatever the period's path, its last word is controller_guard:
 *
 *   someone within d_h    any track the controller received within d_h of the robot: a protective stop
 *                         (HM_STOP_HUMAN_TOO_CLOSE), at the goal, without a goal, turning, stalled;
 *   separation            a plan that moves (not a braking one) commands a speed above the
 *                         speed-and-separation bound of any track: HM_STOP_SEPARATION;
 *   a stop in time        a plan that moves, followed for the reaction time and then braked along its
 *                         heading, would still be moving when it comes within d_h of a person's predicted
 *                         position (the N_h people the OCP sees, from any side: the bound above sees people
 *                         ahead only): HM_STOP_PREDICTED_CONTACT, while a stop can still bring the robot to
 *                         rest before they arrive;
 *   the command guard     the command and u0 finite and within the period's bounds (monitor_command_ok):
 *                         else HM_STOP_COMMAND_BOUNDS (braking at the goal from above the speed limit too);
 *   the deadline          the whole period, from its first clock reading, within params.deadline_ms:
 *                         else HM_STOP_DEADLINE (the solver's own deadline counts from the same reading).
 *
 * Every protective stop brakes (ocp_nlp_protective_stop): towards v = 0 from either direction at the
 * configured rate of that direction, no turning.
 */
#ifndef CONTROLLER_SAFETY_H
#define CONTROLLER_SAFETY_H
#include "controller_common.h"

/* Distance from the point p to the nearest of the controller's tracks (all of them; HM_INF without). */
HM_FUNC hm_real controller_nearest_track(const hm_controller_input *cin, const hm_real *p);

/* The tests of a plan that moves, on the solver's output o of this period (c->in, the solver's parameters
 * set): speed and separation on every track, then the stop in time; HM_STOP_NONE when both pass. The
 * guard applies them to the plan applied, the candidates' choice to every plan it may apply. */
HM_FUNC int controller_moving_plan_reason(const hm_controller *c, const hm_controller_input *cin, const hm_output *o);
/* The period's last word on c->out (see above): a protective stop replaces it when one of the tests
 * fails; a stop already in force is kept with its reason. braking: 1 when c->out is the controller's own
 * braking plan (at the goal, without a goal), which the speed-and-separation test leaves alone: a stop
 * would brake the same way. t0: the period's first clock reading. */
HM_FUNC void controller_guard(hm_controller *c, const hm_controller_input *cin, unsigned long long t0, int braking);

#endif /* CONTROLLER_SAFETY_H */
