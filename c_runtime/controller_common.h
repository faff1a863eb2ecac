/*
 * controller_common.h: what the controller's parts share: the runtime's names for the public
 * controller types, its sizes and small geometric helpers. The controller is the layer above the
 * solver (ocp_nlp_*): it turns what a robot perceives (odometry, a path or a goal, tracked people,
 * obstacle points) into the solver's input and parameters, and the solver's output into a command.
 *
 * Sizes from the including translation unit: HM_MAX_TRACKS tracks, HM_MAX_PATH_POINTS path points,
 * HM_MAX_OBSTACLE_POINTS obstacle points, HM_NH the solver's people (N_h).
 */
#ifndef CONTROLLER_COMMON_H
#define CONTROLLER_COMMON_H
#include "hm_common.h"
#include "ocp_nlp_common.h"

typedef HM_NS(controller) hm_controller;
typedef HM_NS(controller_params) hm_controller_params;
typedef HM_NS(controller_input) hm_controller_input;
typedef HM_NS(controller_output) hm_controller_output;

/* What a controller step ended with (rows of hm_status.h; fixed values, public API). */
enum hm_outcome { HM_OUTCOME_TABLE(HM_STATUS_ENUM_ROW) };

#define HM_PI HM_R(3.14159265358979323846)

/* The goal the OCP sees this period, from the path or the goal pose (controller_path.c). */
typedef struct hm_controller_goal {
    int has;              /* 0: no path and no goal */
    hm_real carrot[3];    /* [x, y, theta]: the point lookahead metres along the path, its heading */
    hm_real final[3];     /* the final goal [x, y, theta] */
    hm_real left;         /* [m] distance left along the path from the robot's projection */
    hm_real to_final;     /* [m] straight distance from the robot to the final goal */
    hm_real s_proj;       /* [m] the robot's projection: arc length along the path from its start */
    hm_real length;       /* [m] the path's length */
} hm_controller_goal;

/* angle + 2 pi k nearest to reference */
HM_FUNC hm_real controller_unwrap(hm_real angle, hm_real reference);
/* The bearing of the OCP's goal (the carrot, in->goal) from a robot at x, in (-pi, pi]. */
HM_FUNC hm_real controller_carrot_bearing(const hm_input *in, const hm_real *x);

#endif /* CONTROLLER_COMMON_H */
