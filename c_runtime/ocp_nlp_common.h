/*
 * ocp_nlp_common.h: what every part of the NLP layer shares: the NLP itself, the runtime's names
 * for the public header's parameter, input, output and solver types (which the monitor reads too),
 * the status of a solver step, and three stateless helpers (ocp_nlp_common.c). The layer's lowest
 * header: the monitor includes it, and it includes nothing of the layer.
 *
 * The NLP (paper, eq. 1, with the runtime parameters of <name>_params):
 *   min  sum_{n<N} ||x_n - g||^2_Wg + ||u_n||^2_Wu + sum_i f(d(p_n, h_{i,n}))
 *        + ||x_N - g||^2_WgN + sum_i f(d(p_N, h_{i,N})) + slack penalties
 *   s.t. x_0 = measured state, x_{n+1} = F(x_n, u_n), bounds on v (n >= 1), a and omega,
 *        d(p_n, h_{i,0}) + s_{i,n} >= d_h   (humans' current positions; exact penalty on s)
 *        d(p_n, o) + s_n >= d_s             (closest obstacle; L1 + L2 penalty on s)
 *        v_n <= speed-and-separation bound  (params.separation: from node n - 1's geometry, frozen at
 *                                            the linearisation point; monitor_separation_speed)
 * for n = 1..N. The human rows are exact-penalty soft rows: with a penalty above every multiplier
 * the optimum of the hard problem is kept whenever it exists, and the QP stays feasible when it
 * does not (a human already too close, a linearisation that cannot reach the half-plane). The
 * true constraint is guarded by the safety monitor.
 *
 * Model functions are supplied by the including translation unit as the macros hm_model_dynamics,
 * hm_model_dynamics_hessian, hm_model_cost_stage, hm_model_cost_terminal, hm_model_cost_collision,
 * hm_model_cost_collision_gn and hm_model_distance_constraint (the generated CasADi wrappers).
 */
#ifndef OCP_NLP_COMMON_H
#define OCP_NLP_COMMON_H

#include "hm_common.h"
#include "hm_timing.h"

/* HM_DT: the interval length, from the including translation unit. */

typedef HM_NS(params) hm_params;
typedef HM_NS(input) hm_input;
typedef HM_NS(output) hm_output;
typedef HM_NS(clock_fn) hm_clock_fn;
typedef HM_NS(solver) hm_solver;

/* Status of a solver step (rows of hm_status.h; fixed values, part of the public C and Python API).
 * HM_STATUS_OK: RTI: QP solved, step taken; full SQP: converged to the tolerance. HM_STATUS_MAX_ITER:
 * RTI: QP stopped at its iteration limit (step taken); SQP: not converged. HM_STATUS_QP_FAILED: the QP
 * failed (see qp_status): no step taken, the next step starts cold. HM_STATUS_SKIPPED: nothing solved:
 * inputs unusable or a human already too close (see stop). */
enum hm_status { HM_STATUS_TABLE(HM_STATUS_ENUM_ROW) };

/* The present humans of the input, their count clamped to 0..HM_NG - 1. */
HM_FUNC int ocp_nlp_clamp_humans(const hm_input *in);
/* The goal the cost of node n tracks: in->refs[n] with per-node goals (in->has_refs), else in->goal. */
HM_FUNC const hm_real *ocp_nlp_goal_at(const hm_input *in, int n);

/* The solver's clock now (0 without a clock). */
HM_FUNC unsigned long long ocp_nlp_now(const hm_solver *s);

/* The deadline of a step: params.deadline_ms from t_start (a clock reading), polled by
 * ocp_nlp_deadline_passed (the QP iterations' hook; ctx is the solver). */
HM_FUNC void ocp_nlp_start_clock(hm_solver *s, unsigned long long t_start);
HM_FUNC int ocp_nlp_deadline_passed(void *ctx);
/* A QP status whose solution is a step the SQP may take (solved, or at its iteration limit). */
HM_FUNC int ocp_nlp_qp_usable(int status);

/* The clock monitor, at the end of a step that solved, with the clock's last reading t_end: 1 when the
 * clock ran backwards during the step (a reading before t_start, here or inside the QPs), or did not
 * advance over it although a QP was solved (stuck: no deadline could ever fire). A clock must tick
 * within one QP solve (microseconds; POSIX's and a Cortex-M SysTick's do). Without a clock: 0 (the
 * deadline is off by the caller's choice, hm_timing.h). */
HM_FUNC int ocp_nlp_clock_fault(hm_solver *s, unsigned long long t_end);

#endif /* OCP_NLP_COMMON_H */
