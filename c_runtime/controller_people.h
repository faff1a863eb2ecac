/*
 * controller_people.h: the people and the obstacle the OCP sees in one period
 * (controller_people.c): constant-velocity predictions of the tracks, the N_h most relevant of them,
 * and the obstacle point nearest to the robot's expected path.
 */
#ifndef CONTROLLER_PEOPLE_H
#define CONTROLLER_PEOPLE_H
#include "controller_common.h"

/* The N_h tracks nearest to the robot's expected path over the horizon (not only now) into the
 * solver's input (in->n_humans, humans_now, humans_pred) and out (people_index, people_ids,
 * predictions). The expected path: the solver's last plan advanced by one interval when it has one,
 * else the robot going straight on at its measured speed. */
HM_FUNC void controller_select_people(const hm_solver *s, const hm_controller_input *cin, hm_input *in,
                                      hm_controller_output *out);

/* The obstacle point the robot could reach soonest into in->obstacle (in->has_obstacle = 0 without
 * points): the smallest over the expected path's nodes of the time to reach node n (at `speed`, m/s)
 * plus the distance from there, in metres. The OCP has one obstacle row for all nodes: the point
 * nearest to the robot alone lets the plan cut a wall's corner a few nodes ahead; the point nearest to
 * any node lets it drift into the wall beside it while a corner further on holds the row. */
HM_FUNC void controller_nearest_obstacle(const hm_solver *s, const hm_controller_input *cin, hm_real speed,
                                         hm_input *in);

#endif /* CONTROLLER_PEOPLE_H */
