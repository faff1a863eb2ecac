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
/* A stalled robot does not drive on away from its goal: when the command c->out moves the robot neither
 * towards the carrot (v cos(bearing to the carrot) <= 0) nor on a plan that is nearer the carrot half a
 * horizon on, c->out becomes a braking plan (not a protective stop). Returns 1 when it did. Walking along
 * beside a person who crosses at the robot's own speed, the paper's objective held a stalled robot at full
 * speed, at right angles to its goal, for 45 s (its plans there put the turn back off to their last nodes). */
HM_FUNC int controller_stalled_command(hm_controller *c);

#endif /* CONTROLLER_PROGRESS_CHECKER_H */
