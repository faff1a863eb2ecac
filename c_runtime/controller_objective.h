/*
 * controller_objective.h: what the OCP is asked to do in one period (controller_objective.c): its
 * weights and bounds (the speed limit; the progress objective's weights, or the paper's carrot with the
 * speed taper and the approach), the progress objective's goal per node along the path, the collision
 * potential's end at the earliest arrival, and no potential for people standing at the goal.
 */
#ifndef CONTROLLER_OBJECTIVE_H
#define CONTROLLER_OBJECTIVE_H
#include "controller_common.h"

/* The caller's values of the solver parameters that controller_solver_params changes for a period: kept
 * when the period starts, put back when it ends, so that between periods c->solver.params is the
 * caller's and a period changes only these fields in it. */
typedef struct controller_caller_params {
    hm_real w_goal[HM_NX];
    hm_real w_goal_terminal[HM_NX];
    hm_real v_max;                 /* v_bounds[1] */
    hm_real collision_horizon;
} controller_caller_params;
HM_FUNC void controller_caller_keep(const hm_controller *c, controller_caller_params *caller);
HM_FUNC void controller_caller_restore(hm_controller *c, const controller_caller_params *caller);
/* The solver's parameters for this period: the caller's (in c->solver.params) with the speed cap and the
 * objective's weights and potential end written into it; and the speed the OCP tracks (c->in.goal[3]). */
HM_FUNC void controller_solver_params(hm_controller *c, const hm_controller_goal *g);
/* Where the path to the goal starts (a goal pose given alone: where the robot was when it got it). */
HM_FUNC const hm_real *controller_origin(hm_controller *c, const hm_controller_input *cin);
/* The progress objective's goal per node: c->in.refs, c->in.has_refs; updates the goals' lead (c->lead). */
HM_FUNC void controller_references(hm_controller *c, const hm_controller_input *cin, const hm_controller_goal *g);
/* c->in.humans_no_potential for the people the OCP sees (out->people_index). */
HM_FUNC void controller_goal_people(hm_controller *c, const hm_controller_input *cin, const hm_controller_goal *g,
                                   const hm_controller_output *out);

#endif /* CONTROLLER_OBJECTIVE_H */
