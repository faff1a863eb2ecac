/*
 * ocp_nlp_step.c: the step of an SQP iteration from its QP's solution: the full step (real-time
 * iteration) or a backtracking line search on the l1 merit (full SQP, and the real-time iteration
 * with line_search). The QP's multipliers are the NLP's: the QP writes its solution into s->mult.
 * The linearisation point is kept in x_base, u_base for the step's duration.
 */
#include "ocp_nlp_step.h"

#include "ocp_nlp_cost.h"
#include "ocp_nlp_lin.h"
#include "ocp_nlp_screen.h"

/* Iterate = base + alpha * QP step (base: the linearisation point, kept in x_base/u_base). */
static void ocp_nlp_step_from_base(hm_solver *s, hm_real alpha)
{
    int n, i;
    const hm_ocp_qp_sol *d = &s->mult;
    s->dyn_fresh = 0;
    for (n = 0; n <= HM_N; n++)
        for (i = 0; i < HM_NX; i++) s->x[n][i] = s->x_base[n][i] + alpha * d->x[n][i];
    for (n = 0; n < HM_N; n++)
        for (i = 0; i < HM_NU; i++) s->u[n][i] = s->u_base[n][i] + alpha * d->u[n][i];
}

static void ocp_nlp_save_base(hm_solver *s)
{
    int n, i;
    for (n = 0; n <= HM_N; n++)
        for (i = 0; i < HM_NX; i++) s->x_base[n][i] = s->x[n][i];
    for (n = 0; n < HM_N; n++)
        for (i = 0; i < HM_NU; i++) s->u_base[n][i] = s->u[n][i];
}

/* Solve the QP; when usable, take the full step (real-time iteration). */
HM_FUNC int ocp_nlp_qp_step(hm_solver *s, const hm_input *in, int shifted, int *qp_iter)
{
    const int status = ocp_nlp_qp_solve(s, in, s->params.qp_tol, 0, shifted, qp_iter);
    if (!ocp_nlp_qp_usable(status)) return status;
    ocp_nlp_save_base(s);
    ocp_nlp_step_from_base(s, HM_R(1.0));
    return status;
}

/* l1 merit of the iterate: the objective with the soft-row penalties (ocp_nlp_objective) + mu *
 * (|dynamics gaps|_1 + |x_0 - measured x0|_1). Bounds are linear, so every step of the line search
 * keeps those its base kept; the speed-and-separation bounds, which move with the iterate, count with
 * their excess. */
static hm_real ocp_nlp_merit(const hm_solver *s, const hm_input *in, hm_real mu)
{
    hm_real gaps = HM_R(0.0);
    int n, i;
    for (i = 0; i < HM_NX; i++) gaps += hm_fabs(s->x[0][i] - in->x0[i]);
    for (n = 0; n < HM_N; n++) {
        hm_real x_next[HM_NX], A[HM_NX * HM_NX], B[HM_NX * HM_NU];
        hm_model_dynamics(s->x[n], s->u[n], x_next, A, B);
        for (i = 0; i < HM_NX; i++) gaps += hm_fabs(x_next[i] - s->x[n + 1][i]);
    }
    return ocp_nlp_objective(s, in) + mu * gaps;
}

/* Full SQP step with a backtracking line search on the l1 merit (Armijo on the decrease that the
 * QP model predicts); mu grows to stay above the dynamics multipliers, as exactness requires. */
HM_FUNC int ocp_nlp_qp_line_search_step(hm_solver *s, const hm_input *in, hm_real tol, int shifted,
                                       int *qp_iter)
{
    /* The QP must be solved at least as tightly as the SQP is asked to converge. */
    const int status = ocp_nlp_qp_solve(s, in, hm_fmin(s->params.qp_tol, HM_R(0.1) * tol), 1, shifted, qp_iter);
    hm_real gaps = HM_R(0.0), pi_max = HM_R(0.0), merit0, predicted, alpha = HM_R(1.0);
    int n, i;
    if (!ocp_nlp_qp_usable(status)) return status;
    for (i = 0; i < HM_NX; i++) gaps += hm_fabs(s->qp.x0[i]);
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NX; i++) {
            gaps += hm_fabs(s->qp.b[n][i]);
            pi_max = hm_fmax(pi_max, hm_fabs(s->mult.pi[n][i]));
        }
    }
    s->merit_mu = hm_fmax(s->merit_mu, HM_R(2.0) * pi_max + HM_R(1.0));
    merit0 = s->cost + s->merit_mu * gaps;
    /* The QP model of the merit after the full step: smooth objective + QP objective (its slack
     * penalties included) and linearised gaps closed. */
    predicted = merit0 - (s->cost - s->cost_slack + s->ipm_ws.out.res.obj);
    ocp_nlp_save_base(s);
    for (;;) {
        ocp_nlp_step_from_base(s, alpha);
        if (alpha <= HM_R(1e-4)) break;
        if (ocp_nlp_merit(s, in, s->merit_mu) <= merit0 - HM_R(1e-4) * alpha * hm_fmax(predicted, HM_R(0.0)))
            break;
        alpha *= HM_R(0.5);
    }
    return status;
}
