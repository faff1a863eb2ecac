/*
 * controller_common.c: the controller's shared helpers (controller_common.h).
 */
#include "controller_common.h"

HM_FUNC hm_real controller_unwrap(hm_real angle, hm_real reference)
{
    const hm_real turns = hm_floor((reference - angle) / (HM_R(2.0) * HM_PI) + HM_R(0.5));
    return angle + turns * HM_R(2.0) * HM_PI;
}
