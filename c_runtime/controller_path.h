/*
 * controller_path.h: the goal the OCP sees in one period (controller_path.c): the robot's projection
 * on the reference path (or on the straight line to a goal pose), the distance left along it, and a
 * carrot lookahead metres further on, with the path's heading there.
 */
#ifndef CONTROLLER_PATH_H
#define CONTROLLER_PATH_H
#include "controller_common.h"

/* From the path (n_path >= 2), a one-point path or a goal pose (a straight path from origin), or nothing
 * (g->has = 0). position: the robot's [x, y]; heading: its heading (unwrapped), the final heading of a path
 * given without a goal pose when the path has no length. */
HM_FUNC void controller_goal(const hm_controller_input *cin, const hm_real *origin, const hm_real *position,
                             hm_real heading, hm_real lookahead, hm_controller_goal *g);

/* The point of the path (as controller_goal reads it) at arc length s from its start, [x, y, heading] with
 * the heading of its segment unwound to heading; the final goal at and beyond the path's end. */
HM_FUNC void controller_path_at(const hm_controller_input *cin, const hm_real *origin, hm_real heading, hm_real s,
                                const hm_controller_goal *g, hm_real *point);

#endif /* CONTROLLER_PATH_H */
