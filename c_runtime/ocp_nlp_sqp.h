/*
 * ocp_nlp_sqp.h: the solver object (init, reset) and the full SQP, which iterates to a tolerance
 * (ocp_nlp_sqp.c); the real-time iteration is ocp_nlp_rti.h, the NLP ocp_nlp_common.h.
 */
#ifndef OCP_NLP_SQP_H
#define OCP_NLP_SQP_H

#include "ocp_nlp_common.h"

HM_FUNC void ocp_nlp_sqp_init(hm_solver *s, const hm_params *params);
HM_FUNC void ocp_nlp_sqp_reset(hm_solver *s);
/* The full SQP, under the monitors of the real-time iteration (inputs, parameters, every QP solved, the
 * deadline of params.deadline_ms from now, the clock, C1 / C2, the command guard): a failure of any is a
 * protective stop; max_iter < 1 or tol not positive and finite an invalid input. */
HM_FUNC int ocp_nlp_sqp_solve(hm_solver *s, const hm_input *in, hm_output *out, int max_iter, hm_real tol);
/* The same with the deadline counted from the clock reading t0 (a recovery inside a control period). */
HM_FUNC int ocp_nlp_sqp_solve_timed(hm_solver *s, const hm_input *in, hm_output *out, int max_iter, hm_real tol,
                                    unsigned long long t0);
/* A candidate plan's iterations (the controller's passing decisions): those of ocp_nlp_sqp_solve_timed (the
 * line search on the l1 merit, its QPs cold-started) with two differences. Its QPs evaluate their residuals by
 * the recurrence, as the real-time iteration's (the reference's exact ones in every interior-point iteration
 * are for tolerances far below the QP's); nothing that only reports is computed: no KKT residuals (the kkt_*
 * of out zero, the status HM_STATUS_MAX_ITER after max_iter iterations, never tested for convergence), and
 * out->cost is the reference's own, bit for bit, without its final linearisation (ocp_nlp_plan_cost). */
HM_FUNC int ocp_nlp_sqp_candidate_step(hm_solver *s, const hm_input *in, hm_output *out, int max_iter, hm_real tol,
                                       unsigned long long t0);
HM_FUNC const char *ocp_nlp_status_message(int status);

#endif /* OCP_NLP_SQP_H */
