/*
 * ocp_nlp_screen.h: the QP solve of an SQP iteration with row screening (ocp_nlp_screen.c).
 */
#ifndef OCP_NLP_SCREEN_H
#define OCP_NLP_SCREEN_H

#include "ocp_nlp_common.h"

/* Screening radii for a guess that is not the previous QP's solution: the distance the robot can
 * cover by each node, plus the margin. */
HM_FUNC void ocp_nlp_screen_reach(hm_solver *s);

/* Solve the QP of the current linearisation (its x0 offset set; in: its input), screened, to tol; residuals: the
 * solver's residuals of the returned solution (ocp_qp_ipm_arg); shifted: warm start from the iterate
 * the last solve kept, a stage on. Adds the iterations to *qp_iter; returns the QP status. */
HM_FUNC int ocp_nlp_qp_solve(hm_solver *s, const hm_input *in, hm_real tol, int residuals, int shifted, int *qp_iter);

/* The plain distance beyond which a row of node n with minimum distance d_min is screened whatever its
 * exact margin (HM_INF: screening off, no row is far), and the test of a row of the point c at the
 * node x against it: far rows are left unevaluated by the linearisation. */
HM_FUNC hm_real ocp_nlp_screen_far_reach(const hm_solver *s, int n, hm_real d_min);
HM_FUNC int ocp_nlp_screen_far(const hm_real *x, const hm_real *c, hm_real reach);

#endif /* OCP_NLP_SCREEN_H */
