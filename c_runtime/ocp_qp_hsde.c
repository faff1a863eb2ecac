/*
 * ocp_qp_hsde.c: the fallback solver of ocp_qp_ipm_solve (ocp_qp_hsde.h): the homogeneous self-dual
 * embedding interior-point method, with its own packed row layout and Riccati factorisation. Runs
 * when the primal-dual iteration stalls, from scratch, in the memory that the primal-dual method's
 * stage blocks otherwise occupy (ocp_qp_ipm_ws.u).
 */
#include "ocp_qp.h"
#include "ocp_qp_hsde.h"
#include "ocp_qp_kkt.h"


/* Inverse square root of a pivot of the 2x2 input block, or -1 if the pivot is not positive beyond
 * the rounding noise of the diagonal it came from (`!(a > b)` also catches NaN). */
HM_FUNC hm_real ocp_qp_hsde_kkt_pivot_inv(hm_real pivot, hm_real diag)
{
    if (!(pivot > HM_R(64.0) * HM_EPS * diag) || !(pivot > HM_R(0.0))) return HM_R(-1.0);
    return HM_R(1.0) / hm_sqrt(pivot);
}

/* Lower triangle of the 6x6 stage matrix (column-major, u first) without the recursion term: cost
 * Hessian (times ws->cost_scale), bound weights on the diagonal, and every general row as w D D' on (px, py), where a soft
 * row with weight w_r, slack-bound weight w_s and slack Hessian Zl acts like a hard row of weight
 * w_r (Zl + w_s) / (Zl + w_r + w_s) (the two in series; written as a product, not as
 * w_r - w_r^2 / (...), which cancels when w_r is large). */
HM_FUNC void ocp_qp_hsde_kkt_stage_matrix(const hm_ocp_qp *restrict qp, hm_ocp_qp_hsde_ws *restrict ws, int n,
                                     hm_real *restrict H)
{
    const hm_real *restrict w = ws->w;
    const int off = ws->off[n];
    const int nb = ws->nb[n];
    const int base = off + nb;
    const int nr = ws->nr[n];
    const int ns = ws->ns[n];
    const hm_real c = ws->cost_scale;
    hm_real wrow[HM_NG > 0 ? HM_NG : 1];
    int i, j, k;

    if (n < HM_N) {
        const hm_real *restrict R = qp->R[n];
        H[0] = c * R[0];
        H[1] = c * R[1];
        H[1 + HM_QP_NUX] = c * R[3];
        if (n > 0) {
            const hm_real *restrict S = qp->S[n];
            for (j = 0; j < HM_NU; j++) {
                for (i = 0; i < HM_NX; i++) H[HM_NU + i + j * HM_QP_NUX] = c * S[j + i * HM_NU];
            }
        }
    }
    if (n > 0) {
        const hm_real *restrict Q = qp->Q[n];
        for (j = 0; j < HM_NX; j++) {
            for (i = j; i < HM_NX; i++) H[HM_NU + i + (HM_NU + j) * HM_QP_NUX] = c * Q[i + j * HM_NX];
        }
        for (k = 0; k < nr; k++) wrow[k] = w[base + k];
        for (j = 0; j < ns; j++) {
            const int kr = ws->soft_of[n][j];
            const hm_real Zl = ws->soft_Zl[n][j];
            const hm_real wsl = w[base + nr + j];
            const hm_real hinv = HM_R(1.0) / (Zl + wrow[kr] + wsl);
            ws->soft_hinv[n][j] = hinv;
            wrow[kr] *= (Zl + wsl) * hinv;
        }
        {
            hm_real h00 = HM_R(0.0), h10 = HM_R(0.0), h11 = HM_R(0.0);
            for (k = 0; k < nr; k++) {
                const hm_real *restrict d = ws->D[n][k];
                const hm_real wd0 = wrow[k] * d[0];
                h00 += wd0 * d[0];
                h10 += wd0 * d[1];
                h11 += wrow[k] * d[1] * d[1];
            }
            H[HM_NU + HM_NU * HM_QP_NUX] += h00;
            H[HM_NU + 1 + HM_NU * HM_QP_NUX] += h10;
            H[HM_NU + 1 + (HM_NU + 1) * HM_QP_NUX] += h11;
        }
    }
    for (k = 0; k < nb; k++) H[ws->box_comp[n][k] * (HM_QP_NUX + 1)] += w[off + k];
}

HM_FUNC int ocp_qp_hsde_kkt_factorize(const hm_ocp_qp *restrict qp, hm_ocp_qp_hsde_ws *restrict ws)
{
    hm_real H[HM_QP_NUX * HM_QP_NUX];
    int n, i, j;

    ocp_qp_hsde_kkt_stage_matrix(qp, ws, HM_N, H);
    for (j = 0; j < HM_NX; j++) {
        for (i = j; i < HM_NX; i++) {
            const hm_real v = H[HM_NU + i + (HM_NU + j) * HM_QP_NUX];
            ws->P[HM_N][i + j * HM_NX] = v;
            ws->P[HM_N][j + i * HM_NX] = v;
        }
    }

    for (n = HM_N - 1; n >= 0; n--) {
        const hm_real *restrict Pn = ws->P[n + 1];
        const hm_real *restrict A = qp->A[n];
        const hm_real *restrict B = qp->B[n];
        hm_real FB[HM_NX * HM_NU];   /* P_{n+1} B */
        hm_real *restrict L = ws->Lr[n];
        hm_real l00, l10, piv;

        ocp_qp_hsde_kkt_stage_matrix(qp, ws, n, H);
        ocp_qp_kkt_mul4(Pn, B, FB, HM_NU);
        for (j = 0; j < HM_NU; j++) {
            for (i = j; i < HM_NU; i++) H[i + j * HM_QP_NUX] += ocp_qp_kkt_dot4(&B[i * HM_NX], &FB[j * HM_NX]);
        }
        if (n > 0) {
            hm_real FA[HM_NX * HM_NX];   /* P_{n+1} A */
            ocp_qp_kkt_mul4(Pn, A, FA, HM_NX);
            for (j = 0; j < HM_NU; j++) {
                for (i = 0; i < HM_NX; i++)
                    H[HM_NU + i + j * HM_QP_NUX] += ocp_qp_kkt_dot4(&A[i * HM_NX], &FB[j * HM_NX]);
            }
            for (j = 0; j < HM_NX; j++) {
                for (i = j; i < HM_NX; i++)
                    H[HM_NU + i + (HM_NU + j) * HM_QP_NUX] += ocp_qp_kkt_dot4(&A[i * HM_NX], &FA[j * HM_NX]);
            }
        }

        /* partial Cholesky over the u rows; a pivot that is not safely positive means the QP is not
         * strictly convex in u along the current active set */
        if (!(H[0] > HM_R(0.0))) return HM_QP_NUMERICAL;
        l00 = hm_sqrt(H[0]);
        L[0] = HM_R(1.0) / l00;
        l10 = H[1] * L[0];
        L[1] = l10;
        piv = H[1 + HM_QP_NUX] - l10 * l10;
        L[2] = ocp_qp_hsde_kkt_pivot_inv(piv, H[1 + HM_QP_NUX]);
        if (L[2] < HM_R(0.0)) return HM_QP_NUMERICAL;
        if (n == 0) break;
        {
            hm_real *restrict Y = ws->Y[n];
            hm_real *restrict P = ws->P[n];
            for (j = 0; j < HM_NX; j++) {
                const hm_real y0 = H[HM_NU + j] * L[0];
                Y[0 + j * HM_NU] = y0;
                Y[1 + j * HM_NU] = (H[HM_NU + j + HM_QP_NUX] - l10 * y0) * L[2];
            }
            for (j = 0; j < HM_NX; j++) {
                const hm_real yj0 = Y[0 + j * HM_NU], yj1 = Y[1 + j * HM_NU];
                for (i = j; i < HM_NX; i++) {
                    const hm_real v = H[HM_NU + i + (HM_NU + j) * HM_QP_NUX] - Y[0 + i * HM_NU] * yj0
                                      - Y[1 + i * HM_NU] * yj1;
                    P[i + j * HM_NX] = v;
                    P[j + i * HM_NX] = v;
                }
            }
        }
    }
    return 0;
}

/* Gradient of the equality-constrained stage QP that is left after eliminating dz and the soft
 * slacks: h_n = -(rhs_v + A_I' W rhs_z) on (u, x), with the soft slacks folded in (their step at a
 * zero position step is kept in ws->soft_e for ocp_qp_hsde_kkt_expand). */
HM_FUNC void ocp_qp_hsde_kkt_condense(hm_ocp_qp_hsde_ws *restrict ws,
                                 const hm_ocp_qp_hsde_vec *rhs, int n, hm_real *restrict h)
{
    const hm_real *restrict w = ws->w;
    const hm_real *rz = rhs->z;
    const int off = ws->off[n];
    const int nb = ws->nb[n];
    const int base = off + nb;
    const int nr = ws->nr[n];
    const int ns = ws->ns[n];
    int i, j, k;
    for (i = 0; i < HM_QP_NUX; i++) h[i] = -rhs->ux[n][i];
    for (k = 0; k < nb; k++) h[ws->box_comp[n][k]] -= ws->box_sign[n][k] * w[off + k] * rz[off + k];
    if (nr > 0) {
        hm_real coef[HM_NG > 0 ? HM_NG : 1];   /* the multiple of D of each row in h_p */
        hm_real hp0 = HM_R(0.0), hp1 = HM_R(0.0);
        for (k = 0; k < nr; k++) coef[k] = w[base + k] * rz[base + k];
        for (j = 0; j < ns; j++) {
            const int jr = base + nr + j;
            const int kr = ws->soft_of[n][j];
            const hm_real e = (rhs->s[n][kr] - coef[kr] - w[jr] * rz[jr]) * ws->soft_hinv[n][j];
            ws->soft_e[n][j] = e;
            coef[kr] += w[base + kr] * e;
        }
        for (k = 0; k < nr; k++) {
            const hm_real *restrict d = ws->D[n][k];
            hp0 += coef[k] * d[0];
            hp1 += coef[k] * d[1];
        }
        h[HM_NU] += hp0;
        h[HM_NU + 1] += hp1;
    }
}

/* dz of the rows of stage n and the soft slack steps, from the (u, x) step of the stage. Reads each
 * entry of rhs before it writes the same entry of sol, so the two may be one vector. */
HM_FUNC void ocp_qp_hsde_kkt_expand(const hm_ocp_qp_hsde_ws *restrict ws,
                               const hm_ocp_qp_hsde_vec *rhs, hm_ocp_qp_hsde_vec *sol, int n)
{
    const hm_real *restrict w = ws->w;
    const hm_real *dux = sol->ux[n];
    const int off = ws->off[n];
    const int nb = ws->nb[n];
    const int base = off + nb;
    const int nr = ws->nr[n];
    const int ns = ws->ns[n];
    hm_real gd[HM_NG > 0 ? HM_NG : 1];   /* -(D' dp + ds) of each general row */
    int j, k;
    for (k = 0; k < nb; k++) {
        const int c = ws->box_comp[n][k];
        sol->z[off + k] = w[off + k] * (ws->box_sign[n][k] * dux[c] - rhs->z[off + k]);
    }
    if (nr == 0) return;
    {
        const hm_real dp0 = dux[HM_NU], dp1 = dux[HM_NU + 1];
        for (k = 0; k < nr; k++) {
            const hm_real *restrict d = ws->D[n][k];
            gd[k] = -(d[0] * dp0 + d[1] * dp1);
        }
    }
    for (j = 0; j < ns; j++) {
        const int jr = base + nr + j;
        const int kr = ws->soft_of[n][j];
        const hm_real dsl = ws->soft_e[n][j] + w[base + kr] * ws->soft_hinv[n][j] * gd[kr];
        sol->s[n][kr] = dsl;
        sol->z[jr] = w[jr] * (-dsl - rhs->z[jr]);
        gd[kr] -= dsl;
    }
    for (k = 0; k < nr; k++) sol->z[base + k] = w[base + k] * (gd[k] - rhs->z[base + k]);
}

/* The part of stage n of c' sol_v + b' sol_w, the tau row of the interior-point Newton system, with
 * c = (ws->c_ux, ws->c_s) and b = (ws->b_eq, ws->b_ineq); evaluated while the stage is in cache. */
HM_FUNC hm_real ocp_qp_hsde_kkt_tau_row(const hm_ocp_qp_hsde_ws *restrict ws, const hm_ocp_qp_hsde_vec *sol, int n)
{
    const int off = ws->off[n];
    const int nc = ws->nb[n] + ws->nr[n] + ws->ns[n];
    hm_real acc = HM_R(0.0);
    int i, j;
    for (i = 0; i < HM_QP_NUX; i++) acc += ws->c_ux[n][i] * sol->ux[n][i];
    for (j = 0; j < ws->ns[n]; j++) {
        const int kr = ws->soft_of[n][j];
        acc += ws->c_s[n][kr] * sol->s[n][kr];
    }
    if (n < HM_N) {
        for (i = 0; i < HM_NX; i++) acc += ws->b_eq[n][i] * sol->y[n][i];
    }
    for (j = off; j < off + nc; j++) acc += ws->b_ineq[j] * sol->z[j];
    return acc;
}

HM_FUNC hm_real ocp_qp_hsde_kkt_solve(const hm_ocp_qp *restrict qp, hm_ocp_qp_hsde_ws *restrict ws,
                                 const hm_ocp_qp_hsde_vec *rhs, hm_ocp_qp_hsde_vec *sol)
{
    hm_real cdot = HM_R(0.0);
    int n, i, k;

    /* backward: cost-to-go gradients p_n and the input terms yk_n = Lr^-1 (reduced input gradient) */
    {
        hm_real h[HM_QP_NUX];
        ocp_qp_hsde_kkt_condense(ws, rhs, HM_N, h);
        for (i = 0; i < HM_NX; i++) ws->p[HM_N][i] = h[HM_NU + i];
    }
    for (n = HM_N - 1; n >= 0; n--) {
        const hm_real *restrict Pn = ws->P[n + 1];
        const hm_real *restrict A = qp->A[n];
        const hm_real *restrict B = qp->B[n];
        const hm_real *restrict L = ws->Lr[n];
        const hm_real *ry = rhs->y[n];
        hm_real h[HM_QP_NUX], pb[HM_NX], rb0, rb1, y0, y1;
        ocp_qp_hsde_kkt_condense(ws, rhs, n, h);
        for (i = 0; i < HM_NX; i++) pb[i] = ws->p[n + 1][i];
        for (k = 0; k < HM_NX; k++) {
            const hm_real rk = ry[k];
            for (i = 0; i < HM_NX; i++) pb[i] += Pn[i + k * HM_NX] * rk;
        }
        rb0 = h[0] + B[0] * pb[0] + B[1] * pb[1] + B[2] * pb[2] + B[3] * pb[3];
        rb1 = h[1] + B[4] * pb[0] + B[5] * pb[1] + B[6] * pb[2] + B[7] * pb[3];
        y0 = rb0 * L[0];
        y1 = (rb1 - L[1] * y0) * L[2];
        ws->yk[n][0] = y0;
        ws->yk[n][1] = y1;
        if (n > 0) {
            const hm_real *restrict Y = ws->Y[n];
            hm_real *restrict p = ws->p[n];
            for (i = 0; i < HM_NX; i++) {
                const hm_real *restrict a = &A[i * HM_NX];
                p[i] = h[HM_NU + i] + a[0] * pb[0] + a[1] * pb[1] + a[2] * pb[2] + a[3] * pb[3]
                       - Y[0 + i * HM_NU] * y0 - Y[1 + i * HM_NU] * y1;
            }
        }
    }

    /* forward: u_n = -Lr^-T (Y x_n + yk_n), x_{n+1} = A x_n + B u_n + rhs_y, dy_n = -(P x + p) */
    for (i = 0; i < HM_NX; i++) sol->ux[0][HM_NU + i] = HM_R(0.0);
    for (n = 0; n < HM_N; n++) {
        const hm_real *restrict Pn = ws->P[n + 1];
        const hm_real *restrict A = qp->A[n];
        const hm_real *restrict B = qp->B[n];
        const hm_real *restrict L = ws->Lr[n];
        hm_real *ux = sol->ux[n];
        hm_real *xn = &sol->ux[n + 1][HM_NU];
        hm_real x[HM_NX], xnew[HM_NX], a0 = ws->yk[n][0], a1 = ws->yk[n][1], u0, u1;
        for (i = 0; i < HM_NX; i++) x[i] = ux[HM_NU + i];
        if (n > 0) {
            const hm_real *restrict Y = ws->Y[n];
            for (k = 0; k < HM_NX; k++) {
                a0 += Y[0 + k * HM_NU] * x[k];
                a1 += Y[1 + k * HM_NU] * x[k];
            }
        }
        u1 = -a1 * L[2];
        u0 = -(a0 + L[1] * u1) * L[0];
        ux[0] = u0;
        ux[1] = u1;
        for (i = 0; i < HM_NX; i++) xnew[i] = rhs->y[n][i] + B[i] * u0 + B[i + HM_NX] * u1;
        if (n > 0) {
            for (k = 0; k < HM_NX; k++) {
                const hm_real xk = x[k];
                for (i = 0; i < HM_NX; i++) xnew[i] += A[i + k * HM_NX] * xk;
            }
        }
        {
            hm_real dy[HM_NX];
            for (i = 0; i < HM_NX; i++) dy[i] = ws->p[n + 1][i];
            for (k = 0; k < HM_NX; k++) {
                const hm_real xk = xnew[k];
                for (i = 0; i < HM_NX; i++) dy[i] += Pn[i + k * HM_NX] * xk;
            }
            for (i = 0; i < HM_NX; i++) {
                xn[i] = xnew[i];
                sol->y[n][i] = -dy[i];
            }
        }
        ocp_qp_hsde_kkt_expand(ws, rhs, sol, n);
        cdot += ocp_qp_hsde_kkt_tau_row(ws, sol, n);
    }
    for (i = 0; i < HM_NU; i++) sol->ux[HM_N][i] = HM_R(0.0);
    ocp_qp_hsde_kkt_expand(ws, rhs, sol, HM_N);
    return cdot + ocp_qp_hsde_kkt_tau_row(ws, sol, HM_N);
}


/* Cap of the row weights z / t, relative to the curvature of the cost. Near the solution the weights
 * of active rows grow like 1 / mu; condensed into the Riccati recursion, whose Schur complements
 * subtract them again, they leave rounding errors of eps * weight in the moderate directions, and
 * beyond ~1e-6 / eps the cost-to-go matrices lose definiteness and the steps go wrong. Capping the
 * weight makes the Newton step slightly inexact on active rows only; that error shrinks with the
 * step itself, so convergence is kept (measured on random QPs solved to 1e-10: 300/300 with the cap,
 * 70% without it). */
#ifdef HM_REAL_IS_FLOAT
#define OCP_QP_HSDE_W_MAX_REL HM_R(1e4)
#else
#define OCP_QP_HSDE_W_MAX_REL HM_R(1e10)
#endif

/* max without libm's fmax call (whose NaN rule is not needed here: NaN is caught on the sums) */
#define OCP_QP_HSDE_MAX(a, b) ((a) > (b) ? (a) : (b))

/* Packs the present inequality rows and computes the data of the embedding and its norms. Returns
 * HM_QP_INFEASIBLE if a lower bound exceeds its upper bound; *bad = stage * HM_QP_NUX + component. */
HM_FUNC int ocp_qp_hsde_setup(const hm_ocp_qp *qp, hm_ocp_qp_hsde_ws *ws, int *bad)
{
    int n, i, k, m = 0;
    hm_real norm_q = HM_R(0.0), norm_b = HM_R(0.0), hscale = HM_R(0.0);
    for (n = 0; n <= HM_N; n++) {
        int nb = 0, nr = 0, ns = 0;
        ws->off[n] = m;
        for (i = 0; i < HM_QP_NUX; i++) {
            hm_real lb, ub;
            if (i < HM_NU) {
                if (n == HM_N) continue;
                lb = qp->lbu[n][i];
                ub = qp->ubu[n][i];
            } else {
                if (n == 0) continue;
                lb = qp->lbx[n][i - HM_NU];
                ub = qp->ubx[n][i - HM_NU];
            }
            if (ocp_qp_bound_present(lb)) {
                if (ocp_qp_bound_present(ub) && lb > ub) {
                    *bad = n * HM_QP_NUX + i;
                    return HM_QP_INFEASIBLE;
                }
                ws->box_comp[n][nb] = (unsigned char)i;
                ws->box_sign[n][nb] = HM_R(-1.0);
                ws->b_ineq[m + nb] = -lb;
                nb++;
            }
            if (ocp_qp_bound_present(ub)) {
                ws->box_comp[n][nb] = (unsigned char)i;
                ws->box_sign[n][nb] = HM_R(1.0);
                ws->b_ineq[m + nb] = ub;
                nb++;
            }
        }
        if (n > 0) {
            for (i = 0; i < qp->ng[n]; i++) {
                if (!ocp_qp_bound_present(qp->lg[n][i])) continue;
                ws->row_idx[n][nr] = (unsigned char)i;
                ws->D[n][nr][0] = qp->D[n][i][0];
                ws->D[n][nr][1] = qp->D[n][i][1];
                ws->b_ineq[m + nb + nr] = -qp->lg[n][i];
                nr++;
            }
            for (k = 0; k < nr; k++) {
                const int i_row = ws->row_idx[n][k];
                if (!qp->soft[n][i_row]) continue;
                ws->soft_of[n][ns] = (unsigned char)k;
                ws->b_ineq[m + nb + nr + ns] = HM_R(0.0);
                ws->q_s[n][k] = qp->zl[n][i_row];
                norm_q = OCP_QP_HSDE_MAX(norm_q, hm_fabs(qp->zl[n][i_row]));
                hscale = OCP_QP_HSDE_MAX(hscale, hm_fabs(qp->Zl[n][i_row]));
                ns++;
            }
        }
        ws->nb[n] = nb;
        ws->nr[n] = nr;
        ws->ns[n] = ns;
        /* the tau row is evaluated by every solve, also those before the first residuals */
        for (i = 0; i < HM_QP_NUX; i++) ws->c_ux[n][i] = HM_R(0.0);
        for (k = 0; k < nr; k++) ws->c_s[n][k] = HM_R(0.0);
        m += nb + nr + ns;

        /* linear cost on (u, x); x_0 is data, its terms move into stage 0 */
        for (i = 0; i < HM_NU; i++) {
            hm_real acc = HM_R(0.0);
            if (n < HM_N) {
                acc = qp->r[n][i];
                if (n == 0) {
                    for (k = 0; k < HM_NX; k++) acc += qp->S[0][i + k * HM_NU] * qp->x0[k];
                }
                hscale = OCP_QP_HSDE_MAX(hscale, hm_fabs(qp->R[n][i * (HM_NU + 1)]));
            }
            ws->q_ux[n][i] = acc;
        }
        for (i = 0; i < HM_NX; i++) {
            ws->q_ux[n][HM_NU + i] = n == 0 ? HM_R(0.0) : qp->q[n][i];
            if (n > 0) hscale = OCP_QP_HSDE_MAX(hscale, hm_fabs(qp->Q[n][i * (HM_NX + 1)]));
        }
        for (i = 0; i < HM_QP_NUX; i++) norm_q = OCP_QP_HSDE_MAX(norm_q, hm_fabs(ws->q_ux[n][i]));
        if (n < HM_N) {
            for (i = 0; i < HM_NX; i++) {
                hm_real acc = qp->b[n][i];
                if (n == 0) {
                    for (k = 0; k < HM_NX; k++) acc += qp->A[0][i + k * HM_NX] * qp->x0[k];
                }
                ws->b_eq[n][i] = acc;
                norm_b = OCP_QP_HSDE_MAX(norm_b, hm_fabs(acc));
            }
        }
    }
    ws->m = m;
    for (i = 0; i < m; i++) norm_b = OCP_QP_HSDE_MAX(norm_b, hm_fabs(ws->b_ineq[i]));

    /* Cost scaling (as in Clarabel): the embedding balances cost against constraints through tau and
     * kappa, and a cost measured in hundreds (goal weight 250) against rows measured in metres made
     * it take twice the iterations. Clipped so that tiny or huge data are not blown up. */
    {
        const hm_real mag = OCP_QP_HSDE_MAX(hscale, norm_q);
        const hm_real c = HM_R(1.0) / (mag < HM_R(1e-4) ? HM_R(1e-4) : (mag > HM_R(1e4) ? HM_R(1e4) : mag));
        for (n = 0; n <= HM_N; n++) {
            for (i = 0; i < HM_QP_NUX; i++) ws->q_ux[n][i] *= c;
            for (k = 0; k < ws->nr[n]; k++) ws->q_s[n][k] *= c;
            for (k = 0; k < ws->ns[n]; k++) ws->soft_Zl[n][k] = c * qp->Zl[n][ws->row_idx[n][ws->soft_of[n][k]]];
        }
        ws->cost_scale = c;
        ws->norm_q = norm_q * c;
        ws->w_max = OCP_QP_HSDE_W_MAX_REL * OCP_QP_HSDE_MAX(HM_R(1.0), hscale * c);
    }
    ws->norm_b = norm_b;
    return 0;
}

/* y = c H_n x for the cost Hessian [R S'; S Q] of stage n on (u, x) and the cost scale c; parts
 * absent at stage 0 (x) and stage N (u) are zero in y and ignored in x. */
HM_FUNC void ocp_qp_hsde_stage_hess_mul(const hm_ocp_qp *restrict qp, int n, hm_real c, const hm_real *restrict x,
                                       hm_real *restrict y)
{
    int i, k;
    if (n < HM_N) {
        const hm_real *restrict R = qp->R[n];
        y[0] = c * (R[0] * x[0] + R[2] * x[1]);
        y[1] = c * (R[1] * x[0] + R[3] * x[1]);
    } else {
        y[0] = y[1] = HM_R(0.0);
    }
    if (n == 0) {
        for (i = 0; i < HM_NX; i++) y[HM_NU + i] = HM_R(0.0);
        return;
    }
    {
        const hm_real *restrict Q = qp->Q[n];
        hm_real yx[HM_NX] = {HM_R(0.0), HM_R(0.0), HM_R(0.0), HM_R(0.0)};
        for (k = 0; k < HM_NX; k++) {
            const hm_real xk = x[HM_NU + k];
            for (i = 0; i < HM_NX; i++) yx[i] += Q[i + k * HM_NX] * xk;
        }
        if (n < HM_N) {
            const hm_real *restrict S = qp->S[n];
            hm_real su0 = HM_R(0.0), su1 = HM_R(0.0);
            for (k = 0; k < HM_NX; k++) {
                const hm_real *restrict sk = &S[k * HM_NU];
                su0 += sk[0] * x[HM_NU + k];
                su1 += sk[1] * x[HM_NU + k];
                yx[k] += sk[0] * x[0] + sk[1] * x[1];
            }
            y[0] += c * su0;
            y[1] += c * su1;
        }
        for (i = 0; i < HM_NX; i++) y[HM_NU + i] = c * yx[i];
    }
}

/* Scalars of one residual evaluation. */
typedef struct {
    hm_real qv, bw, vPv, tz;          /* q' v, b' w, v' P v, t' z */
    hm_real atw, pv, av_eq, av_ineq;  /* inf-norms of A' w, P v, A_E v, A_I v + t */
    hm_real rd, rp;                   /* inf-norms of the dual and primal residuals */
    hm_real nv, nw, nt;               /* inf-norms of v, w, t */
} ocp_qp_hsde_sums;

/* Residuals of the embedding at the point (v, t, tau, ws->kappa) into ws->rv:
 *   rv.ux, rv.s = P v + A' w + q tau,   rv.y = A_E v - b_E tau,   rv.z = A_I v + t - b_I tau,
 *   rtau = kappa + q' v + b' w + v' P v / tau,
 * the vector c = q + 2 P v / tau of the tau row, and the scalars of the termination tests. With
 * weights, also the row weights of the Newton matrix at this point (ws->w, ws->winv, ws->zinv). */
HM_FUNC void ocp_qp_hsde_residuals(const hm_ocp_qp *restrict qp, hm_ocp_qp_hsde_ws *restrict ws,
                                  const hm_ocp_qp_hsde_vec *restrict v, const hm_real *restrict t, hm_real tau,
                                  int weights, ocp_qp_hsde_sums *restrict sm)
{
    hm_ocp_qp_hsde_vec *restrict r = &ws->rv;
    const hm_real two_tinv = HM_R(2.0) / tau;
    const hm_real w_max = ws->w_max;
    hm_real qv = HM_R(0.0), bw = HM_R(0.0), vPv = HM_R(0.0), tz = HM_R(0.0);
    hm_real atw_n = HM_R(0.0), pv_n = HM_R(0.0), aveq_n = HM_R(0.0), avin_n = HM_R(0.0);
    hm_real rd = HM_R(0.0), rp = HM_R(0.0), nv = HM_R(0.0), nw = HM_R(0.0), nt = HM_R(0.0);
    int n, i, j, k;

    for (n = 0; n <= HM_N; n++) {
        const hm_real *restrict ux = v->ux[n];
        const hm_real *restrict qn = ws->q_ux[n];
        const int off = ws->off[n];
        const int nb = ws->nb[n];
        const int base = off + nb;
        const int nr = ws->nr[n];
        const int ns = ws->ns[n];
        const int c0 = n == HM_N ? HM_NU : 0;
        const int c1 = n == 0 ? HM_NU : HM_QP_NUX;
        hm_real Pux[HM_QP_NUX], atw[HM_QP_NUX];

        ocp_qp_hsde_stage_hess_mul(qp, n, ws->cost_scale, ux, Pux);

        /* A' w on (u, x): dynamics, bounds, general rows */
        if (n < HM_N) {
            const hm_real *restrict B = qp->B[n];
            const hm_real *restrict y = v->y[n];
            atw[0] = -(B[0] * y[0] + B[1] * y[1] + B[2] * y[2] + B[3] * y[3]);
            atw[1] = -(B[4] * y[0] + B[5] * y[1] + B[6] * y[2] + B[7] * y[3]);
        } else {
            atw[0] = atw[1] = HM_R(0.0);
        }
        if (n > 0) {
            for (i = 0; i < HM_NX; i++) atw[HM_NU + i] = v->y[n - 1][i];
            if (n < HM_N) {
                const hm_real *restrict A = qp->A[n];
                const hm_real *restrict y = v->y[n];
                for (i = 0; i < HM_NX; i++) {
                    const hm_real *restrict a = &A[i * HM_NX];
                    atw[HM_NU + i] -= a[0] * y[0] + a[1] * y[1] + a[2] * y[2] + a[3] * y[3];
                }
            }
        } else {
            for (i = 0; i < HM_NX; i++) atw[HM_NU + i] = HM_R(0.0);
        }
        for (k = 0; k < nb; k++) {
            const int c = ws->box_comp[n][k];
            const hm_real sg = ws->box_sign[n][k];
            atw[c] += sg * v->z[off + k];
            r->z[off + k] = sg * ux[c] + t[off + k] - ws->b_ineq[off + k] * tau;
        }
        if (nr > 0) {
            const hm_real p0 = ux[HM_NU], p1 = ux[HM_NU + 1];
            hm_real a0 = HM_R(0.0), a1 = HM_R(0.0);
            for (k = 0; k < nr; k++) {
                const hm_real *restrict d = ws->D[n][k];
                const hm_real zk = v->z[base + k];
                a0 += d[0] * zk;
                a1 += d[1] * zk;
                r->z[base + k] = t[base + k] - (d[0] * p0 + d[1] * p1) - ws->b_ineq[base + k] * tau;
                /* soft slack subtracted below */
            }
            atw[HM_NU] -= a0;
            atw[HM_NU + 1] -= a1;
        }
        for (j = 0; j < ns; j++) {
            const int jr = base + nr + j;
            const int kr = ws->soft_of[n][j];
            const hm_real s = v->s[n][kr];
            const hm_real ps = ws->soft_Zl[n][j] * s;
            const hm_real atws = -v->z[base + kr] - v->z[jr];
            const hm_real rs = ps + atws + ws->q_s[n][kr] * tau;
            r->s[n][kr] = rs;
            ws->c_s[n][kr] = ws->q_s[n][kr] + two_tinv * ps;
            r->z[base + kr] -= s;
            r->z[jr] = t[jr] - s;
            qv += ws->q_s[n][kr] * s;
            vPv += ps * s;
            atw_n = OCP_QP_HSDE_MAX(atw_n, hm_fabs(atws));
            pv_n = OCP_QP_HSDE_MAX(pv_n, hm_fabs(ps));
            rd = OCP_QP_HSDE_MAX(rd, hm_fabs(rs));
            nv = OCP_QP_HSDE_MAX(nv, hm_fabs(s));
        }
        for (i = 0; i < HM_QP_NUX; i++) {
            const hm_real ri = Pux[i] + atw[i] + qn[i] * tau;
            r->ux[n][i] = ri;
            ws->c_ux[n][i] = qn[i] + two_tinv * Pux[i];
        }
        for (i = c0; i < c1; i++) {
            qv += qn[i] * ux[i];
            vPv += Pux[i] * ux[i];
            atw_n = OCP_QP_HSDE_MAX(atw_n, hm_fabs(atw[i]));
            pv_n = OCP_QP_HSDE_MAX(pv_n, hm_fabs(Pux[i]));
            rd = OCP_QP_HSDE_MAX(rd, hm_fabs(r->ux[n][i]));
            nv = OCP_QP_HSDE_MAX(nv, hm_fabs(ux[i]));
        }

        /* dynamics rows x_{n+1} - A x_n - B u_n = b_n tau */
        if (n < HM_N) {
            const hm_real *restrict A = qp->A[n];
            const hm_real *restrict B = qp->B[n];
            const hm_real *restrict y = v->y[n];
            hm_real e[HM_NX];
            for (i = 0; i < HM_NX; i++) e[i] = v->ux[n + 1][HM_NU + i] - B[i] * ux[0] - B[i + HM_NX] * ux[1];
            if (n > 0) {
                for (k = 0; k < HM_NX; k++) {
                    const hm_real xk = ux[HM_NU + k];
                    for (i = 0; i < HM_NX; i++) e[i] -= A[i + k * HM_NX] * xk;
                }
            }
            for (i = 0; i < HM_NX; i++) {
                const hm_real bi = ws->b_eq[n][i];
                const hm_real ri = e[i] - bi * tau;
                r->y[n][i] = ri;
                aveq_n = OCP_QP_HSDE_MAX(aveq_n, hm_fabs(e[i]));
                rp = OCP_QP_HSDE_MAX(rp, hm_fabs(ri));
                bw += bi * y[i];
                nw = OCP_QP_HSDE_MAX(nw, hm_fabs(y[i]));
            }
        }
    }
    /* and, for the Newton matrix of this iterate, the row weights w = min(z / t, w_max), 1 / w and
     * 1 / z, with one division per row */
    for (j = 0; j < ws->m; j++) {
        const hm_real zj = v->z[j], tj = t[j];
        rp = OCP_QP_HSDE_MAX(rp, hm_fabs(r->z[j]));
        avin_n = OCP_QP_HSDE_MAX(avin_n, hm_fabs(r->z[j] + ws->b_ineq[j] * tau));
        bw += ws->b_ineq[j] * zj;
        tz += tj * zj;
        nw = OCP_QP_HSDE_MAX(nw, zj);
        nt = OCP_QP_HSDE_MAX(nt, tj);
    }
    for (j = 0; weights && j < ws->m; j++) {
        const hm_real zj = v->z[j], tj = t[j];
        const hm_real inv = HM_R(1.0) / (tj * zj);
        const hm_real wj = zj * zj * inv;
        ws->zinv[j] = tj * inv;
        if (wj < w_max) {
            ws->w[j] = wj;
            ws->winv[j] = tj * tj * inv;
        } else {
            ws->w[j] = w_max;
            ws->winv[j] = HM_R(1.0) / w_max;
        }
    }
    ws->rtau = ws->kappa + qv + bw + vPv / tau;
    sm->qv = qv;
    sm->bw = bw;
    sm->vPv = vPv;
    sm->tz = tz;
    sm->atw = atw_n;
    sm->pv = pv_n;
    sm->av_eq = aveq_n;
    sm->av_ineq = avin_n;
    sm->rd = rd;
    sm->rp = rp;
    sm->nv = nv;
    sm->nw = nw;
    sm->nt = nt;
}

/* The tau pivot of the Newton system, -kappa/tau + c' v1 + b' w1 - v' P v / tau^2 for the constant
 * solve (v1, w1). Evaluated in the equal form -kappa/tau - (v1 - v/tau)' P (v1 - v/tau) -
 * sum_j z1_j^2 / w_j, negative by construction: near the solution the first form cancels to rounding
 * noise and can even come out positive. */
HM_FUNC hm_real ocp_qp_hsde_tau_pivot(const hm_ocp_qp *restrict qp, const hm_ocp_qp_hsde_ws *restrict ws,
                                     hm_real tinv)
{
    const hm_ocp_qp_hsde_vec *restrict v1 = &ws->v1;
    const hm_ocp_qp_hsde_vec *restrict v = &ws->v;
    hm_real acc = ws->kappa * tinv;
    int n, i, j;
    for (n = 0; n <= HM_N; n++) {
        hm_real d[HM_QP_NUX], Hd[HM_QP_NUX];
        for (i = 0; i < HM_QP_NUX; i++) d[i] = v1->ux[n][i] - tinv * v->ux[n][i];
        ocp_qp_hsde_stage_hess_mul(qp, n, ws->cost_scale, d, Hd);
        for (i = 0; i < HM_QP_NUX; i++) acc += d[i] * Hd[i];
        for (j = 0; j < ws->ns[n]; j++) {
            const int kr = ws->soft_of[n][j];
            const hm_real ds = v1->s[n][kr] - tinv * v->s[n][kr];
            acc += ws->soft_Zl[n][j] * ds * ds;
        }
    }
    for (j = 0; j < ws->m; j++) acc += v1->z[j] * v1->z[j] * ws->winv[j];
    return -acc;
}

/* y += a x on the (u, x), soft-slack and dynamics-multiplier parts (z is each caller's own). */
HM_FUNC void ocp_qp_hsde_vec_axpy_except_z(const hm_ocp_qp_hsde_ws *restrict ws, hm_real a,
                                         const hm_ocp_qp_hsde_vec *restrict x, hm_ocp_qp_hsde_vec *restrict y)
{
    int n, i, j;
    for (n = 0; n <= HM_N; n++) {
        for (i = 0; i < HM_QP_NUX; i++) y->ux[n][i] += a * x->ux[n][i];
        for (j = 0; j < ws->ns[n]; j++) {
            const int kr = ws->soft_of[n][j];
            y->s[n][kr] += a * x->s[n][kr];
        }
    }
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NX; i++) y->y[n][i] += a * x->y[n][i];
    }
}

/* The step (ws->dv, ws->dt, ws->dtau, ws->dkappa) that leaves (1 - keep) of the residuals, for the
 * complementarity targets t o z + z o dt + t o dz = t o z - ds (ds in ws->ds) and
 * tau kappa + kappa dtau + tau dkappa = tau kappa - dk. den is the tau pivot of this factorisation.
 * Returns the largest alpha in (0, 1] with t, z, tau, kappa + alpha * step >= 0 (dividing only
 * where a row shortens the step). */
HM_FUNC hm_real ocp_qp_hsde_direction(const hm_ocp_qp *restrict qp, hm_ocp_qp_hsde_ws *restrict ws, hm_real keep,
                                  hm_real dk, hm_real den)
{
    hm_ocp_qp_hsde_vec *restrict d = &ws->dv;
    const hm_ocp_qp_hsde_vec *restrict r = &ws->rv;
    const hm_ocp_qp_hsde_vec *restrict v1 = &ws->v1;
    const hm_real tau = ws->tau;
    hm_real dtau, a = HM_R(1.0);
    int n, i, j;
    for (n = 0; n <= HM_N; n++) {
        for (i = 0; i < HM_QP_NUX; i++) d->ux[n][i] = -keep * r->ux[n][i];
        for (j = 0; j < ws->ns[n]; j++) {
            const int kr = ws->soft_of[n][j];
            d->s[n][kr] = -keep * r->s[n][kr];
        }
    }
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NX; i++) d->y[n][i] = -keep * r->y[n][i];
    }
    for (j = 0; j < ws->m; j++) d->z[j] = ws->ds[j] * ws->zinv[j] - keep * r->z[j];
    dtau = (dk / tau - keep * ws->rtau - ocp_qp_hsde_kkt_solve(qp, ws, d, d)) / den;
    ocp_qp_hsde_vec_axpy_except_z(ws, dtau, v1, d);
    ws->dtau = dtau;
    ws->dkappa = -(dk + ws->kappa * dtau) / tau;
    if (-ws->dtau * a > ws->tau) a = -ws->tau / ws->dtau;
    if (-ws->dkappa * a > ws->kappa) a = -ws->kappa / ws->dkappa;
    for (j = 0; j < ws->m; j++) {
        const hm_real dz = d->z[j] + dtau * v1->z[j];
        const hm_real tj = ws->t[j], zj = ws->v.z[j];
        const hm_real dtj = -(ws->ds[j] + tj * dz) * ws->zinv[j];
        d->z[j] = dz;
        ws->dt[j] = dtj;
        if (-dtj * a > tj) a = -tj / dtj;
        if (-dz * a > zj) a = -zj / dz;
    }
    return a;
}

/* Clarabel's shift of a starting vector into the interior of the nonnegative orthant. */
HM_FUNC void ocp_qp_hsde_shift_interior(hm_real *x, int m)
{
    hm_real mn = HM_INF, pos = HM_R(0.0), target;
    int j;
    if (m == 0) return;
    for (j = 0; j < m; j++) {
        mn = x[j] < mn ? x[j] : mn;
        pos += OCP_QP_HSDE_MAX(x[j], HM_R(0.0));
    }
    target = OCP_QP_HSDE_MAX(HM_R(1.0), HM_R(0.1) * pos / (hm_real)m);
    if (mn <= HM_R(0.0)) {
        /* in two stages: x - mn + target in one go can round x_min to 0 when target << |mn| */
        for (j = 0; j < m; j++) x[j] -= mn;
        for (j = 0; j < m; j++) x[j] += target;
    } else if (mn < target) {
        for (j = 0; j < m; j++) x[j] += target - mn;
    }
}

/* The right-hand side (-q, b) of the constant solve, into a. */
HM_FUNC void ocp_qp_hsde_constant_rhs(const hm_ocp_qp_hsde_ws *restrict ws, hm_ocp_qp_hsde_vec *restrict a)
{
    int n, i, j;
    for (n = 0; n <= HM_N; n++) {
        for (i = 0; i < HM_QP_NUX; i++) a->ux[n][i] = -ws->q_ux[n][i];
        for (j = 0; j < ws->ns[n]; j++) {
            const int kr = ws->soft_of[n][j];
            a->s[n][kr] = -ws->q_s[n][kr];
        }
    }
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NX; i++) a->y[n][i] = ws->b_eq[n][i];
    }
    for (j = 0; j < ws->m; j++) a->z[j] = ws->b_ineq[j];
}

/* sol := the point v (an iterate, or the polished solution) with the primal part scaled by sp
 * (1 / tau) and the multipliers by sc (1 / (tau * cost scale)); or, with sp = 0, the certificate
 * w scaled by sc (1 / -b'w). */
HM_FUNC void ocp_qp_hsde_write_sol(const hm_ocp_qp *qp, const hm_ocp_qp_hsde_ws *ws, const hm_ocp_qp_hsde_vec *v,
                                  hm_ocp_qp_sol *sol, hm_real sc, hm_real sp)
{
    int n, i, j, k;
    ocp_qp_sol_set_zero(sol);
    for (i = 0; i < HM_NX; i++) sol->x[0][i] = qp->x0[i];
    for (n = 0; n <= HM_N; n++) {
        const int off = ws->off[n];
        const int base = off + ws->nb[n];
        const int nr = ws->nr[n];
        if (n < HM_N) {
            for (i = 0; i < HM_NU; i++) sol->u[n][i] = sp * v->ux[n][i];
            for (i = 0; i < HM_NX; i++) sol->pi[n][i] = -sc * v->y[n][i];
        }
        if (n > 0) {
            for (i = 0; i < HM_NX; i++) sol->x[n][i] = sp * v->ux[n][HM_NU + i];
        }
        for (k = 0; k < ws->nb[n]; k++) {
            const int c = ws->box_comp[n][k];
            const hm_real lam = sc * v->z[off + k];
            const int upper = ws->box_sign[n][k] > HM_R(0.0);
            if (c < HM_NU) {
                if (upper) sol->lam_ubu[n][c] = lam;
                else sol->lam_lbu[n][c] = lam;
            } else {
                if (upper) sol->lam_ubx[n][c - HM_NU] = lam;
                else sol->lam_lbx[n][c - HM_NU] = lam;
            }
        }
        for (k = 0; k < nr; k++) sol->lam_lg[n][ws->row_idx[n][k]] = sc * v->z[base + k];
        for (j = 0; j < ws->ns[n]; j++) {
            const int kr = ws->soft_of[n][j];
            const int i_row = ws->row_idx[n][kr];
            sol->s[n][i_row] = sp * v->s[n][kr];
            sol->lam_ls[n][i_row] = sc * v->z[base + nr + j];
        }
    }
}

/* Starting point (Clarabel's for QPs): (v, w) solving the Newton system with unit row weights for
 * the right-hand side (-q, b), i.e. the minimiser of the cost plus 1/2 ||A_I v - b_I||^2 under the
 * dynamics; then t = b_I - A_I v and z, each shifted into the interior; tau = kappa = 1. */
HM_FUNC int ocp_qp_hsde_init(const hm_ocp_qp *qp, hm_ocp_qp_hsde_ws *ws)
{
    int j;
    for (j = 0; j < ws->m; j++) ws->w[j] = HM_R(1.0);
    if (ocp_qp_hsde_kkt_factorize(qp, ws)) return HM_QP_NUMERICAL;
    ocp_qp_hsde_constant_rhs(ws, &ws->v);
    ocp_qp_hsde_kkt_solve(qp, ws, &ws->v, &ws->v);
    for (j = 0; j < ws->m; j++) ws->t[j] = -ws->v.z[j];
    ocp_qp_hsde_shift_interior(ws->t, ws->m);
    ocp_qp_hsde_shift_interior(ws->v.z, ws->m);
    ws->tau = HM_R(1.0);
    ws->kappa = HM_R(1.0);
    return 0;
}

/* Active-set polish (after OSQP's): rows whose slack is smaller than their multiplier are taken as
 * active and become equalities, the others are dropped, and the QP is solved on that active set. An
 * interior-point iterate stops at complementarity ~ tol, where a constraint that is active with a
 * zero multiplier (degenerate) keeps a slack of ~sqrt(tol); the polished point has none. The
 * equality-constrained system is solved by the Riccati factorisation with the active rows held by the
 * largest row weight and the dropped ones by a negligible one, plus two steps of iterative
 * refinement against the exact system, which remove both that penalty error and the rounding error
 * of the large weights. A degenerate row can be taken as active and come out with a (tiny) negative
 * multiplier: such rows are dropped and the solve repeated once. The result replaces the iterate
 * only if its worst KKT residual is smaller. Costs one or two factorisations, three solves each. */
HM_FUNC void ocp_qp_hsde_polish(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_hsde_ws *ws)
{
    hm_ocp_qp_hsde_vec *d = &ws->dv;
    hm_ocp_qp_hsde_vec *e = &ws->v1;
    const hm_ocp_qp_hsde_vec *r = &ws->rv;
    /* dropped rows keep a weight far below rounding level, not zero: a soft row's slack may have
     * neither curvature nor an active bound, and its elimination divides by the sum of the three */
    const hm_real w_drop = HM_EPS * HM_EPS / ws->w_max;
    const hm_real before = ocp_qp_res_worst(&ws->out.res);
    hm_ocp_qp_res res;
    ocp_qp_hsde_sums sm;
    int j, k, n, i, round, dropped = 1;

    for (j = 0; j < ws->m; j++) ws->w[j] = ws->t[j] < ws->v.z[j] ? ws->w_max : w_drop;
    for (round = 0; round < 2 && dropped; round++) {
        if (ocp_qp_hsde_kkt_factorize(qp, ws)) return;
        ocp_qp_hsde_constant_rhs(ws, d);
        ocp_qp_hsde_kkt_solve(qp, ws, d, d);
        for (k = 0; k < 2; k++) {
            /* residual of the exact system: active rows a' v = b, dropped rows as factorised */
            for (j = 0; j < ws->m; j++) ws->dt[j] = ws->w[j] < ws->w_max ? -d->z[j] / ws->w[j] : HM_R(0.0);
            ocp_qp_hsde_residuals(qp, ws, d, ws->dt, HM_R(1.0), 0, &sm);
            for (n = 0; n <= HM_N; n++) {
                for (i = 0; i < HM_QP_NUX; i++) e->ux[n][i] = -r->ux[n][i];
                for (j = 0; j < ws->ns[n]; j++) e->s[n][ws->soft_of[n][j]] = -r->s[n][ws->soft_of[n][j]];
            }
            for (n = 0; n < HM_N; n++) {
                for (i = 0; i < HM_NX; i++) e->y[n][i] = -r->y[n][i];
            }
            for (j = 0; j < ws->m; j++) e->z[j] = -r->z[j];
            ocp_qp_hsde_kkt_solve(qp, ws, e, e);
            for (n = 0; n <= HM_N; n++) {
                for (i = 0; i < HM_QP_NUX; i++) d->ux[n][i] += e->ux[n][i];
                for (j = 0; j < ws->ns[n]; j++) d->s[n][ws->soft_of[n][j]] += e->s[n][ws->soft_of[n][j]];
            }
            for (n = 0; n < HM_N; n++) {
                for (i = 0; i < HM_NX; i++) d->y[n][i] += e->y[n][i];
            }
            for (j = 0; j < ws->m; j++) d->z[j] += e->z[j];
        }
        dropped = 0;
        for (j = 0; j < ws->m; j++) {
            if (ws->w[j] < ws->w_max) {
                d->z[j] = HM_R(0.0);
            } else if (d->z[j] < HM_R(0.0)) {
                ws->w[j] = w_drop;
                dropped = 1;
            }
        }
    }
    ocp_qp_hsde_write_sol(qp, ws, d, sol, HM_R(1.0) / ws->cost_scale, HM_R(1.0));
    ocp_qp_res_compute(qp, sol, &res);
    if (ocp_qp_res_worst(&res) < before) {
        ws->out.res = res;
        ws->out.polished = 1;
    } else {
        ocp_qp_hsde_write_sol(qp, ws, &ws->v, sol, HM_R(1.0) / (ws->tau * ws->cost_scale), HM_R(1.0) / ws->tau);
    }
}

/* Ends a solve: the solution, the certificate (with b' w = bw) or zeros (before the first iterate,
 * or for non-finite iterates) into sol, its residuals into ws->out.res. */
HM_FUNC int ocp_qp_hsde_finish(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_hsde_ws *ws, int status,
                              hm_real bw, int have_iterate, int polish)
{
    if (status == HM_QP_INFEASIBLE) {
        ocp_qp_hsde_write_sol(qp, ws, &ws->v, sol, HM_R(1.0) / -bw, HM_R(0.0));
    } else if (status == HM_QP_NONFINITE || !have_iterate) {
        ocp_qp_sol_set_zero(sol);
    } else {
        ocp_qp_hsde_write_sol(qp, ws, &ws->v, sol, HM_R(1.0) / (ws->tau * ws->cost_scale), HM_R(1.0) / ws->tau);
    }
    ocp_qp_res_compute(qp, sol, &ws->out.res);
    if (status == HM_QP_SOLVED && polish) ocp_qp_hsde_polish(qp, sol, ws);
    ws->out.status = status;
    return status;
}

HM_FUNC int ocp_qp_hsde_solve(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_hsde_ws *ws,
                             const hm_ocp_qp_ipm_arg *arg)
{
    int status, bad = 0, j;
    ocp_qp_hsde_sums sm;
    hm_real mu0 = HM_R(1.0);

    ws->out.iter = 0;
    ws->out.unbounded = 0;
    ws->out.polished = 0;
    ws->out.res_primal = ws->out.res_dual = ws->out.gap = ws->out.mu = HM_R(0.0);
    ws->tau = ws->kappa = HM_R(1.0);

    status = ocp_qp_check(qp);
    if (status) return ocp_qp_hsde_finish(qp, sol, ws, status, HM_R(0.0), 0, 0);
    status = ocp_qp_hsde_setup(qp, ws, &bad);
    if (status == HM_QP_INFEASIBLE) {
        ocp_qp_sol_box_certificate(qp, sol, bad);
        ocp_qp_res_compute(qp, sol, &ws->out.res);
        ws->out.status = status;
        return status;
    }
    status = ocp_qp_hsde_init(qp, ws);
    if (status) return ocp_qp_hsde_finish(qp, sol, ws, status, HM_R(0.0), 0, 0);

    for (;;) {
        const hm_real mdeg = (hm_real)(ws->m + 1);
        hm_real mu, tinv, res_p, res_d, pcost, gap, gap_rel, den, sigma, dk, alpha_aff, corr, frac, alpha;

        ocp_qp_hsde_residuals(qp, ws, &ws->v, ws->t, ws->tau, 1, &sm);
        mu = (sm.tz + ws->tau * ws->kappa) / mdeg;
        if (ws->out.iter == 0) mu0 = mu;
        ws->out.mu = mu;
        if (!isfinite(mu + sm.rd + sm.rp + ws->rtau + sm.nv + sm.nw)) {
            status = HM_QP_NONFINITE;
            break;
        }

        /* termination tests on the QP point v / tau */
        tinv = HM_R(1.0) / ws->tau;
        res_p = sm.rp * tinv / OCP_QP_HSDE_MAX(HM_R(1.0), ws->norm_b + (sm.nv + sm.nt) * tinv);
        res_d = sm.rd * tinv / OCP_QP_HSDE_MAX(HM_R(1.0), ws->norm_q + (sm.nv + sm.nw) * tinv);
        /* the complementarity t' z of the QP point (= primal - dual cost once the residuals vanish,
         * but without the cancellation of those two large numbers), absolute and relative to the
         * cost, in the units of the data */
        pcost = (sm.qv * tinv + HM_R(0.5) * sm.vPv * tinv * tinv) / ws->cost_scale;
        gap = sm.tz * tinv * tinv / ws->cost_scale;
        gap_rel = gap / OCP_QP_HSDE_MAX(HM_R(1.0), hm_fabs(pcost));
        ws->out.res_primal = res_p;
        ws->out.res_dual = res_d;
        ws->out.gap = gap_rel;
        if (ws->kappa <= ws->tau && res_p <= arg->tol && res_d <= arg->tol
            && (gap <= arg->tol || gap_rel <= arg->tol)) {
            status = HM_QP_SOLVED;
            break;
        }
        if (ws->kappa > ws->tau) {
            if (sm.bw < HM_R(0.0) && sm.atw <= arg->tol_infeas * -sm.bw) {
                status = HM_QP_INFEASIBLE;
                break;
            }
            const hm_real cinv = HM_R(1.0) / ws->cost_scale;
            if (arg->detect_unbounded && sm.qv < HM_R(0.0)
                && OCP_QP_HSDE_MAX(sm.pv * cinv, OCP_QP_HSDE_MAX(sm.av_eq, sm.av_ineq)) <= arg->tol_infeas * -sm.qv * cinv) {
                ws->out.unbounded = 1;
                status = HM_QP_NUMERICAL;
                break;
            }
        }
        if (ws->out.iter >= arg->max_iter) {
            status = HM_QP_MAX_ITER;
            break;
        }
        /* the residuals have met their rounding floor above tol: going on only drives mu into
         * underflow and the iterates into noise */
        if (mu < mu0 * HM_EPS * HM_EPS) {
            status = HM_QP_NUMERICAL;
            break;
        }
        if (arg->should_stop && arg->should_stop(arg->stop_ctx)) {
            status = HM_QP_TIMEOUT;
            break;
        }
        ws->out.iter++;

        /* Newton matrix (weights from ocp_qp_hsde_residuals), and its solve for the constant right-hand
         * side (v1, w1) = K^-1 (-q, b) */
        if (ocp_qp_hsde_kkt_factorize(qp, ws)) {
            status = HM_QP_NUMERICAL;
            break;
        }
        ocp_qp_hsde_constant_rhs(ws, &ws->v1);
        ocp_qp_hsde_kkt_solve(qp, ws, &ws->v1, &ws->v1);
        den = ocp_qp_hsde_tau_pivot(qp, ws, tinv);
        if (!(den < HM_R(0.0))) {
            status = isfinite(den) ? HM_QP_NUMERICAL : HM_QP_NONFINITE;
            break;
        }

        /* affine predictor */
        for (j = 0; j < ws->m; j++) ws->ds[j] = ws->t[j] * ws->v.z[j];
        alpha_aff = ocp_qp_hsde_direction(qp, ws, HM_R(1.0), ws->tau * ws->kappa, den);
        sigma = (HM_R(1.0) - alpha_aff) * (HM_R(1.0) - alpha_aff) * (HM_R(1.0) - alpha_aff);

        /* Mehrotra corrector, with only part of the second-order term in the first iteration, whose
         * start may be far from central */
        corr = ws->out.iter > 1 ? HM_R(1.0) : alpha_aff;
        for (j = 0; j < ws->m; j++) ws->ds[j] += corr * ws->dt[j] * ws->dv.z[j] - sigma * mu;
        dk = ws->tau * ws->kappa + corr * ws->dtau * ws->dkappa - sigma * mu;
        alpha = ocp_qp_hsde_direction(qp, ws, HM_R(1.0) - sigma, dk, den);

        /* fraction to the boundary: arg->step_frac far from the solution, closer to 1 as mu falls
         * (relative to its start, so the rule does not depend on the data's units), which turns the
         * last iterations' linear rate 1 - step_frac into a superlinear one; never so close that t
         * or z could round to zero */
        frac = hm_fmin(HM_R(1.0) - mu / mu0, HM_R(1.0) - hm_sqrt(HM_EPS));
        alpha *= OCP_QP_HSDE_MAX(arg->step_frac, frac);
        if (!(alpha >= arg->min_step)) {
            status = isfinite(alpha) ? HM_QP_NUMERICAL : HM_QP_NONFINITE;
            break;
        }
        {
            hm_ocp_qp_hsde_vec *restrict v = &ws->v;
            const hm_ocp_qp_hsde_vec *restrict dv = &ws->dv;
            ocp_qp_hsde_vec_axpy_except_z(ws, alpha, dv, v);
            for (j = 0; j < ws->m; j++) {
                v->z[j] += alpha * dv->z[j];
                ws->t[j] += alpha * ws->dt[j];
            }
        }
        ws->tau += alpha * ws->dtau;
        ws->kappa += alpha * ws->dkappa;
    }
    return ocp_qp_hsde_finish(qp, sol, ws, status, sm.bw, 1, arg->polish);
}
