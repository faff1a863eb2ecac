/*
 * ocp_nlp_sqp.c: Gauss-Newton SQP over the human-aware OCP (see ocp_nlp_sqp.h).
 *
 * Warm start (real-time iteration): the previous plan is shifted by one interval and its controls
 * are re-simulated from the predicted state x_1, so the linearisation has no dynamics gaps. Large
 * gaps are what make linearised human half-planes unreachable after bang-bang steps (measured with
 * acados on this problem); re-simulation removes them before the QP sees them. The measured state
 * enters in the feedback phase as the QP's initial-state offset only.
 */
#include "ocp_nlp_sqp.h"

#include "monitor.h"
#include "ocp_qp.h"
#include "ocp_qp_ipm.h"

/* Each RTI QP keeps its first iterate after the start with mu <= this (scaled; 1 at the cold start)
 * for the next step's QP to start from (ocp_qp_ipm.c, warm start). */
#define OCP_NLP_WARM_MU HM_R(0.2)

static int ocp_nlp_clamp_humans(const hm_input *in)
{
    int nh = in->n_humans;
    if (nh < 0) nh = 0;
    if (nh > HM_NG - 1) nh = HM_NG - 1;
    return nh;
}

static unsigned long long ocp_nlp_now(const hm_solver *s)
{
    return s->clock ? s->clock(s->clock_ctx) : 0ULL;
}

HM_FUNC void ocp_nlp_sqp_init(hm_solver *s, const hm_params *params)
{
    s->params = *params;
    ocp_qp_ipm_arg_set_default(&s->ipm_arg);
    /* Every QP of the SQP is bounded by construction (box bounds on both inputs of every stage, the
     * states follow from them, soft slacks cost zl >= 0 and only relax their rows): a ray test could
     * only give false positives, and in single precision it did (a large early step whose cost
     * decrease dwarfs its rounding-level residuals, RTI replays with 30 humans). */
    s->ipm_arg.detect_unbounded = 0;
    s->ipm_arg.warm_mu = OCP_NLP_WARM_MU;
#if defined(HM_HAVE_POSIX_CLOCK)
    s->clock = hm_clock_posix_ns;
#else
    s->clock = 0;
#endif
    s->clock_ctx = 0;
    ocp_nlp_sqp_reset(s);
}

HM_FUNC void ocp_nlp_sqp_reset(hm_solver *s)
{
    int n, i;
    s->warm = 0;
    s->prepared = 0;
    s->ipm_ws.warm.ready = 0;
    s->dyn_fresh = 0;
    for (n = 0; n < HM_N; n++)
        for (i = 0; i < HM_NU; i++) s->u[n][i] = HM_R(0.0);
    for (n = 0; n <= HM_N; n++)
        for (i = 0; i < HM_NX; i++) s->x[n][i] = HM_R(0.0);
    s->cost = HM_R(0.0);
    s->time_prepare_ms = HM_R(0.0);
    s->screen_radius[0] = HM_INF;
}

/* x_{n+1} = F(x_n, u_n) for n = 0..N-1 from the given x_0. The Jacobians come with the model's
 * values; they are kept in the QP for the linearisation that follows (s->dyn_fresh). */
static void ocp_nlp_simulate(hm_solver *s)
{
    int n;
    for (n = 0; n < HM_N; n++) hm_model_dynamics(s->x[n], s->u[n], s->x[n + 1], s->qp.A[n], s->qp.B[n]);
    s->dyn_fresh = 1;
}

/* a[r][.] <- a[r + 1][.] for r < rows - 1; the last row is kept. */
static void ocp_nlp_shift_rows(hm_real *a, int rows, int cols)
{
    int k;
    for (k = 0; k < (rows - 1) * cols; k++) a[k] = a[k + cols];
}

/* Screening radii for a guess that is not the previous QP's solution (cold start, braking retry):
 * the distance the robot can cover by node n at its top speed, plus the margin (the QP's plan may
 * leave the guess anywhere within it; rows found violated are admitted all the same). */
static void ocp_nlp_screen_reach(hm_solver *s)
{
    const hm_real vmax = hm_fmax(hm_fabs(s->params.v_bounds[0]), hm_fabs(s->params.v_bounds[1]));
    int n;
    for (n = 0; n <= HM_N; n++) s->screen_radius[n] = HM_R(0.5) + vmax * HM_R(HM_DT) * (hm_real)n;
}

/* Initial guess of the next step: the previous plan shifted by one interval (the last control
 * repeated), re-simulated from the predicted state; or, cold, the controls held at zero from x0. */
static void ocp_nlp_shift(hm_solver *s, const hm_input *in)
{
    int n, i;
    if (!s->warm) {
        for (i = 0; i < HM_NX; i++) s->x[0][i] = in->x0[i];
        for (n = 0; n < HM_N; n++)
            for (i = 0; i < HM_NU; i++) s->u[n][i] = HM_R(0.0);
        ocp_nlp_screen_reach(s); /* no previous step to size the screening by */
    } else {
        hm_ocp_qp_sol *m = &s->mult;
        for (i = 0; i < HM_NX; i++) s->x[0][i] = s->x[1][i];
        for (n = 0; n + 1 < HM_N; n++)
            for (i = 0; i < HM_NU; i++) s->u[n][i] = s->u[n + 1][i];
        /* The multipliers follow their stages (they only enter the reported residuals). */
        ocp_nlp_shift_rows(&m->pi[0][0], HM_N, HM_NX);
        ocp_nlp_shift_rows(&m->lam_lbu[0][0], HM_N, HM_NU);
        ocp_nlp_shift_rows(&m->lam_ubu[0][0], HM_N, HM_NU);
        ocp_nlp_shift_rows(&m->lam_lbx[0][0], HM_N + 1, HM_NX);
        ocp_nlp_shift_rows(&m->lam_ubx[0][0], HM_N + 1, HM_NX);
        ocp_nlp_shift_rows(&m->lam_lg[0][0], HM_N + 1, HM_NG);
        ocp_nlp_shift_rows(&m->lam_ls[0][0], HM_N + 1, HM_NG);
    }
    ocp_nlp_simulate(s);
}

/* The safe fallback guess: brake to standstill within the acceleration bound, without turning,
 * from the measured state. Whenever braking keeps d_h, this guess satisfies every human row, so
 * the QP linearised at it (zero step feasible, rows convex) returns a plan that keeps d_h too. */
static void ocp_nlp_init_braking(hm_solver *s, const hm_input *in)
{
    const hm_real a_min = s->params.a_bounds[0], a_max = s->params.a_bounds[1];
    int n, i;
    for (i = 0; i < HM_NX; i++) s->x[0][i] = in->x0[i];
    for (n = 0; n < HM_N; n++) {
        s->u[n][0] = hm_fmin(hm_fmax(-s->x[n][3] / HM_R(HM_DT), a_min), a_max);
        s->u[n][1] = HM_R(0.0);
        hm_model_dynamics(s->x[n], s->u[n], s->x[n + 1], s->qp.A[n], s->qp.B[n]);
    }
    s->dyn_fresh = 1;
    ocp_qp_sol_set_zero(&s->mult);
    ocp_nlp_screen_reach(s);
}

static hm_real ocp_nlp_slack_penalty(hm_real g, hm_real l1, hm_real l2)
{
    /* The slack a row needs at this point: s = max(0, -g). */
    const hm_real sl = g < HM_R(0.0) ? -g : HM_R(0.0);
    return l1 * sl + HM_R(0.5) * l2 * sl * sl;
}

/* Symmetric n x n M (column-major, n <= 6) replaced by its projection onto {eigenvalues >= floor}:
 * cyclic Jacobi rotations, then V max(Lambda, floor) V'. */
static void ocp_nlp_project_psd(hm_real *M, int n, hm_real floor)
{
    hm_real V[36], off, total = HM_R(0.0);
    int i, j, k, sweep;
    for (i = 0; i < n * n; i++) {
        V[i] = HM_R(0.0);
        total += M[i] * M[i];
    }
    for (i = 0; i < n; i++) V[i + i * n] = HM_R(1.0);
    for (sweep = 0; sweep < 30; sweep++) {
        off = HM_R(0.0);
        for (i = 0; i < n; i++)
            for (j = i + 1; j < n; j++) off += M[i + j * n] * M[i + j * n];
        if (off <= HM_EPS * HM_EPS * total) break;
        for (i = 0; i < n; i++) {
            for (j = i + 1; j < n; j++) {
                const hm_real mij = M[i + j * n];
                hm_real theta, t, c, sn;
                if (mij == HM_R(0.0)) continue;
                theta = (M[j + j * n] - M[i + i * n]) / (HM_R(2.0) * mij);
                t = (theta >= HM_R(0.0) ? HM_R(1.0) : HM_R(-1.0)) / (hm_fabs(theta) + hm_sqrt(theta * theta + HM_R(1.0)));
                c = HM_R(1.0) / hm_sqrt(t * t + HM_R(1.0));
                sn = t * c;
                for (k = 0; k < n; k++) { /* M <- M J */
                    const hm_real a = M[k + i * n], b = M[k + j * n];
                    M[k + i * n] = c * a - sn * b;
                    M[k + j * n] = sn * a + c * b;
                }
                for (k = 0; k < n; k++) { /* M <- J' M */
                    const hm_real a = M[i + k * n], b = M[j + k * n];
                    M[i + k * n] = c * a - sn * b;
                    M[j + k * n] = sn * a + c * b;
                }
                for (k = 0; k < n; k++) { /* V <- V J */
                    const hm_real a = V[k + i * n], b = V[k + j * n];
                    V[k + i * n] = c * a - sn * b;
                    V[k + j * n] = sn * a + c * b;
                }
            }
        }
    }
    {
        hm_real lam[6];
        for (k = 0; k < n; k++) lam[k] = hm_fmax(M[k + k * n], floor);
        for (i = 0; i < n; i++) {
            for (j = 0; j < n; j++) {
                hm_real acc = HM_R(0.0);
                for (k = 0; k < n; k++) acc += V[i + k * n] * lam[k] * V[j + k * n];
                M[i + j * n] = acc;
            }
        }
    }
}

/* Stage n's Hessian blocks [Q S'; S R] (or Q alone at n = N) projected onto the PSD cone. */
static void ocp_nlp_convexify_stage(hm_ocp_qp *qp, int n, hm_real floor)
{
    hm_real M[36];
    const int nz = n < HM_N ? HM_NX + HM_NU : HM_NX;
    int i, j;
    for (j = 0; j < HM_NX; j++)
        for (i = 0; i < HM_NX; i++) M[i + j * nz] = qp->Q[n][i + j * HM_NX];
    if (n < HM_N) {
        for (j = 0; j < HM_NX; j++)
            for (i = 0; i < HM_NU; i++) {
                M[HM_NX + i + j * nz] = qp->S[n][i + j * HM_NU];
                M[j + (HM_NX + i) * nz] = qp->S[n][i + j * HM_NU];
            }
        for (j = 0; j < HM_NU; j++)
            for (i = 0; i < HM_NU; i++) M[HM_NX + i + (HM_NX + j) * nz] = qp->R[n][i + j * HM_NU];
    }
    ocp_nlp_project_psd(M, nz, floor);
    for (j = 0; j < HM_NX; j++)
        for (i = 0; i < HM_NX; i++) qp->Q[n][i + j * HM_NX] = M[i + j * nz];
    if (n < HM_N) {
        for (j = 0; j < HM_NX; j++)
            for (i = 0; i < HM_NU; i++) qp->S[n][i + j * HM_NU] = M[HM_NX + i + j * nz];
        for (j = 0; j < HM_NU; j++)
            for (i = 0; i < HM_NU; i++) qp->R[n][i + j * HM_NU] = M[HM_NX + i + (HM_NX + j) * nz];
    }
}

/* Build the QP of the current iterate (everything but the initial-state offset) and the NLP
 * objective there. Rows: the present humans first, then the obstacle; absent ones cost nothing.
 * exact = 0: Gauss-Newton Hessian (PSD by construction). exact = 1: the Hessian of the Lagrangian
 * with the multipliers in s->mult, projected per stage onto the PSD cone (full SQP). */
static void ocp_nlp_linearize(hm_solver *s, const hm_input *in, int exact)
{
    const hm_params *p = &s->params;
    hm_ocp_qp *qp = &s->qp;
    const int nh = ocp_nlp_clamp_humans(in);
    const int ng = nh + (in->has_obstacle ? 1 : 0);
    const hm_real reg = p->regularization;
    hm_real cost = HM_R(0.0), penalty = HM_R(0.0);
    int n, i, j;

    for (n = 0; n <= HM_N; n++) {
        hm_real *x = s->x[n];
        hm_real *Q = qp->Q[n];
        hm_real *q = qp->q[n];
        hm_real l;

        if (n < HM_N) {
            if (s->dyn_fresh) {
                /* simulated from this very iterate: the same evaluation would give x_next =
                 * x[n + 1] exactly, and the Jacobians are in qp already */
                for (i = 0; i < HM_NX; i++) qp->b[n][i] = HM_R(0.0);
            } else {
                hm_real x_next[HM_NX];
                hm_model_dynamics(x, s->u[n], x_next, qp->A[n], qp->B[n]);
                for (i = 0; i < HM_NX; i++) qp->b[n][i] = x_next[i] - s->x[n + 1][i];
            }
            hm_model_cost_stage(x, s->u[n], in->goal, p->w_goal, p->w_control, &l, q, qp->r[n], Q, qp->R[n]);
            for (i = 0; i < HM_NU; i++) qp->R[n][i + i * HM_NU] += reg;
            for (i = 0; i < HM_NU * HM_NX; i++) qp->S[n][i] = HM_R(0.0);
            if (exact) {
                hm_real hxx[HM_NX * HM_NX], hux[HM_NU * HM_NX], huu[HM_NU * HM_NU];
                hm_model_dynamics_hessian(x, s->u[n], s->mult.pi[n], hxx, hux, huu);
                for (i = 0; i < HM_NX * HM_NX; i++) Q[i] += hxx[i];
                for (i = 0; i < HM_NU * HM_NX; i++) qp->S[n][i] = hux[i];
                for (i = 0; i < HM_NU * HM_NU; i++) qp->R[n][i] += huu[i];
            }
            qp->lbu[n][0] = p->a_bounds[0] - s->u[n][0];
            qp->ubu[n][0] = p->a_bounds[1] - s->u[n][0];
            qp->lbu[n][1] = p->omega_bounds[0] - s->u[n][1];
            qp->ubu[n][1] = p->omega_bounds[1] - s->u[n][1];
        } else {
            hm_model_cost_terminal(x, in->goal, p->w_goal_terminal, &l, q, Q);
        }
        for (i = 0; i < HM_NX; i++) Q[i + i * HM_NX] += reg;
        cost += l;

        /* Collision cost of each present human at its predicted position at this node: exact
         * gradient, Gauss-Newton Hessian on the (px, py) block. */
        for (j = 0; j < nh; j++) {
            hm_real f, grad[HM_NP], hess_gn[HM_NP * HM_NP], hess_exact[HM_NP * HM_NP];
            const hm_real *hess = hess_gn;
            if (exact) {
                hm_model_cost_collision(x, in->humans_pred[n][j], &p->q, &p->d_th, &p->kappa, &f, grad, hess_gn,
                                        hess_exact);
                hess = hess_exact;
            } else {
                hm_model_cost_collision_gn(x, in->humans_pred[n][j], &p->q, &p->d_th, &p->kappa, &f, grad, hess_gn);
            }
            cost += f;
            q[0] += grad[0];
            q[1] += grad[1];
            Q[0] += hess[0];
            Q[1] += hess[1];
            Q[HM_NX] += hess[2];
            Q[HM_NX + 1] += hess[3];
        }

        /* Node 0 is the measured state: its bounds and rows cannot be acted on. */
        for (i = 0; i < HM_NX; i++) {
            qp->lbx[n][i] = -HM_INF;
            qp->ubx[n][i] = HM_INF;
        }
        if (n == 0) {
            qp->ng[0] = 0;
            continue;
        }
        qp->lbx[n][3] = p->v_bounds[0] - x[3];
        qp->ubx[n][3] = p->v_bounds[1] - x[3];
        qp->ng[n] = ng;
        for (j = 0; j < ng; j++) {
            const int human = j < nh;
            const hm_real *c = human ? in->humans_now[j] : in->obstacle;
            const hm_real *d_min = human ? &p->d_h : &p->d_s;
            const hm_real l1 = human ? p->human_slack_l1 : p->slack_l1;
            const hm_real l2 = human ? p->human_slack_l2 : p->slack_l2;
            hm_real g, hess_d[HM_NP * HM_NP];
            hm_model_distance_constraint(x, c, d_min, &g, qp->D[n][j], hess_d);
            if (exact) {
                /* L = cost - lam (d - d_min + s): the row's curvature enters with -lam. */
                const hm_real lam = s->mult.lam_lg[n][j];
                Q[0] -= lam * hess_d[0];
                Q[1] -= lam * hess_d[1];
                Q[HM_NX] -= lam * hess_d[2];
                Q[HM_NX + 1] -= lam * hess_d[3];
            }
            qp->lg[n][j] = -g;
            qp->soft[n][j] = 1;
            qp->zl[n][j] = l1;
            qp->Zl[n][j] = l2;
            penalty += ocp_nlp_slack_penalty(g, l1, l2);
        }
    }
    s->dyn_fresh = 0;
    if (exact)
        for (n = 0; n <= HM_N; n++) ocp_nlp_convexify_stage(qp, n, hm_fmax(reg, HM_R(1e-8)));
    s->cost = cost + penalty;
    s->cost_slack = penalty;
    s->n_active = ng;
}

HM_FUNC void ocp_nlp_sqp_rti_prepare(hm_solver *s, const hm_input *in)
{
    const unsigned long long t0 = ocp_nlp_now(s);
    s->prepared = 0;
    /* Nothing is computed from unusable data; the feedback phase turns it into a stop. A cold
     * start reads x0 (the caller's guess) already here. */
    if (monitor_check_params(&s->params) && monitor_check_input(in, !s->warm)) {
        ocp_nlp_shift(s, in);
        /* exact_hessian: the Lagrangian's Hessian at the shifted multipliers of the last QP (a cold
         * start has none: Gauss-Newton). With the paper's zero control weights and a far goal the
         * Gauss-Newton model misses the costate-weighted curvature of the dynamics, and its full steps
         * flip omega between its bounds from one step to the next. */
        ocp_nlp_linearize(s, in, s->warm && s->params.exact_hessian);
        s->prepared = 1;
    }
    s->time_prepare_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t0);
}

/* ------------------------------------------------------------------------------------------------
 * Row screening
 *
 * Most distance rows of a crowd are far from binding: a human 3 m from the planned node cannot
 * constrain a step that moves the node by centimetres. Such rows are left out of the QP, and the
 * QP's solution is checked against every one of them afterwards. If it satisfies them all, it is
 * the solution of the whole QP (the QP is convex and its feasible set a subset of the screened
 * one's; a soft row satisfied at s = 0 adds nothing to the objective), with multipliers zero on
 * the rows left out and the slack bound's multiplier equal to the L1 weight. Rows found violated
 * join the QP, which is solved again: the outcome is exact whatever the screening radius, which
 * only decides the cost. The radius of a stage follows the last QP step there: SCREEN_MIN plus
 * twice the larger displacement of the two nodes that the shift brings to it (RTI steps move the
 * far end of the plan by metres and the near end by centimetres). Without a previous step (cold
 * start, braking retry) it is the distance the robot can drive by that node (ocp_nlp_screen_reach):
 * measured with 30 people, the braking retries took 0.60 ms instead of 0.77 ms unscreened. Before
 * the first step (screen_radius[0] = HM_INF) nothing is screened.
 * ---------------------------------------------------------------------------------------------- */

static int ocp_nlp_qp_usable(int status)
{
    return status == HM_QP_SOLVED || status == HM_QP_MAX_ITER;
}

#define OCP_NLP_SCREEN_MIN HM_R(0.5)   /* smallest screening radius [m] */
#define OCP_NLP_SCREEN_ROUNDS 3        /* re-solves with violated rows before all rows go in */

/* Rows with margin -lg = d - d_min not below the stage's radius leave the QP: their lg is kept in
 * screened_lg and made absent (-HM_INF), which the QP solvers skip like any absent bound. Nothing
 * else of the QP moves, so putting a row back is one store. */
static void ocp_nlp_screen_rows(hm_solver *s)
{
    hm_ocp_qp *qp = &s->qp;
    int n, j;
    for (n = 0; n <= HM_N; n++) {
        const hm_real radius = s->screen_radius[n];
        for (j = 0; j < qp->ng[n]; j++) {
            const hm_real lg = qp->lg[n][j];
            const int out = !(-lg < radius);
            s->screened[n][j] = (unsigned char)out;
            s->screened_lg[n][j] = lg;
            qp->lg[n][j] = out ? -HM_INF : lg;
        }
    }
}

/* Rows left out that the QP's step violates (by more than tol) join the QP; returns how many. */
static int ocp_nlp_admit_violated_rows(hm_solver *s, hm_real tol)
{
    hm_ocp_qp *qp = &s->qp;
    int n, j, added = 0;
    for (n = 1; n <= HM_N; n++) {
        const hm_real dp0 = s->qp_sol.x[n][0], dp1 = s->qp_sol.x[n][1];
        for (j = 0; j < qp->ng[n]; j++) {
            const hm_real lg = s->screened_lg[n][j];
            if (s->screened[n][j]
                && qp->D[n][j][0] * dp0 + qp->D[n][j][1] * dp1 < lg - tol * hm_fmax(HM_R(1.0), hm_fabs(lg))) {
                s->screened[n][j] = 0;
                qp->lg[n][j] = lg;
                added++;
            }
        }
    }
    return added;
}

/* All rows back in the QP. With sol: the rows left out get their exact multipliers (zero; the slack
 * bound's the L1 weight) and slack (zero). */
static void ocp_nlp_unscreen_rows(hm_solver *s, hm_ocp_qp_sol *sol)
{
    hm_ocp_qp *qp = &s->qp;
    int n, j;
    for (n = 0; n <= HM_N; n++) {
        for (j = 0; j < qp->ng[n]; j++) {
            if (!s->screened[n][j]) continue;
            s->screened[n][j] = 0;
            qp->lg[n][j] = s->screened_lg[n][j];
            if (sol) {
                sol->s[n][j] = HM_R(0.0);
                sol->lam_lg[n][j] = HM_R(0.0);
                sol->lam_ls[n][j] = qp->soft[n][j] ? qp->zl[n][j] : HM_R(0.0);
            }
        }
    }
}

/* Screening radii of the next QP from the displacements of this QP's step (see above). */
static void ocp_nlp_size_screening(hm_solver *s)
{
    hm_real d2[HM_N + 2];
    int n;
    for (n = 0; n <= HM_N; n++) d2[n] = s->qp_sol.x[n][0] * s->qp_sol.x[n][0] + s->qp_sol.x[n][1] * s->qp_sol.x[n][1];
    d2[HM_N + 1] = d2[HM_N];
    for (n = 0; n <= HM_N; n++)
        s->screen_radius[n] = OCP_NLP_SCREEN_MIN + HM_R(2.0) * hm_sqrt(hm_fmax(d2[n], d2[n + 1]));
}

/* Solve the QP of the current linearisation (its x0 offset set), screened; residuals: the caller
 * reads ipm_ws.out.res. shifted: the QP is the last one's a stage on (the real-time iteration's
 * plan, shifted), and starts from the iterate that the last one kept (ocp_qp_ipm.c, warm start);
 * the re-solves with more rows start from the first round's. Returns the QP status. */
static int ocp_nlp_qp_solve(hm_solver *s, hm_real tol, int residuals, int shifted, int *qp_iter)
{
    const int screen = s->params.row_screening && s->screen_radius[0] < HM_INF;
    int status, round;
    s->ipm_arg.max_iter = s->params.qp_max_iter;
    s->ipm_arg.tol = tol;
    s->ipm_arg.residuals = residuals;
    if (screen) ocp_nlp_screen_rows(s);
    for (round = 0;; round++) {
        s->ipm_arg.warm_start = round > 0 ? 2 : shifted;
        status = ocp_qp_ipm_solve(&s->qp, &s->qp_sol, &s->ipm_ws, &s->ipm_arg);
        *qp_iter += s->ipm_ws.out.iter;
        s->qp_solves++;
        if (!screen || !ocp_nlp_qp_usable(status)) break;
        if (round == OCP_NLP_SCREEN_ROUNDS) {
            /* pathological: rows keep turning up; the whole QP settles it */
            ocp_nlp_unscreen_rows(s, 0);
            continue;
        }
        if (round > OCP_NLP_SCREEN_ROUNDS || ocp_nlp_admit_violated_rows(s, tol) == 0) break;
    }
    if (screen) ocp_nlp_unscreen_rows(s, &s->qp_sol);
    if (ocp_nlp_qp_usable(status)) ocp_nlp_size_screening(s);
    return status;
}


/* Iterate = base + alpha * QP step (base: the linearisation point, kept in x_base/u_base). */
static void ocp_nlp_step_from_base(hm_solver *s, hm_real alpha)
{
    int n, i;
    const hm_ocp_qp_sol *d = &s->qp_sol;
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

static void ocp_nlp_copy(hm_real *restrict dst, const hm_real *restrict src, int len)
{
    int i;
    for (i = 0; i < len; i++) dst[i] = src[i];
}

/* The QP's multipliers become the NLP's. Their primal part stays zero (ocp_qp_sol_set_zero at every
 * cold start; never written), the slacks are set by ocp_nlp_residuals: neither is copied. */
static void ocp_nlp_take_multipliers(hm_solver *s)
{
    hm_ocp_qp_sol *m = &s->mult;
    const hm_ocp_qp_sol *q = &s->qp_sol;
    ocp_nlp_copy(&m->pi[0][0], &q->pi[0][0], HM_N * HM_NX);
    ocp_nlp_copy(&m->lam_lbx[0][0], &q->lam_lbx[0][0], (HM_N + 1) * HM_NX);
    ocp_nlp_copy(&m->lam_ubx[0][0], &q->lam_ubx[0][0], (HM_N + 1) * HM_NX);
    ocp_nlp_copy(&m->lam_lbu[0][0], &q->lam_lbu[0][0], HM_N * HM_NU);
    ocp_nlp_copy(&m->lam_ubu[0][0], &q->lam_ubu[0][0], HM_N * HM_NU);
    ocp_nlp_copy(&m->lam_lg[0][0], &q->lam_lg[0][0], (HM_N + 1) * HM_NG);
    ocp_nlp_copy(&m->lam_ls[0][0], &q->lam_ls[0][0], (HM_N + 1) * HM_NG);
}

/* Solve the QP; when usable, take the full step (real-time iteration). */
static int ocp_nlp_qp_step(hm_solver *s, int shifted, int *qp_iter)
{
    const int status = ocp_nlp_qp_solve(s, s->params.qp_tol, 0, shifted, qp_iter);
    if (!ocp_nlp_qp_usable(status)) return status;
    ocp_nlp_save_base(s);
    ocp_nlp_step_from_base(s, HM_R(1.0));
    ocp_nlp_take_multipliers(s);
    return status;
}

/* l1 merit of the iterate: objective with the soft-row penalties + mu * (|dynamics gaps|_1 +
 * |x_0 - measured x0|_1). Bounds are linear, so every step of the line search keeps them. */
static hm_real ocp_nlp_merit(const hm_solver *s, const hm_input *in, hm_real mu)
{
    const hm_params *p = &s->params;
    const int nh = ocp_nlp_clamp_humans(in);
    const int ng = nh + (in->has_obstacle ? 1 : 0);
    hm_real merit = HM_R(0.0), gaps = HM_R(0.0);
    int n, i, j;
    for (i = 0; i < HM_NX; i++) gaps += hm_fabs(s->x[0][i] - in->x0[i]);
    for (n = 0; n <= HM_N; n++) {
        const hm_real *x = s->x[n];
        hm_real l, gx[HM_NX], hx[HM_NX * HM_NX];
        if (n < HM_N) {
            hm_real gu[HM_NU], hu[HM_NU * HM_NU], x_next[HM_NX], A[HM_NX * HM_NX], B[HM_NX * HM_NU];
            hm_model_dynamics(x, s->u[n], x_next, A, B);
            for (i = 0; i < HM_NX; i++) gaps += hm_fabs(x_next[i] - s->x[n + 1][i]);
            hm_model_cost_stage(x, s->u[n], in->goal, p->w_goal, p->w_control, &l, gx, gu, hx, hu);
        } else {
            hm_model_cost_terminal(x, in->goal, p->w_goal_terminal, &l, gx, hx);
        }
        merit += l;
        for (j = 0; j < nh; j++) {
            hm_real f, grad[HM_NP], hess_gn[HM_NP * HM_NP];
            hm_model_cost_collision_gn(x, in->humans_pred[n][j], &p->q, &p->d_th, &p->kappa, &f, grad, hess_gn);
            merit += f;
        }
        if (n == 0) continue;
        for (j = 0; j < ng; j++) {
            const int human = j < nh;
            hm_real g, jac[HM_NP], hess_d[HM_NP * HM_NP];
            hm_model_distance_constraint(x, human ? in->humans_now[j] : in->obstacle, human ? &p->d_h : &p->d_s,
                                         &g, jac, hess_d);
            merit += ocp_nlp_slack_penalty(g, human ? p->human_slack_l1 : p->slack_l1,
                                           human ? p->human_slack_l2 : p->slack_l2);
        }
    }
    return merit + mu * gaps;
}

/* Full SQP step with a backtracking line search on the l1 merit (Armijo on the decrease that the
 * QP model predicts); mu grows to stay above the dynamics multipliers, as exactness requires. */
static int ocp_nlp_qp_line_search_step(hm_solver *s, const hm_input *in, hm_real tol, int shifted,
                                       int *qp_iter)
{
    /* The QP must be solved at least as tightly as the SQP is asked to converge. */
    const int status = ocp_nlp_qp_solve(s, hm_fmin(s->params.qp_tol, HM_R(0.1) * tol), 1, shifted, qp_iter);
    hm_real gaps = HM_R(0.0), pi_max = HM_R(0.0), merit0, predicted, alpha = HM_R(1.0);
    int n, i;
    if (!ocp_nlp_qp_usable(status)) return status;
    for (i = 0; i < HM_NX; i++) gaps += hm_fabs(s->qp.x0[i]);
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NX; i++) {
            gaps += hm_fabs(s->qp.b[n][i]);
            pi_max = hm_fmax(pi_max, hm_fabs(s->qp_sol.pi[n][i]));
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
    ocp_nlp_take_multipliers(s);
    return status;
}

/* The measured state enters the QP as the offset of its fixed x_0 from the iterate's. */
static void ocp_nlp_set_x0(hm_solver *s, const hm_input *in)
{
    int i;
    for (i = 0; i < HM_NX; i++) s->qp.x0[i] = in->x0[i] - s->x[0][i];
}

/* KKT residuals of the NLP at the linearisation point with the multipliers in s->mult: exactly those
 * of the QP of this linearisation at a zero step (its gradient is the NLP's, its constraints are the
 * NLP's linearised here), soft rows carrying the slack they need at this point. */
static void ocp_nlp_residuals(hm_solver *s, hm_output *out)
{
    hm_ocp_qp *qp = &s->qp;
    hm_ocp_qp_sol *m = &s->mult;
    hm_ocp_qp_res res;
    hm_real gap = HM_R(0.0);
    int n, j, i;
    for (i = 0; i < HM_NX; i++) gap = hm_fmax(gap, hm_fabs(qp->x0[i]));
    for (n = 0; n <= HM_N; n++)
        for (j = 0; j < HM_NG; j++)
            m->s[n][j] = (j < qp->ng[n] && qp->lg[n][j] > HM_R(0.0)) ? qp->lg[n][j] : HM_R(0.0);
    ocp_qp_res_at_zero_step(qp, m, &res);
    out->kkt_stat = res.stat;
    out->kkt_eq = hm_fmax(res.eq, gap);
    out->kkt_ineq = res.ineq;
    out->kkt_comp = res.comp;
}

/* Smallest distance of the robot's path (nodes 0..N of s->x) to the present humans' current
 * positions, HM_INF without humans. */
static hm_real ocp_nlp_min_human_distance(const hm_solver *s, const hm_input *in)
{
    const int nh = ocp_nlp_clamp_humans(in);
    hm_real best = HM_INF;   /* of the squared distances: one square root (it is monotonic) */
    int n, j;
    for (n = 0; n <= HM_N; n++) {
        for (j = 0; j < nh; j++) {
            const hm_real dx = s->x[n][0] - in->humans_now[j][0];
            const hm_real dy = s->x[n][1] - in->humans_now[j][1];
            const hm_real d2 = dx * dx + dy * dy;
            if (d2 < best) best = d2;
        }
    }
    return nh > 0 ? hm_sqrt(best) : HM_INF;
}

static int ocp_nlp_plan_finite(const hm_solver *s)
{
    hm_real acc = HM_R(0.0);
    int n, i;
    for (n = 0; n <= HM_N; n++)
        for (i = 0; i < HM_NX; i++) acc += s->x[n][i] * HM_R(0.0);
    for (n = 0; n < HM_N; n++)
        for (i = 0; i < HM_NU; i++) acc += s->u[n][i] * HM_R(0.0);
    return acc == HM_R(0.0); /* 0 * x is NaN for NaN or infinite x */
}

static void ocp_nlp_report(const hm_solver *s, const hm_input *in, hm_output *out)
{
    int n, i;
    for (n = 0; n <= HM_N; n++)
        for (i = 0; i < HM_NX; i++) out->x[n][i] = s->x[n][i];
    for (n = 0; n < HM_N; n++)
        for (i = 0; i < HM_NU; i++) out->u[n][i] = s->u[n][i];
    out->u0[0] = s->u[0][0];
    out->u0[1] = s->u[0][1];
    out->command[0] = s->x[1][3];
    out->command[1] = s->u[0][1];
    out->cost = s->cost;
    out->min_human_distance = ocp_nlp_min_human_distance(s, in);
}

/* Protective stop: brake to standstill within the acceleration bound, no turning; out's plan shows
 * the braking. Without a usable measured speed the command is the hardest braking. After a failure
 * (C1, unusable inputs) the next step starts cold, exactly as a fresh solver; after a C2 stop the
 * plan is kept, so that the next steps go on improving it (a cold start would put the unsafe
 * straight-line guess back every time). */
static void ocp_nlp_protective_stop(hm_solver *s, const hm_input *in, hm_output *out, int reason)
{
    const int params_ok = monitor_check_params(&s->params);
    const hm_real a_min = params_ok ? s->params.a_bounds[0] : HM_R(-1.0);
    const hm_real a_max = params_ok ? s->params.a_bounds[1] : HM_R(1.0);
    const int x0_ok = params_ok && monitor_check_input(in, 1);
    int n, i;
    out->stop = 1;
    out->stop_reason = reason;
    if (!x0_ok) {
        /* No trustworthy state (or bounds): full braking, a plan of zeros, nothing computed. */
        for (n = 0; n <= HM_N; n++)
            for (i = 0; i < HM_NX; i++) out->x[n][i] = HM_R(0.0);
        for (n = 0; n < HM_N; n++) {
            out->u[n][0] = a_min;
            out->u[n][1] = HM_R(0.0);
        }
        out->min_human_distance = HM_INF;
    } else {
        hm_real A[HM_NX * HM_NX], B[HM_NX * HM_NU];
        hm_real best = HM_INF;
        int j;
        for (i = 0; i < HM_NX; i++) out->x[0][i] = in->x0[i];
        for (n = 0; n < HM_N; n++) {
            out->u[n][0] = hm_fmin(hm_fmax(-out->x[n][3] / HM_R(HM_DT), a_min), a_max);
            out->u[n][1] = HM_R(0.0);
            hm_model_dynamics(out->x[n], out->u[n], out->x[n + 1], A, B);
        }
        for (n = 0; n <= HM_N; n++) {
            for (j = 0; j < ocp_nlp_clamp_humans(in); j++) {
                const hm_real dx = out->x[n][0] - in->humans_now[j][0];
                const hm_real dy = out->x[n][1] - in->humans_now[j][1];
                best = hm_fmin(best, hm_sqrt(dx * dx + dy * dy));
            }
        }
        out->min_human_distance = best;
    }
    out->u0[0] = out->u[0][0];
    out->u0[1] = HM_R(0.0);
    out->command[0] = x0_ok ? out->x[1][3] : HM_R(0.0);
    out->command[1] = HM_R(0.0);
    s->prepared = 0;
    if (reason != HM_STOP_UNSAFE_PLAN && reason != HM_STOP_HUMAN_TOO_CLOSE) s->warm = 0;
}

/* Deadline hook of the QP iterations. */
static int ocp_nlp_deadline_passed(void *ctx)
{
    const hm_solver *s = (const hm_solver *)ctx;
    return s->clock != 0 && s->clock(s->clock_ctx) - s->t_start > s->deadline_ns;
}

static void ocp_nlp_start_clock(hm_solver *s, unsigned long long t_start)
{
    /* deadline_ms * 1e6 in nanoseconds, without a real -> 64-bit integer conversion: on a
     * single-precision FPU libgcc does that one in soft double. Whole milliseconds and the fraction
     * are converted to 32 bits each (one FPU instruction); absurd or NaN deadlines are capped at
     * ~50 days (the monitor refuses non-positive or non-finite ones before any solving). */
    hm_real ms = s->params.deadline_ms;
    unsigned long whole, frac_ns;
    if (!(ms >= HM_R(0.0))) ms = HM_R(0.0);
    if (ms > HM_R(4.0e9)) ms = HM_R(4.0e9);
    whole = (unsigned long)ms;
    frac_ns = (unsigned long)((ms - (hm_real)whole) * HM_R(1e6));
    s->t_start = t_start;
    s->deadline_ns = (unsigned long long)whole * 1000000ULL + frac_ns;
}

static void ocp_nlp_clear_output(hm_output *out)
{
    out->stop = 0;
    out->stop_reason = HM_STOP_NONE;
    out->status = HM_STATUS_SKIPPED;
    out->qp_status = -1;
    out->qp_iterations = 0;
    out->sqp_iterations = 0;
    out->qp_solves = 0;
    out->cost = HM_R(0.0);
    out->kkt_stat = HM_R(0.0);
    out->kkt_eq = HM_R(0.0);
    out->kkt_ineq = HM_R(0.0);
    out->kkt_comp = HM_R(0.0);
    out->min_human_distance = HM_INF;
}

/* The checks that come before any solving; returns the stop reason or HM_STOP_NONE. */
static int ocp_nlp_check_before(const hm_solver *s, const hm_input *in)
{
    if (!monitor_check_params(&s->params)) return HM_STOP_INVALID_PARAMS;
    if (!monitor_check_input(in, 1)) return HM_STOP_INVALID_INPUT;
    if (monitor_distance_now(in) < s->params.d_h) return HM_STOP_HUMAN_TOO_CLOSE;
    return HM_STOP_NONE;
}

static int ocp_nlp_keeps_distance(const hm_real *x, const hm_input *in, hm_real limit)
{
    const int nh = ocp_nlp_clamp_humans(in);
    int j;
    for (j = 0; j < nh; j++) {
        const hm_real dx = x[0] - in->humans_now[j][0];
        const hm_real dy = x[1] - in->humans_now[j][1];
        if (dx * dx + dy * dy < limit * limit) return 0;
    }
    return 1;
}

/* C2 on the plan: its nodes 1..N against the humans' current positions, and the state the robot
 * really reaches after applying u0 for one interval (the model from the measured x0: the plan's
 * own x_1 is the QP's linear prediction of it). The allowance covers the distance smoothing
 * (eps^2 / (2 d_h) ~ 1e-6 m) and the QP tolerance. */
static int ocp_nlp_check_plan(const hm_solver *s, const hm_input *in)
{
    const hm_real limit = s->params.d_h - HM_R(1e-5);
    hm_real x1[HM_NX], A[HM_NX * HM_NX], B[HM_NX * HM_NU];
    int n;
    if (!ocp_nlp_plan_finite(s)) return HM_STOP_NONFINITE;
    for (n = 1; n <= HM_N; n++)
        if (!ocp_nlp_keeps_distance(s->x[n], in, limit)) return HM_STOP_UNSAFE_PLAN;
    hm_model_dynamics(in->x0, s->u[0], x1, A, B);
    if (!ocp_nlp_keeps_distance(x1, in, limit)) return HM_STOP_UNSAFE_PLAN;
    return HM_STOP_NONE;
}

static int ocp_nlp_rti_feedback_from(hm_solver *s, const hm_input *in, hm_output *out, unsigned long long t_start)
{
    unsigned long long t_feedback;
    int qp_status, status, reason;
    /* the plan moved on by one stage since the last QP, whose kept iterate (if any: dropped after a
     * stop, below) the QP starts from */
    const int shifted = s->warm;
    ocp_nlp_start_clock(s, t_start);
    ocp_nlp_clear_output(out);
    s->qp_solves = 0;
    out->sqp_iterations = 1;
    reason = ocp_nlp_check_before(s, in);
    if (reason == HM_STOP_NONE) {
        if (!s->prepared) ocp_nlp_sqp_rti_prepare(s, in);
        t_feedback = ocp_nlp_now(s);
        if (!s->warm) ocp_qp_sol_set_zero(&s->mult);
        ocp_nlp_set_x0(s, in);
        s->ipm_arg.should_stop = ocp_nlp_deadline_passed;
        s->ipm_arg.stop_ctx = s;
        if (s->params.line_search) {
            /* A damped step: with the paper's zero control weights the Gauss-Newton curvature in
             * omega is tiny, and full steps overshoot from one bound of omega to the other. */
            s->merit_mu = HM_R(1.0);
            qp_status = ocp_nlp_qp_line_search_step(s, in, s->params.qp_tol, shifted, &out->qp_iterations);
        } else {
            qp_status = ocp_nlp_qp_step(s, shifted, &out->qp_iterations);
        }
        s->ipm_arg.should_stop = 0;
        s->ipm_arg.stop_ctx = 0;
        /* With the multipliers of this QP: how far the linearisation point is from a KKT point. */
        ocp_nlp_residuals(s, out);
        s->prepared = 0;
        out->qp_status = qp_status;
        status = qp_status == HM_QP_SOLVED ? HM_STATUS_OK
                 : qp_status == HM_QP_MAX_ITER ? HM_STATUS_MAX_ITER : HM_STATUS_QP_FAILED;
        out->status = status;
        if (qp_status == HM_QP_TIMEOUT) {
            reason = HM_STOP_DEADLINE;
        } else if (qp_status != HM_QP_SOLVED) {
            reason = HM_STOP_QP_FAILED;  /* the iteration limit too: not a solution */
        } else {
            reason = ocp_nlp_check_plan(s, in);
            if (reason == HM_STOP_UNSAFE_PLAN) {
                /* The warm start led the plan between humans it cannot pass (a local solution in
                 * the wrong homotopy class). Solve once more from the braking guess, which keeps
                 * d_h whenever braking does. */
                out->sqp_iterations = 2;
                ocp_nlp_init_braking(s, in);
                ocp_nlp_linearize(s, in, 0);
                ocp_nlp_set_x0(s, in);
                s->ipm_arg.should_stop = ocp_nlp_deadline_passed;
                s->ipm_arg.stop_ctx = s;
                qp_status = ocp_nlp_qp_step(s, 0, &out->qp_iterations);
                s->ipm_arg.should_stop = 0;
                s->ipm_arg.stop_ctx = 0;
                ocp_nlp_residuals(s, out);
                out->qp_status = qp_status;
                out->status = qp_status == HM_QP_SOLVED ? HM_STATUS_OK
                              : qp_status == HM_QP_MAX_ITER ? HM_STATUS_MAX_ITER : HM_STATUS_QP_FAILED;
                reason = qp_status == HM_QP_TIMEOUT ? HM_STOP_DEADLINE
                         : qp_status != HM_QP_SOLVED ? HM_STOP_QP_FAILED : ocp_nlp_check_plan(s, in);
            }
            if (reason == HM_STOP_NONE && ocp_nlp_deadline_passed(s)) reason = HM_STOP_DEADLINE;
        }
    } else {
        s->prepared = 0;
        t_feedback = ocp_nlp_now(s);
    }
    if (reason == HM_STOP_NONE || reason == HM_STOP_UNSAFE_PLAN) s->warm = 1;
    /* after a stop the next QP starts cold: after the braking retry (HM_STOP_UNSAFE_PLAN) its kept
     * iterate is the retry's, whose linearisation the plan has left; a stop before solving leaves one
     * from an older step */
    if (reason != HM_STOP_NONE) s->ipm_ws.warm.ready = 0;
    if (reason == HM_STOP_NONE) {
        ocp_nlp_report(s, in, out);
    } else {
        ocp_nlp_protective_stop(s, in, out, reason);
    }
    out->qp_solves = s->qp_solves;
    out->time_prepare_ms = s->time_prepare_ms;
    out->time_feedback_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t_feedback);
    out->time_total_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t_start);
    return out->status;
}

/* Feedback after a separate preparation: the deadline counts from here. */
HM_FUNC int ocp_nlp_sqp_rti_feedback(hm_solver *s, const hm_input *in, hm_output *out)
{
    if (!s->prepared) s->time_prepare_ms = HM_R(0.0);
    return ocp_nlp_rti_feedback_from(s, in, out, ocp_nlp_now(s));
}

/* A whole real-time iteration: the deadline counts from the start of the preparation. */
HM_FUNC int ocp_nlp_sqp_rti_step(hm_solver *s, const hm_input *in, hm_output *out)
{
    const unsigned long long t0 = ocp_nlp_now(s);
    ocp_nlp_sqp_rti_prepare(s, in);
    return ocp_nlp_rti_feedback_from(s, in, out, t0);
}

HM_FUNC int ocp_nlp_sqp_solve(hm_solver *s, const hm_input *in, hm_output *out, int max_iter, hm_real tol)
{
    const unsigned long long t0 = ocp_nlp_now(s);
    int k, qp_status = HM_QP_SOLVED, status = HM_STATUS_MAX_ITER, reason;
    ocp_nlp_clear_output(out);
    s->qp_solves = 0;
    reason = ocp_nlp_check_before(s, in);
    if (reason != HM_STOP_NONE) {
        ocp_nlp_protective_stop(s, in, out, reason);
        out->time_total_ms = out->time_feedback_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t0);
        out->time_prepare_ms = HM_R(0.0);
        return out->status;
    }
    if (!s->warm) {
        ocp_nlp_shift(s, in); /* cold: controls held at zero from x0 */
        ocp_qp_sol_set_zero(&s->mult);
        s->warm = 1;
    }
    s->merit_mu = HM_R(1.0);
    /* The reference: its QPs with exact residuals in every iteration. Their last steps then leave
     * the residuals far below the QP tolerance, which is relative to the scaled data; with the
     * recurrence they end just below it, and at tol = 1e-9 the SQP stalled on that (stationarity
     * 3.5e-7 after 300 iterations, 30 people). */
    s->ipm_arg.recurrence = 0;
    /* and all of them from the cold start (keeping none, so the next RTI step starts cold too) */
    s->ipm_arg.warm_mu = HM_R(0.0);
    for (k = 0; k < max_iter; k++) {
        ocp_nlp_linearize(s, in, k > 0);
        ocp_nlp_set_x0(s, in);
        ocp_nlp_residuals(s, out);
        if (k > 0 && out->kkt_stat <= tol && out->kkt_eq <= tol && out->kkt_ineq <= tol && out->kkt_comp <= tol) {
            status = HM_STATUS_OK;
            break;
        }
        qp_status = ocp_nlp_qp_line_search_step(s, in, tol, 0, &out->qp_iterations);
        if (!ocp_nlp_qp_usable(qp_status)) {
            status = HM_STATUS_QP_FAILED;
            break;
        }
    }
    if (k == max_iter) {
        /* Report the residuals at the final iterate. */
        ocp_nlp_linearize(s, in, 1);
        ocp_nlp_set_x0(s, in);
        ocp_nlp_residuals(s, out);
        if (out->kkt_stat <= tol && out->kkt_eq <= tol && out->kkt_ineq <= tol && out->kkt_comp <= tol)
            status = HM_STATUS_OK;
    }
    s->ipm_arg.recurrence = 1;
    s->ipm_arg.warm_mu = OCP_NLP_WARM_MU;
    s->prepared = 0;
    out->status = status;
    out->qp_status = qp_status;
    out->sqp_iterations = k;
    out->qp_solves = s->qp_solves;
    reason = HM_STOP_NONE;
    if (status == HM_STATUS_QP_FAILED) {
        reason = HM_STOP_QP_FAILED;
    } else {
        reason = ocp_nlp_check_plan(s, in);
    }
    if (reason == HM_STOP_NONE)
        ocp_nlp_report(s, in, out);
    else
        ocp_nlp_protective_stop(s, in, out, reason);
    out->time_prepare_ms = HM_R(0.0);
    out->time_feedback_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t0);
    out->time_total_ms = out->time_feedback_ms;
    return status;
}

HM_FUNC const char *ocp_nlp_status_message(int status)
{
    switch (status) {
    case HM_STATUS_OK:
        return "solved";
    case HM_STATUS_MAX_ITER:
        return "iteration limit reached before the tolerance";
    case HM_STATUS_QP_FAILED:
        return "the QP failed; no step taken";
    case HM_STATUS_SKIPPED:
        return "nothing solved: a protective stop was decided before solving";
    default:
        return "unknown status";
    }
}
