/*
 * ocp_nlp_iterate.h: a solver's warm start kept aside (ocp_nlp_iterate.c), so that other solves may use
 * the solver's memory between two of its steps and the next step runs as if they had not: the
 * controller's candidate plans are solved in its solver's workspace, not in solvers of their own.
 *
 * What is kept is what the next step reads before writing it: the iterate (x, u), the multipliers the
 * next linearisation reads with the exact Hessian (pi, lam_lg; the others are shifted with them but only
 * enter the residuals, which come after the next QP has written them), the screening radii, the measured
 * state of the jump test, the flags (warm, prepared, dyn_fresh, the QP's kept iterate being ready), the QP
 * options and the small counters and times. Not kept: the QP data, the interior-point workspace and the
 * line search's base point, which every step sets up before reading. The QP's kept iterate itself
 * (ipm_ws.warm but for its flag) is not copied: only a solve with warm_mu > 0 writes it, which the
 * real-time iteration is and the full SQP (ocp_nlp_sqp_solve*) is not; the solves in between must be of
 * the latter kind.
 */
#ifndef OCP_NLP_ITERATE_H
#define OCP_NLP_ITERATE_H

#include "ocp_nlp_common.h"

typedef HM_NS(ocp_nlp_iterate) hm_ocp_nlp_iterate;

HM_FUNC void ocp_nlp_iterate_save(const hm_solver *s, hm_ocp_nlp_iterate *it);
/* Puts back what ocp_nlp_iterate_save kept; the parameters, clock and kept QP iterate were not changed. */
HM_FUNC void ocp_nlp_iterate_restore(hm_solver *s, const hm_ocp_nlp_iterate *it);

#endif /* OCP_NLP_ITERATE_H */
