/*
 * controller_recovery.h: when the main plan's real-time iteration is stuck in a local solution (a loop,
 * a standstill with the goal behind, a slow or stalled robot), a bounded SQP inside the period's deadline
 * from another start (controller_recovery.c); its plan replaces the main one only when it is better.
 */
#ifndef CONTROLLER_RECOVERY_H
#define CONTROLLER_RECOVERY_H
#include "controller_common.h"

/* Where a recovery's SQP starts. */
enum controller_start {
    CONTROLLER_START_COLD,     /* a standstill guess: after a loop */
    CONTROLLER_START_SIDEWAYS, /* a step to the side: slow or stalled */
    CONTROLLER_START_TURN      /* a turn towards the carrot: standing, the carrot behind */
};

/* 1 when the main plan c->out is a loop (loop_ratio, loop_min_length). */
HM_FUNC int controller_plan_is_loop(const hm_controller *c);
/* 1 when the carrot is behind the robot and the plan stands. */
HM_FUNC int controller_stuck_facing_away(const hm_controller *c);
/* A recovery from the given start; returns 1 when its plan replaced c->out. */
HM_FUNC int controller_recover(hm_controller *c, unsigned long long t0, enum controller_start start,
                               hm_controller_output *out);
/* 1 when a paced recovery may run in this period. */
HM_FUNC int controller_may_recover(const hm_controller *c, const hm_controller_input *cin,
                                   const hm_controller_output *out);
/* controller_recover, its time taken for the pace of controller_may_recover. */
HM_FUNC int controller_recover_paced(hm_controller *c, const hm_controller_input *cin, unsigned long long t0,
                                     enum controller_start start, hm_controller_output *out);

#endif /* CONTROLLER_RECOVERY_H */
