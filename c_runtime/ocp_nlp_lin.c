/*
 * ocp_nlp_lin.c: the linearisation of the NLP, once per SQP iteration (in the real-time iteration's
 * preparation phase): its point (the previous plan shifted and re-simulated, the cold guess, or the
 * braking guess), the QP of the model's derivatives there (Gauss-Newton, or the exact Hessian made
 * convex) with the objective, and, at feedback, the measured state as the QP's x_0 offset.
 * Model functions: the hm_model_* macros of the translation unit (ocp_nlp_common.h).
 */
#include "ocp_nlp_lin.h"

#include "monitor.h"
#include "ocp_nlp_screen.h"
#include "ocp_qp.h"

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

/* Initial guess of the next step: the previous plan shifted by one interval (the last control
 * repeated), re-simulated from the predicted state; or, cold, the controls held at zero from x0. */
HM_FUNC void ocp_nlp_shift(hm_solver *s, const hm_input *in)
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

/* The guess moved into the bounds: omega clamped to omega_bounds, and each acceleration to a_bounds and
 * to what keeps the next speed within v_bounds where a_bounds allow it (the model integrates v' = a:
 * v_{n+1} = v_n + dt a_n), re-simulated from x_0. For the real-time iteration with a line search, which
 * moves from its linearisation point only part of the way to the QP's solution: from a point outside
 * the bounds (the repeated last control of a shifted plan) its plans stayed outside them (issue 22,
 * item 10: speeds up to 1.3 m/s with v_max = 1). */
HM_FUNC void ocp_nlp_project_guess(hm_solver *s)
{
    const hm_params *p = &s->params;
    const hm_real dt = HM_R(HM_DT);
    int n;
    for (n = 0; n < HM_N; n++) {
        const hm_real v = s->x[n][3];
        const hm_real lo = hm_fmax(p->a_bounds[0], (p->v_bounds[0] - v) / dt);
        const hm_real hi = hm_fmin(p->a_bounds[1], (p->v_bounds[1] - v) / dt);
        hm_real a = s->u[n][0];
        if (lo <= hi) {
            a = hm_fmin(hm_fmax(a, lo), hi);
        } else {
            a = v > p->v_bounds[1] ? p->a_bounds[0] : p->a_bounds[1]; /* towards v_bounds at full rate */
        }
        s->u[n][0] = a;
        s->u[n][1] = hm_fmin(hm_fmax(s->u[n][1], p->omega_bounds[0]), p->omega_bounds[1]);
        hm_model_dynamics(s->x[n], s->u[n], s->x[n + 1], s->qp.A[n], s->qp.B[n]);
    }
    s->dyn_fresh = 1;
}

/* The safe fallback guess: brake to standstill within the acceleration bound, without turning,
 * from the measured state. Whenever braking keeps d_h, this guess satisfies every human row, so
 * the QP linearised at it (zero step feasible, rows convex) returns a plan that keeps d_h too. */
HM_FUNC void ocp_nlp_init_braking(hm_solver *s, const hm_input *in)
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

/* Symmetric n x n M (column-major, n <= 6) replaced by its projection onto {eigenvalues >= floor}:
 * Jacobi sweeps over the upper triangle in round-robin order (each rotation zeroes its pair and moves the other
 * rows' two entries; Golub and Van Loan 8.5), then V max(Lambda, floor) V'. When every eigenvalue is
 * at least floor the projection is M itself, which is kept as it was: rebuilding it from V and
 * Lambda would only add rounding. */
static void ocp_nlp_project_psd(hm_real *M, int n, hm_real floor)
{
    hm_real A[36], V[36], off, total = HM_R(0.0);
    const int np = n + (n & 1);   /* places in the round robin: one a bye when n is odd */
    int pos[6];
    int i, j, k, m, round, sweep, clipped = 0;
    for (i = 0; i < n * n; i++) {
        A[i] = M[i];
        V[i] = HM_R(0.0);
        total += M[i] * M[i];
    }
    for (i = 0; i < n; i++) V[i + i * n] = HM_R(1.0);
    for (sweep = 0; sweep < 30; sweep++) {
        off = HM_R(0.0);
        for (j = 1; j < n; j++)
            for (i = 0; i < j; i++) off += A[i + j * n] * A[i + j * n];
        if (off <= HM_EPS * HM_EPS * total) break;
        /* A sweep in rounds of pairs that share no index (the round robin's: (0, 3) (1, 2), then (0, 2)
         * (1, 3), then (0, 1) (2, 3) for n = 4). A rotation moves only rows and columns of its own pair,
         * so every angle of a round comes from entries no other rotation of the round moves: the
         * round's angles are computed first, their chains of square roots and divisions side by side,
         * then its rotations applied. */
        for (i = 0; i < np; i++) pos[i] = i;
        for (round = 0; round < np - 1; round++) {
            int ri[3], rj[3], nrot = 0;
            hm_real rt[3], rsn[3], rtau[3], raij[3];
            for (m = 0; m < np / 2; m++) {
                const int a = pos[m], b = pos[np - 1 - m];
                hm_real aij, small, h, t, g;
                i = a < b ? a : b;
                j = a < b ? b : a;
                if (j >= n) continue;   /* the bye */
                aij = A[i + j * n];
                small = HM_R(100.0) * hm_fabs(aij);
                if (aij == HM_R(0.0)) continue;
                /* below the last bit of both diagonal entries: a rotation would not change them */
                if (hm_fabs(A[i + i * n]) + small == hm_fabs(A[i + i * n]) &&
                    hm_fabs(A[j + j * n]) + small == hm_fabs(A[j + j * n])) {
                    A[i + j * n] = A[j + i * n] = HM_R(0.0);
                    continue;
                }
                /* t = sgn(theta) / (|theta| + sqrt(theta^2 + 1)), theta = h / (2 aij), h = ajj - aii, the
                 * smaller root of t^2 + 2 theta t - 1 = 0, with |2 aij| multiplied through: one division
                 * less in the chain */
                h = A[j + j * n] - A[i + i * n];
                t = ((h >= HM_R(0.0)) == (aij >= HM_R(0.0)) ? HM_R(2.0) : HM_R(-2.0)) * hm_fabs(aij) /
                    (hm_fabs(h) + hm_sqrt(h * h + HM_R(4.0) * aij * aij));
                /* c = 1 / g, s = t / g and tau = s / (1 + c) = t / (g + 1): two divisions side by side
                 * rather than three in a chain */
                g = hm_sqrt(t * t + HM_R(1.0));
                ri[nrot] = i;
                rj[nrot] = j;
                rt[nrot] = t;
                rsn[nrot] = t / g;
                rtau[nrot] = t / (g + HM_R(1.0));
                raij[nrot] = aij;
                nrot++;
            }
            for (m = 0; m < nrot; m++) {
                const hm_real t = rt[m], sn = rsn[m], tau = rtau[m], aij = raij[m];
                i = ri[m];
                j = rj[m];
                A[i + i * n] -= t * aij;
                A[j + j * n] += t * aij;
                A[i + j * n] = A[j + i * n] = HM_R(0.0);
                for (k = 0; k < n; k++) {
                    hm_real p, q;
                    if (k != i && k != j) {
                        p = A[k + i * n];
                        q = A[k + j * n];
                        A[k + i * n] = A[i + k * n] = p - sn * (q + p * tau);
                        A[k + j * n] = A[j + k * n] = q + sn * (p - q * tau);
                    }
                    p = V[k + i * n];
                    q = V[k + j * n];
                    V[k + i * n] = p - sn * (q + p * tau);
                    V[k + j * n] = q + sn * (p - q * tau);
                }
            }
            /* the circle method: the first place stays, the others move round by one */
            k = pos[np - 1];
            for (m = np - 1; m > 1; m--) pos[m] = pos[m - 1];
            pos[1] = k;
        }
    }
    {
        hm_real lam[6];
        for (k = 0; k < n; k++) {
            lam[k] = A[k + k * n];
            if (lam[k] < floor) {
                lam[k] = floor;
                clipped = 1;
            }
        }
        if (!clipped) return;
        for (j = 0; j < n; j++)
            for (i = 0; i <= j; i++) {
                hm_real acc = HM_R(0.0);
                for (k = 0; k < n; k++) acc += V[i + k * n] * lam[k] * V[j + k * n];
                M[i + j * n] = M[j + i * n] = acc;
            }
    }
}

/* The 2 x 2 case in closed form: [a b; b c] projected onto {eigenvalues >= floor}. Its smaller
 * eigenvalue lo = (a + c) / 2 - r, r = sqrt(((c - a) / 2)^2 + b^2), with eigenvector u: the
 * projection adds (floor - lo) u u' when only lo is below floor, and is floor I when both are. */
static void ocp_nlp_project_psd2(hm_real *a, hm_real *b, hm_real *c, hm_real floor)
{
    const hm_real hd = HM_R(0.5) * (*c - *a);
    const hm_real r = hm_sqrt(hd * hd + *b * *b);
    const hm_real mean = HM_R(0.5) * (*a + *c);
    const hm_real lo = mean - r;
    hm_real u0, u1, scale;
    if (lo >= floor) return;
    if (mean + r <= floor) {
        *a = *c = floor;
        *b = HM_R(0.0);
        return;
    }
    /* (M - lo I) u = 0 from the row with the larger diagonal entry: r - hd or r + hd, no cancellation */
    if (hd >= HM_R(0.0)) {
        u0 = -(r + hd);
        u1 = *b;
    } else {
        u0 = *b;
        u1 = -(r - hd);
    }
    scale = (floor - lo) / (u0 * u0 + u1 * u1);
    *a += scale * u0 * u0;
    *b += scale * u0 * u1;
    *c += scale * u1 * u1;
}

/* Stage n's Hessian blocks [Q S'; S R] (or Q alone at n = N) projected onto the PSD cone. */
static void ocp_nlp_convexify_stage(hm_ocp_qp *qp, int n, hm_real floor)
{
    hm_real M[36];
    const int nz = n < HM_N ? HM_NX + HM_NU : HM_NX;
    int i, j, blocks = 1;
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
    /* the robot's stages are block diagonal, (px, py) apart from (theta, v, a, omega): the dynamics'
     * Hessian has no position in it, and the projection of a block diagonal matrix is that of its
     * blocks. Checked; the full matrix otherwise. */
    for (j = 0; j < 2; j++)
        for (i = 2; i < nz; i++)
            if (M[i + j * nz] != HM_R(0.0) || M[j + i * nz] != HM_R(0.0)) blocks = 0;
    if (blocks) {
        hm_real B[36];
        const int nr = nz - 2;
        ocp_nlp_project_psd2(&M[0], &M[nz], &M[1 + nz], floor);
        M[1] = M[nz];
        for (j = 0; j < nr; j++)
            for (i = 0; i < nr; i++) B[i + j * nr] = M[2 + i + (2 + j) * nz];
        ocp_nlp_project_psd(B, nr, floor);
        for (j = 0; j < nr; j++)
            for (i = 0; i < nr; i++) M[2 + i + (2 + j) * nz] = B[i + j * nr];
    } else {
        ocp_nlp_project_psd(M, nz, floor);
    }
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
HM_FUNC void ocp_nlp_linearize(hm_solver *s, const hm_input *in, int exact)
{
    const hm_params *p = &s->params;
    hm_ocp_qp *qp = &s->qp;
    const ocp_nlp_terms t = ocp_nlp_cost_terms(p, in);
    const int nh = t.nh, ng = t.ng;
    const hm_real reg = p->regularization;
    hm_real cost = HM_R(0.0), penalty = HM_R(0.0);
    int n, i, j;

    for (n = 0; n <= HM_N; n++) {
        hm_real *x = s->x[n];
        hm_real *Q = qp->Q[n];
        hm_real *q = qp->q[n];
        hm_real l, far_h, far_o;

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
            l = ocp_nlp_cost_tracking(p, in, n, x, s->u[n], q, qp->r[n], Q, qp->R[n]);
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
            l = ocp_nlp_cost_tracking(p, in, n, x, 0, q, 0, Q, 0);
        }
        for (i = 0; i < HM_NX; i++) Q[i + i * HM_NX] += reg;
        cost += l;

        /* Collision cost of each present person within reach at their predicted position at this
         * node: exact gradient, Gauss-Newton (or exact) Hessian on the (px, py) block. */
        cost = ocp_nlp_cost_people(p, in, &t, n, x, exact, cost, q, Q);

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
        /* node 1's bound comes from the measured state (ocp_nlp_set_x0) */
        if (p->separation && n >= 2)
            s->v_separation[n] = monitor_separation_bound(in, p, s->x[n - 1], n - 1, p->v_bounds[1]);
        qp->ng[n] = ng;
        far_h = ocp_nlp_screen_far_reach(s, n, p->d_h);
        far_o = ocp_nlp_screen_far_reach(s, n, p->d_s);
        for (j = 0; j < ng; j++) {
            const ocp_nlp_row r = ocp_nlp_row_of(p, in, nh, j);
            hm_real g, hess_d[HM_NPOS * HM_NPOS];
            qp->soft[n][j] = 1;
            qp->zl[n][j] = r.l1;
            qp->Zl[n][j] = r.l2;
            /* beyond the screening radius by plain distance already: screened whatever its exact
             * margin, and not evaluated unless the QP's step could reach it (ocp_nlp_screen.c); with
             * the exact Hessian only without a multiplier, whose curvature it would carry */
            if ((!exact || s->mult.lam_lg[n][j] == HM_R(0.0)) && ocp_nlp_screen_far(x, r.c, j < nh ? far_h : far_o)) {
                qp->D[n][j][0] = qp->D[n][j][1] = HM_R(0.0);
                qp->lg[n][j] = -HM_INF;
                continue;
            }
            hm_model_distance_constraint(x, r.c, r.d_min, &g, qp->D[n][j], hess_d);
            if (exact) {
                /* L = cost - lam (d - d_min + s): the row's curvature enters with -lam. */
                const hm_real lam = s->mult.lam_lg[n][j];
                Q[0] -= lam * hess_d[0];
                Q[1] -= lam * hess_d[1];
                Q[HM_NX] -= lam * hess_d[2];
                Q[HM_NX + 1] -= lam * hess_d[3];
            }
            qp->lg[n][j] = -g;
            penalty += ocp_nlp_slack_penalty(g, r.l1, r.l2);
        }
    }
    s->dyn_fresh = 0;
    if (exact)
        for (n = 0; n <= HM_N; n++) ocp_nlp_convexify_stage(qp, n, hm_fmax(reg, HM_R(1e-8)));
    s->cost = cost + penalty;
    s->cost_slack = penalty;
    s->n_active = ng;
}

/* The measured state enters the QP as the offset of its fixed x_0 from the iterate's. With speed and
 * separation, the upper speed bounds too: node 1's from the measured state, and every node's never
 * below the speed that braking at the lower acceleration bound from the measured speed reaches there
 * (v is linear in the controls, so the braking plan is feasible: a bound that braking cannot keep is
 * the monitor's to report, not an infeasible QP). */
HM_FUNC void ocp_nlp_set_x0(hm_solver *s, const hm_input *in)
{
    const hm_params *p = &s->params;
    hm_real penalty;
    int i, n;
    for (i = 0; i < HM_NX; i++) s->qp.x0[i] = in->x0[i] - s->x[0][i];
    if (!p->separation) return;
    s->v_separation[1] = monitor_separation_bound(in, p, in->x0, 0, p->v_bounds[1]);
    for (n = 1; n <= HM_N; n++) {
        const hm_real braked = hm_fmax(p->v_bounds[0], in->x0[3] + p->a_bounds[0] * HM_R(HM_DT) * (hm_real)n);
        s->v_separation[n] = hm_fmin(p->v_bounds[1], hm_fmax(s->v_separation[n], braked)); /* idempotent */
        s->qp.ubx[n][3] = s->v_separation[n] - s->x[n][3];
    }
    /* The iterate may exceed bounds that moved with it, which a QP step then closes: the merit of
     * the line search (and the cost reported) counts the excess, or it would refuse that step. */
    penalty = ocp_nlp_separation_penalty(s);
    s->cost += penalty;
    s->cost_slack += penalty;
}
