/*
 * ocp_nlp_sqp.h: Gauss-Newton SQP over the human-aware OCP: real-time iteration (preparation +
 * feedback, one QP per control step) and a full SQP that iterates to a tolerance.
 *
 * The NLP (paper, eq. 1, with the runtime parameters of <name>_params):
 *   min  sum_{n<N} ||x_n - g||^2_Wg + ||u_n||^2_Wu + sum_i f(d(p_n, h_{i,n}))
 *        + ||x_N - g||^2_WgN + sum_i f(d(p_N, h_{i,N})) + slack penalties
 *   s.t. x_0 = measured state, x_{n+1} = F(x_n, u_n), bounds on v (n >= 1), a and omega,
 *        d(p_n, h_{i,0}) + s_{i,n} >= d_h   (humans' current positions; exact penalty on s)
 *        d(p_n, o) + s_n >= d_s             (closest obstacle; L1 + L2 penalty on s)
 * for n = 1..N. The human rows are exact-penalty soft rows: with a penalty above every multiplier
 * the optimum of the hard problem is kept whenever it exists, and the QP stays feasible when it
 * does not (a human already too close, a linearisation that cannot reach the half-plane). The
 * true constraint is guarded by the safety monitor.
 *
 * Model functions are supplied by the including translation unit as the macros hm_model_dynamics,
 * hm_model_dynamics_hessian, hm_model_cost_stage, hm_model_cost_terminal, hm_model_cost_collision,
 * hm_model_cost_collision_gn and hm_model_distance_constraint (the generated CasADi wrappers).
 */
#ifndef OCP_NLP_SQP_H
#define OCP_NLP_SQP_H

#include "hm_common.h"
#include "hm_timing.h"

/* HM_DT: the interval length, from the including translation unit. */

typedef HM_NS(params) hm_params;
typedef HM_NS(input) hm_input;
typedef HM_NS(output) hm_output;
typedef HM_NS(clock_fn) hm_clock_fn;
typedef HM_NS(solver) hm_solver;

/* Status of a solver step. Fixed values: part of the public C and Python API. */
enum hm_status {
    HM_STATUS_OK = 0,        /* RTI: QP solved, step taken. Full SQP: converged to the tolerance */
    HM_STATUS_MAX_ITER = 1,  /* RTI: QP stopped at its iteration limit (step taken). SQP: not converged */
    HM_STATUS_QP_FAILED = 2, /* the QP failed (see qp_status): no step taken, next step starts cold */
    HM_STATUS_SKIPPED = 3    /* nothing solved: inputs unusable or a human already too close (see stop) */
};

HM_FUNC void ocp_nlp_sqp_init(hm_solver *s, const hm_params *params);
HM_FUNC void ocp_nlp_sqp_reset(hm_solver *s);
HM_FUNC void ocp_nlp_sqp_rti_prepare(hm_solver *s, const hm_input *in);
HM_FUNC int ocp_nlp_sqp_rti_feedback(hm_solver *s, const hm_input *in, hm_output *out);
HM_FUNC int ocp_nlp_sqp_rti_step(hm_solver *s, const hm_input *in, hm_output *out);
HM_FUNC int ocp_nlp_sqp_solve(hm_solver *s, const hm_input *in, hm_output *out, int max_iter, hm_real tol);
HM_FUNC const char *ocp_nlp_status_message(int status);

#endif /* OCP_NLP_SQP_H */
