/*
 * ocp_qp_hsde_kkt.c: the Newton system of the fallback solver's embedding, over its packed rows: the
 * stage matrices with the row weights condensed in, a Riccati factorisation (once per iteration)
 * and the solves (three per iteration: the constant right-hand side, the predictor, the corrector),
 * with dz and the soft slacks eliminated and expanded again, and the tau row.
 */
#include "ocp_qp_hsde.h"
#include "ocp_qp_hsde_kkt.h"
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
    const int so = ws->soff[n], ro = ws->roff[n];
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
            const int kr = ws->soft_of[so + j];
            const hm_real Zl = ws->soft_Zl[so + j];
            const hm_real wsl = w[base + nr + j];
            const hm_real hinv = HM_R(1.0) / (Zl + wrow[kr] + wsl);
            ws->soft_hinv[so + j] = hinv;
            wrow[kr] *= (Zl + wsl) * hinv;
        }
        {
            hm_real h00 = HM_R(0.0), h10 = HM_R(0.0), h11 = HM_R(0.0);
            for (k = 0; k < nr; k++) {
                const hm_real *restrict d = ws->D[ro + k];
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
    const int so = ws->soff[n], ro = ws->roff[n];
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
            const int kr = ws->soft_of[so + j];
            const hm_real e = (rhs->s[ro + kr] - coef[kr] - w[jr] * rz[jr]) * ws->soft_hinv[so + j];
            ws->soft_e[so + j] = e;
            coef[kr] += w[base + kr] * e;
        }
        for (k = 0; k < nr; k++) {
            const hm_real *restrict d = ws->D[ro + k];
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
    const int so = ws->soff[n], ro = ws->roff[n];
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
            const hm_real *restrict d = ws->D[ro + k];
            gd[k] = -(d[0] * dp0 + d[1] * dp1);
        }
    }
    for (j = 0; j < ns; j++) {
        const int jr = base + nr + j;
        const int kr = ws->soft_of[so + j];
        const hm_real dsl = ws->soft_e[so + j] + w[base + kr] * ws->soft_hinv[so + j] * gd[kr];
        sol->s[ro + kr] = dsl;
        sol->z[jr] = w[jr] * (-dsl - rhs->z[jr]);
        gd[kr] -= dsl;
    }
    for (k = 0; k < nr; k++) sol->z[base + k] = w[base + k] * (gd[k] - rhs->z[base + k]);
}

/* The part of stage n of c' sol_v + b' sol_w, the tau row of the interior-point Newton system, with
 * c = (ws->c_ux, ws->c_s) and b = (ws->b_eq, ws->b_ineq); evaluated while the stage is in cache. */
HM_FUNC hm_real ocp_qp_hsde_kkt_tau_row(const hm_ocp_qp_hsde_ws *restrict ws, const hm_ocp_qp_hsde_vec *sol, int n)
{
    const int so = ws->soff[n], ro = ws->roff[n];
    const int off = ws->off[n];
    const int nc = ws->nb[n] + ws->nr[n] + ws->ns[n];
    hm_real acc = HM_R(0.0);
    int i, j;
    for (i = 0; i < HM_QP_NUX; i++) acc += ws->c_ux[n][i] * sol->ux[n][i];
    for (j = 0; j < ws->ns[n]; j++) {
        const int kr = ws->soft_of[so + j];
        acc += ws->c_s[ro + kr] * sol->s[ro + kr];
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
