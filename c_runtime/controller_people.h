/*
 * controller_people.h: the people and the obstacle the OCP sees in one period
 * (controller_people.c): constant-velocity predictions of the tracks, the N_h most relevant of them,
 * and the obstacle point nearest to the robot's expected path.
 */
#ifndef CONTROLLER_PEOPLE_H
#define CONTROLLER_PEOPLE_H
#include "controller_common.h"

/* The robot's expected positions at the nodes 0..N of this period: the solver's last plan advanced
 * by one interval when it has one, else the robot going straight on at its measured speed. Computed
 * once per period for the two selections below (which only read it). */
HM_FUNC void controller_expected_path(const hm_solver *s, const hm_controller_input *cin, hm_real path[HM_N + 1][2]);

/* N_h tracks into the solver's input (in->n_humans, humans_now, humans_vel: the tracks' own, humans_pred:
 * their constant-velocity predictions, made here and nowhere else) and out (people_index,
 * people_ids, predictions): first everyone within the stopping reach of a robot at up to v_cap (m/s) under
 * p (monitor_stopping_reach), nearest first; then those nearest to the robot's expected path over the
 * horizon (not only now). */
HM_FUNC void controller_select_people(hm_real path[HM_N + 1][2], const hm_controller_input *cin, const hm_params *p,
                                      hm_real v_cap, hm_input *in, hm_controller_output *out);

/* The obstacle point the robot could reach soonest into in->obstacle (in->has_obstacle = 0 without
 * points): the smallest, over the robot's position and the expected path's nodes, of the way there
 * (node n: n intervals at `speed`, m/s) plus the distance from there, in metres. The OCP has one
 * obstacle row for all nodes: the point nearest to the robot alone lets the plan cut a wall's corner
 * a few nodes ahead; the point nearest to any node lets it drift into the wall beside it while a
 * corner further on holds the row. */
HM_FUNC void controller_nearest_obstacle(hm_real path[HM_N + 1][2], const hm_controller_input *cin, hm_real speed,
                                         hm_input *in);

/* The smallest monitor_separation_speed over every track (not only the N_h the OCP sees), for a robot
 * at x0 heading along (cos_t, sin_t): HM_INF when none binds below v_cap, or without
 * params->separation. */
HM_FUNC hm_real controller_separation_bound(const hm_controller_input *cin, const hm_real *x0, hm_real cos_t,
                                            hm_real sin_t, hm_real v_cap, const hm_params *params);

#endif /* CONTROLLER_PEOPLE_H */
