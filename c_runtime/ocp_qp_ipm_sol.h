/*
 * ocp_qp_ipm_sol.h: the QP solution (ocp_qp_sol) from the interior-point method's iterate or from a
 * vector in its layout (ocp_qp_ipm_sol.c).
 */
#ifndef OCP_QP_IPM_SOL_H
#define OCP_QP_IPM_SOL_H

#include "hm_common.h"

/* sol := the iterate with the primal part scaled by sp (1) and the multipliers by sc
 * (1 / cost scale); or, with sp = 0, the certificate w scaled by sc (1 / -b'w). */
HM_FUNC void ocp_qp_ipm_write_sol(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, hm_ocp_qp_sol *sol,
                                  hm_real sc, hm_real sp);

/* sol := the certificate of ocp_qp_ipm_farkas_step (the last step's multiplier steps clipped at 0)
 * scaled by sc (1 / -b'w); primal part zero but x_0 = x0. */
HM_FUNC void ocp_qp_ipm_write_sol_ray(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, hm_ocp_qp_sol *sol,
                                      hm_real sc);

#ifdef HM_QP_POLISH
/* The same as ocp_qp_ipm_write_sol from a vector in the solver's layout (the polished solution). */
HM_FUNC void ocp_qp_ipm_write_sol_vec(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws,
                                      const hm_ocp_qp_ipm_vec *v, hm_ocp_qp_sol *sol, hm_real sc);
#endif

#endif /* OCP_QP_IPM_SOL_H */
