/*
 * ocp_qp_ipm_polish.h: the active-set polish of an interior-point solution (ocp_qp_ipm_polish.c),
 * compiled in with HM_QP_POLISH (ocp_qp_ipm_types.h).
 */
#ifndef OCP_QP_IPM_POLISH_H
#define OCP_QP_IPM_POLISH_H

#include "hm_common.h"

#ifdef HM_QP_POLISH
/* Whether some inequality is undecided after the last step (alpha, dt, dz): neither its slack nor
 * its multiplier fell below OCP_QP_IPM_UNDEC of its value (arg->polish = 2 polishes only then). */
HM_FUNC int ocp_qp_ipm_undecided(const hm_ocp_qp_ipm_ws *ws, hm_real alpha);

/* Solves qp once more on the active set of the iterate and keeps the result in sol (and its residuals
 * in ws->out.res, ws->out.polished = 1) only if its worst KKT residual is below ws->out.res's; else
 * sol is the iterate. */
HM_FUNC void ocp_qp_ipm_polish(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_ipm_ws *ws, hm_real alpha);
#endif

#endif /* OCP_QP_IPM_POLISH_H */
