/*
 * controller_goal_checker.h: goal checking as nav2's stateful, stopped goal checker does it
 * (controller_goal_checker.c): once within goal_tolerance the robot brakes to a standstill and turns in
 * place to the goal's heading; the goal is reached within yaw_goal_tolerance and at rest.
 */
#ifndef CONTROLLER_GOAL_CHECKER_H
#define CONTROLLER_GOAL_CHECKER_H
#include "controller_common.h"

/* Slower than this a robot counts as standing: it may turn in place at its goal, and it has reached its goal
 * (the evaluation's threshold of moving, python/eval/metrics.py). */
#define CONTROLLER_AT_REST HM_R(0.05)

/* What the robot does within goal_tolerance of its goal (controller_at_goal). */
enum controller_at_goal_state {
    CONTROLLER_GOAL_DONE,    /* the heading is within yaw_goal_tolerance, or there is none to meet: braking */
    CONTROLLER_GOAL_TURNING  /* braking, then turning in place to the goal's heading */
};

/* c->out: braking to a standstill (not a protective stop); the solver starts cold next period. */
HM_FUNC void controller_brake(hm_controller *c);
/* 1 once the robot has come within goal_tolerance of this goal, until a new goal. */
HM_FUNC int controller_arriving(hm_controller *c, const hm_controller_goal *g);
/* c->out: braking, and the turn in place to heading when it is off by more than yaw_goal_tolerance. */
HM_FUNC enum controller_at_goal_state controller_at_goal(hm_controller *c, const hm_controller_input *cin,
                                                         hm_real heading);

#endif /* CONTROLLER_GOAL_CHECKER_H */
