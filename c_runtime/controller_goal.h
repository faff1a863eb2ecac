/*
 * controller_goal.h: the goal the OCP sees in one period (controller_goal.c): the robot's projection
 * on the reference path (or on the straight line to a goal pose), the distance left along it, and a
 * carrot lookahead metres further on, with the path's heading there.
 */
#ifndef CONTROLLER_GOAL_H
#define CONTROLLER_GOAL_H
#include "controller_common.h"

/* From the path (n_path >= 2), a one-point path or a goal pose (a straight path from the robot), or
 * nothing (g->has = 0). position: the robot's [x, y]; heading: its heading (unwrapped), the final
 * heading of a path given without a goal pose when the path has no length. */
HM_FUNC void controller_goal(const hm_controller_input *cin, const hm_real *position, hm_real heading,
                             hm_real lookahead, hm_controller_goal *g);

#endif /* CONTROLLER_GOAL_H */
