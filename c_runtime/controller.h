/*
 * controller.h: the navigation controller (controller.c), configured once, then called once per
 * control period with odometry, a path or a goal, tracked people and obstacle points; it returns a
 * velocity command and says what it is doing (an outcome, a stop and its reason, goal reached,
 * stalled), never silently. Around the solver it does what a robot needs and the OCP alone does not:
 * the goal the OCP sees (controller_path.h), the people and the obstacle it sees
 * (controller_people.h), the approach to the goal, the speed limit, loop and stall detection with a
 * recovery by a bounded SQP inside the deadline, the braking at the goal. Its last word on every period
 * is the safety guard (controller_safety.h): someone within d_h, speed and separation, the command's
 * bounds and the deadline of the whole step, over every track it received.
 */
#ifndef CONTROLLER_H
#define CONTROLLER_H
#include "controller_common.h"

/* The solver's parameters (params) and the controller's own (own), copied. */
HM_FUNC void controller_init(hm_controller *c, const hm_params *params, const hm_controller_params *own);
/* Forget the episode: a cold solver, no progress history; the parameters are kept. */
HM_FUNC void controller_reset(hm_controller *c);
/* One control period; returns out->outcome. */
HM_FUNC int controller_step(hm_controller *c, const hm_controller_input *cin, hm_controller_output *out);
HM_FUNC const char *controller_outcome_message(int outcome);

#endif /* CONTROLLER_H */
