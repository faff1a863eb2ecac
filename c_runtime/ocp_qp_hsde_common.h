/*
 * ocp_qp_hsde_common.h: what the files of the fallback solver (ocp_qp_hsde*.c) share: max without
 * libm. No state.
 */
#ifndef OCP_QP_HSDE_COMMON_H
#define OCP_QP_HSDE_COMMON_H

#include "hm_common.h"

/* max without libm's fmax call (whose NaN rule is not needed here: NaN is caught on the sums) */
#define OCP_QP_HSDE_MAX(a, b) ((a) > (b) ? (a) : (b))

#endif /* OCP_QP_HSDE_COMMON_H */
