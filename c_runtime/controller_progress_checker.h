/*
 * controller_progress_checker.h: progress checking as nav2's progress checker does it
 * (controller_progress_checker.c): the distance left along the path must shrink by stall_distance within
 * stall_time, or the robot is stalled.
 */
#ifndef CONTROLLER_PROGRESS_CHECKER_H
#define CONTROLLER_PROGRESS_CHECKER_H
#include "controller_common.h"

/* Returns 1 when stalled; *slow: 1 when the robot has gone slower than half the speed it tracks for
 * stall_time. stopped: a protective stop this period (restarts the measure). */
HM_FUNC int controller_progress(hm_controller *c, const hm_controller_input *cin, const hm_controller_goal *g,
                                int stopped, int *slow, hm_controller_output *out);

#endif /* CONTROLLER_PROGRESS_CHECKER_H */
