/*
 * controller_common.c: the controller's shared helpers (controller_common.h).
 */
#include "controller_common.h"

HM_FUNC hm_real controller_unwrap(hm_real angle, hm_real reference)
{
    const hm_real turns = hm_floor((reference - angle) / (HM_R(2.0) * HM_PI) + HM_R(0.5));
    return angle + turns * HM_R(2.0) * HM_PI;
}

/* The bearing of the carrot from a robot at x, in (-pi, pi]. */
HM_FUNC hm_real controller_carrot_bearing(const hm_input *in, const hm_real *x)
{
    const hm_real e = hm_atan2(in->goal[1] - x[1], in->goal[0] - x[0]) - x[2];
    return hm_atan2(hm_sin(e), hm_cos(e));
}
