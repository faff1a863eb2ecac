/*
 * ocp_qp_kkt.c: Riccati factorisation and solution of the interior-point Newton system
 * (see ocp_qp_kkt.h): factorised once per iteration, solved twice (predictor, corrector), in the
 * stage blocks of the solve.
 *
 * Stage n carries the variables (u_n, x_n) in this order, a 6-vector whose Hessian is
 * H_n = [R S; S' Q] (S is stored as the 2x4 block u-by-x) plus the condensed inequalities; stage 0
 * has only u_0 (x_0 is fixed) and stage N only x_N. The recursion keeps the cost-to-go
 * 1/2 x' P_n x + p_n' x. Eliminating u_n from H_n + [B A]' P_{n+1} [B A] is a partial LDL'
 * factorisation of that 6x6 matrix over its two u rows: the 2x2 factor (1 / d0, l10, 1 / d1), the
 * 2x4 block Kx = L^-1 (S + B' P A) and the Schur complement P_n = (Q + A' P A) - Kx' D^-1 Kx. LDL'
 * rather than Cholesky: no square root on the recursion's critical path.
 *
 * The kernels are written for the fixed sizes (HM_NU = HM_NPOS = 2, HM_NX = 4): loops have
 * compile-time bounds and products are in axpy form over contiguous columns (2-wide SIMD).
 */
#include "ocp_qp_kkt.h"

/* y = P x for the full 4x4 P */
HM_KERNEL void ocp_qp_kkt_mv4(const hm_real *restrict P, const hm_real *restrict x, hm_real *restrict y)
{
    int i, k;
    for (i = 0; i < HM_NX; i++) y[i] = P[i] * x[0];
    for (k = 1; k < HM_NX; k++) {
        const hm_real xk = x[k];
        for (i = 0; i < HM_NX; i++) y[i] += P[i + k * HM_NX] * xk;
    }
}

/* LDL' of the 2x2 input block [h00 h10; h10 h11] into sn->Ld (1 / d0, l10, 1 / d1); HM_QP_NUMERICAL
 * if a pivot is not safely positive: the QP is not strictly convex in u along the current active set
 * (`!(a > b)` also catches NaN). */
HM_KERNEL int ocp_qp_kkt_input_ldl(hm_ocp_qp_ipm_stage *restrict sn, hm_real h00, hm_real h10, hm_real h11)
{
    hm_real id0, l10, d1;
    if (!(h00 > HM_R(0.0))) return HM_QP_NUMERICAL;
    id0 = HM_R(1.0) / h00;
    l10 = h10 * id0;
    d1 = h11 - l10 * h10;
    if (!(d1 > HM_R(64.0) * HM_EPS * h11) || !(d1 > HM_R(0.0))) return HM_QP_NUMERICAL;
    sn->Ld[0] = id0;
    sn->Ld[1] = l10;
    sn->Ld[2] = HM_R(1.0) / d1;
    return 0;
}

/* The closed-loop matrix F = A - B G of stage 0 < n < HM_N, G the feedback gain of the solves
 * (u = -G x + const): the substitutions carry p and x through F alone, one 4x4 product per stage
 * on their sequential chain instead of the gain's dot products followed by A and B. */
HM_KERNEL void ocp_qp_kkt_closed_loop(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_stage *restrict sn, int n)
{
    const hm_real *restrict A = qp->A[n];
    const hm_real *restrict B = qp->B[n];
    const hm_real *restrict K0 = sn->Kx;
    const hm_real *restrict K1 = sn->Kx + HM_NX;
    const hm_real id0 = sn->Ld[0], l10 = sn->Ld[1], id1 = sn->Ld[2];
    int i, k;
    for (k = 0; k < HM_NX; k++) {
        const hm_real g1 = id1 * K1[k];
        const hm_real g0 = id0 * K0[k] - l10 * g1;
        for (i = 0; i < HM_NX; i++) sn->F[i + k * HM_NX] = A[i + k * HM_NX] - B[i] * g0 - B[i + HM_NX] * g1;
    }
}

/* Stage 0 < n < HM_N of the factorisation for the robot's dynamics (sn->ab_int): A_n = [e_0 e_1 a_2 a_3]
 * (the position enters no other state's update) and rows 2 and 3 of [A_n B_n] are those of two
 * integrators (heading and speed: theta += b21 omega, v += b30 a), so a_2 = (a02, a12, 1, 0),
 * a_3 = (a03, a13, 0, 1) and B = [b00 b01; b10 b11; 0 b21; b30 0]. Written out for these shapes:
 * the symmetric entries once, the products with those zeros and ones left out and every sum kept in
 * the order of the sum over all four terms, so the results are those of the full products
 * (x + 0 * y = x, up to the sign of a zero). The products with P are column operations over P's
 * columns (P is stored mirrored: its columns are its rows), which the compiler runs in vector
 * lanes; the same sums written entry by entry made scalar code that was slower although it did
 * less arithmetic (docs/benchmarks.md). */
HM_FUNC int ocp_qp_kkt_factor_stage_integrators(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_stage *restrict sn,
                                                const hm_ocp_qp_ipm_stage *restrict sn1, int n, hm_real c)
{
    const hm_real *restrict P = sn1->P;
    const hm_real *restrict A = qp->A[n];
    const hm_real *restrict B = qp->B[n];
    const hm_real *restrict Q = qp->Q[n];   /* unscaled: every read below is times c */
    const hm_real *restrict S = qp->S[n];
    const hm_real *restrict R = qp->R[n];
    const hm_real *restrict Hd = sn->Hd;
    const hm_real *restrict r = sn->ry;
    const hm_real a02 = A[8], a12 = A[9], a03 = A[12], a13 = A[13];
    const hm_real b00 = B[0], b10 = B[1], b30 = B[3];
    const hm_real b01 = B[4], b11 = B[5], b21 = B[6];
    /* P B, P a_2, P a_3 and P ry, by columns */
    hm_real f0[HM_NX], f1[HM_NX], g2[HM_NX], g3[HM_NX];
    hm_real h00, h10, h11, x00, x10, x20, x30, x01, x11, x21, x31;
    hm_real id0, l10, id1, k0[4], k1[4], c0[4], c1[4], *restrict Pn = sn->P;
    hm_real q00, q10, q20, q30, q11, q21, q31, q22, q32, q33;
    int i;
    for (i = 0; i < HM_NX; i++) {
        f0[i] = P[i] * b00 + P[4 + i] * b10 + P[12 + i] * b30;
        f1[i] = P[i] * b01 + P[4 + i] * b11 + P[8 + i] * b21;
        g2[i] = P[i] * a02 + P[4 + i] * a12 + P[8 + i];
        g3[i] = P[i] * a03 + P[4 + i] * a13 + P[12 + i];
    }
    /* the input block */
    h00 = c * R[0] + Hd[0] + (b00 * f0[0] + b10 * f0[1] + b30 * f0[3]);
    h10 = c * R[1] + (b01 * f0[0] + b11 * f0[1] + b21 * f0[2]);
    h11 = c * R[3] + Hd[1] + (b01 * f1[0] + b11 * f1[1] + b21 * f1[2]);
    /* the state-input block (S + B' P A)', column j for u_j */
    x00 = c * S[0] + f0[0];
    x10 = c * S[2] + f0[1];
    x20 = c * S[4] + (a02 * f0[0] + a12 * f0[1] + f0[2]);
    x30 = c * S[6] + (a03 * f0[0] + a13 * f0[1] + f0[3]);
    x01 = c * S[1] + f1[0];
    x11 = c * S[3] + f1[1];
    x21 = c * S[5] + (a02 * f1[0] + a12 * f1[1] + f1[2]);
    x31 = c * S[7] + (a03 * f1[0] + a13 * f1[1] + f1[3]);
    for (i = 0; i < HM_NX; i++) sn->Pry[i] = P[i] * r[0] + P[4 + i] * r[1] + P[8 + i] * r[2] + P[12 + i] * r[3];
    if (ocp_qp_kkt_input_ldl(sn, h00, h10, h11)) return HM_QP_NUMERICAL;
    id0 = sn->Ld[0];
    l10 = sn->Ld[1];
    id1 = sn->Ld[2];
    k0[0] = x00;
    k0[1] = x10;
    k0[2] = x20;
    k0[3] = x30;
    k1[0] = x01 - l10 * x00;
    k1[1] = x11 - l10 * x10;
    k1[2] = x21 - l10 * x20;
    k1[3] = x31 - l10 * x30;
    c0[0] = k0[0] * id0;
    c0[1] = k0[1] * id0;
    c0[2] = k0[2] * id0;
    c0[3] = k0[3] * id0;
    c1[0] = k1[0] * id1;
    c1[1] = k1[1] * id1;
    c1[2] = k1[2] * id1;
    c1[3] = k1[3] * id1;
    sn->Kx[0] = k0[0];
    sn->Kx[1] = k0[1];
    sn->Kx[2] = k0[2];
    sn->Kx[3] = k0[3];
    sn->Kx[4] = k1[0];
    sn->Kx[5] = k1[1];
    sn->Kx[6] = k1[2];
    sn->Kx[7] = k1[3];
    /* Q + A' P A + the inequalities' diagonal and (px, py) block, minus the Schur terms */
    q00 = c * Q[0] + P[0] + Hd[2] + sn->Hpp[0] - c0[0] * k0[0] - c1[0] * k1[0];
    q10 = c * Q[1] + P[1] + sn->Hpp[1] - c0[1] * k0[0] - c1[1] * k1[0];
    q11 = c * Q[5] + P[5] + Hd[3] + sn->Hpp[2] - c0[1] * k0[1] - c1[1] * k1[1];
    q20 = c * Q[2] + g2[0] - c0[2] * k0[0] - c1[2] * k1[0];
    q21 = c * Q[6] + g2[1] - c0[2] * k0[1] - c1[2] * k1[1];
    q30 = c * Q[3] + g3[0] - c0[3] * k0[0] - c1[3] * k1[0];
    q31 = c * Q[7] + g3[1] - c0[3] * k0[1] - c1[3] * k1[1];
    q22 = c * Q[10] + Hd[4] + (a02 * g2[0] + a12 * g2[1] + g2[2]) - c0[2] * k0[2] - c1[2] * k1[2];
    q32 = c * Q[11] + (a03 * g2[0] + a13 * g2[1] + g2[3]) - c0[3] * k0[2] - c1[3] * k1[2];
    q33 = c * Q[15] + Hd[5] + (a03 * g3[0] + a13 * g3[1] + g3[3]) - c0[3] * k0[3] - c1[3] * k1[3];
    Pn[0] = q00;
    Pn[1] = q10;
    Pn[2] = q20;
    Pn[3] = q30;
    Pn[4] = q10;
    Pn[5] = q11;
    Pn[6] = q21;
    Pn[7] = q31;
    Pn[8] = q20;
    Pn[9] = q21;
    Pn[10] = q22;
    Pn[11] = q32;
    Pn[12] = q30;
    Pn[13] = q31;
    Pn[14] = q32;
    Pn[15] = q33;
    ocp_qp_kkt_closed_loop(qp, sn, n);
    return 0;
}

HM_FUNC int ocp_qp_kkt_factor_stage(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_stage *restrict sn,
                                    const hm_ocp_qp_ipm_stage *restrict sn1, int n, hm_real c)
{
    hm_real Hxx[HM_NX * HM_NX], Hxu[HM_NX * HM_NU];   /* column-major; Hxu column j for u_j */
    hm_real h00 = HM_R(0.0), h10 = HM_R(0.0), h11 = HM_R(0.0);
    int i, j;

    if (n > 0 && n < HM_N && sn->ab_int) return ocp_qp_kkt_factor_stage_integrators(qp, sn, sn1, n, c);
    if (n < HM_N) {
        const hm_real *restrict P = sn1->P;
        const hm_real *restrict A = qp->A[n];
        const hm_real *restrict B = qp->B[n];
        hm_real FB[HM_NX * HM_NU];   /* P_{n+1} B */
        ocp_qp_kkt_mul4(P, B, FB, HM_NU);
        ocp_qp_kkt_mv4(P, sn->ry, sn->Pry);
        h00 = c * qp->R[n][0] + sn->Hd[0] + ocp_qp_kkt_dot4(B, FB);
        h10 = c * qp->R[n][1] + ocp_qp_kkt_dot4(B + HM_NX, FB);
        h11 = c * qp->R[n][3] + sn->Hd[1] + ocp_qp_kkt_dot4(B + HM_NX, FB + HM_NX);
        if (n > 0) {
            hm_real FA[HM_NX * HM_NX];   /* P_{n+1} A */
            if (sn->a_id) {
                /* A = [e_0 e_1 a_2 a_3] (the position does not enter the dynamics of the others):
                 * P A = [P e_0, P e_1, P a_2, P a_3], and A' F reads rows 0 and 1 of F directly */
                for (i = 0; i < 2 * HM_NX; i++) FA[i] = P[i];
                ocp_qp_kkt_mul4(P, A + 2 * HM_NX, FA + 2 * HM_NX, 2);
                for (j = 0; j < HM_NU; j++) {
                    const hm_real *restrict f = FB + j * HM_NX;
                    Hxu[0 + j * HM_NX] = c * qp->S[n][j + 0 * HM_NU] + f[0];
                    Hxu[1 + j * HM_NX] = c * qp->S[n][j + 1 * HM_NU] + f[1];
                    Hxu[2 + j * HM_NX] = c * qp->S[n][j + 2 * HM_NU] + ocp_qp_kkt_dot4(A + 2 * HM_NX, f);
                    Hxu[3 + j * HM_NX] = c * qp->S[n][j + 3 * HM_NU] + ocp_qp_kkt_dot4(A + 3 * HM_NX, f);
                }
                /* lower triangle; (i, j) for i in {0, 1} is F[i, j], for i in {2, 3} a_i' F_j */
                for (j = 0; j < 2; j++) {
                    for (i = j; i < 2; i++) Hxx[i + j * HM_NX] = c * qp->Q[n][i + j * HM_NX] + FA[i + j * HM_NX];
                    /* a_i' P e_j = (P a_i)_j */
                    Hxx[2 + j * HM_NX] = c * qp->Q[n][2 + j * HM_NX] + FA[j + 2 * HM_NX];
                    Hxx[3 + j * HM_NX] = c * qp->Q[n][3 + j * HM_NX] + FA[j + 3 * HM_NX];
                }
                Hxx[2 + 2 * HM_NX] = c * qp->Q[n][2 + 2 * HM_NX] + ocp_qp_kkt_dot4(A + 2 * HM_NX, FA + 2 * HM_NX);
                Hxx[3 + 2 * HM_NX] = c * qp->Q[n][3 + 2 * HM_NX] + ocp_qp_kkt_dot4(A + 3 * HM_NX, FA + 2 * HM_NX);
                Hxx[3 + 3 * HM_NX] = c * qp->Q[n][3 + 3 * HM_NX] + ocp_qp_kkt_dot4(A + 3 * HM_NX, FA + 3 * HM_NX);
            } else {
                ocp_qp_kkt_mul4(P, A, FA, HM_NX);
                for (j = 0; j < HM_NU; j++) {
                    for (i = 0; i < HM_NX; i++)
                        Hxu[i + j * HM_NX] = c * qp->S[n][j + i * HM_NU] + ocp_qp_kkt_dot4(A + i * HM_NX, FB + j * HM_NX);
                }
                for (j = 0; j < HM_NX; j++) {
                    for (i = j; i < HM_NX; i++)
                        Hxx[i + j * HM_NX] = c * qp->Q[n][i + j * HM_NX] + ocp_qp_kkt_dot4(A + i * HM_NX, FA + j * HM_NX);
                }
            }
        }
    } else {
        for (i = 0; i < HM_NX * HM_NX; i++) Hxx[i] = c * qp->Q[n][i];
    }
    if (n > 0) {
        for (i = 0; i < HM_NX; i++) Hxx[i * (HM_NX + 1)] += sn->Hd[HM_NU + i];
        Hxx[0] += sn->Hpp[0];
        Hxx[1] += sn->Hpp[1];
        Hxx[HM_NX] += sn->Hpp[1];
        Hxx[HM_NX + 1] += sn->Hpp[2];
        if (n == HM_N) {
            for (i = 0; i < HM_NX * HM_NX; i++) sn->P[i] = Hxx[i];
            return 0;
        }
    }

    /* partial LDL' over the u rows */
    if (ocp_qp_kkt_input_ldl(sn, h00, h10, h11)) return HM_QP_NUMERICAL;
    {
        const hm_real id0 = sn->Ld[0], l10 = sn->Ld[1], id1 = sn->Ld[2];
        if (n == 0) return 0;
        {
            hm_real *restrict K0 = sn->Kx;
            hm_real *restrict K1 = sn->Kx + HM_NX;
            hm_real *restrict Pn = sn->P;
            hm_real k0s[HM_NX], k1s[HM_NX];
            for (i = 0; i < HM_NX; i++) {
                const hm_real a0 = Hxu[i], a1 = Hxu[i + HM_NX] - l10 * Hxu[i];
                K0[i] = a0;
                K1[i] = a1;
                k0s[i] = a0 * id0;
                k1s[i] = a1 * id1;
            }
            /* P_n = Hxx - K0 K0' / d0 - K1 K1' / d1, symmetric by construction (lower triangle
             * mirrored: Hxx is symmetric only up to rounding) */
            for (j = 0; j < HM_NX; j++) {
                for (i = j; i < HM_NX; i++) {
                    const hm_real v = Hxx[i + j * HM_NX] - k0s[i] * K0[j] - k1s[i] * K1[j];
                    Pn[i + j * HM_NX] = v;
                    Pn[j + i * HM_NX] = v;
                }
            }
            ocp_qp_kkt_closed_loop(qp, sn, n);
        }
    }
    return 0;
}

HM_FUNC void ocp_qp_kkt_backward_stage(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_stage *restrict sn,
                                       const hm_ocp_qp_ipm_stage *restrict sn1, int n, const hm_real *restrict h)
{
    int i;
    if (n == HM_N) {
        for (i = 0; i < HM_NX; i++) sn->p[i] = h[HM_NU + i];
        return;
    }
    {
        const hm_real *restrict B = qp->B[n];
        const hm_real *restrict L = sn->Ld;
        hm_real pb[HM_NX], y0, y1;
        for (i = 0; i < HM_NX; i++) pb[i] = sn1->p[i] + sn->Pry[i];
        y0 = h[0] + ocp_qp_kkt_dot4(B, pb);
        y1 = h[1] + ocp_qp_kkt_dot4(B + HM_NX, pb) - L[1] * y0;
        sn->yk[0] = y0;
        sn->yk[1] = y1;
        if (n > 0) {
            /* p = h_x + A' pb - Kx' D^-1 L^-1 (h_u + B' pb), regrouped as the part without pb plus
             * F' pb: only the latter waits for stage n + 1 */
            const hm_real c0 = h[0] * L[0], c1 = (h[1] - L[1] * h[0]) * L[2];
            const hm_real *restrict K0 = sn->Kx;
            const hm_real *restrict K1 = sn->Kx + HM_NX;
            const hm_real *restrict F = sn->F;
            for (i = 0; i < HM_NX; i++)
                sn->p[i] = (h[HM_NU + i] - K0[i] * c0 - K1[i] * c1) + ocp_qp_kkt_dot4(F + i * HM_NX, pb);
        }
    }
}

HM_FUNC void ocp_qp_kkt_forward_stage(const hm_ocp_qp *restrict qp, const hm_ocp_qp_ipm_stage *restrict sn,
                                      const hm_ocp_qp_ipm_stage *restrict sn1, int n, const hm_real *restrict x,
                                      hm_real *restrict u, hm_real *restrict xn, hm_real *restrict dy)
{
    const hm_real *restrict B = qp->B[n];
    const hm_real *restrict L = sn->Ld;
    hm_real w0 = sn->yk[0], w1 = sn->yk[1], v0, v1, t[HM_NX];
    int i;
    if (n > 0) {
        w0 += ocp_qp_kkt_dot4(sn->Kx, x);
        w1 += ocp_qp_kkt_dot4(sn->Kx + HM_NX, x);
    }
    v1 = w1 * L[2];
    v0 = w0 * L[0] - L[1] * v1;
    u[0] = -v0;
    u[1] = -v1;
    if (n > 0) {
        /* x_next = A x + B u + ry = F x + (ry + B u(x = 0)): the state waits on F x only */
        const hm_real e1 = sn->yk[1] * L[2];
        const hm_real e0 = sn->yk[0] * L[0] - L[1] * e1;
        hm_real fx[HM_NX];
        ocp_qp_kkt_mv4(sn->F, x, fx);
        for (i = 0; i < HM_NX; i++) xn[i] = (sn->ry[i] - B[i] * e0 - B[i + HM_NX] * e1) + fx[i];
    } else {
        for (i = 0; i < HM_NX; i++) xn[i] = sn->ry[i] - B[i] * v0 - B[i + HM_NX] * v1;
    }
    /* the multiplier step reads the state step back from xn: computed into a local array and
     * copied, it went through the stack on the sequential chain of the states (a store and a
     * reload more per stage) */
    if (dy) {
        ocp_qp_kkt_mv4(sn1->P, xn, t);
        for (i = 0; i < HM_NX; i++) dy[i] = -(t[i] + sn1->p[i]);
    }
}

#ifdef HM_QP_POLISH
/* ------------------------------------------------------------------------------------------------
 * The general system
 * ---------------------------------------------------------------------------------------------- */

HM_FUNC void ocp_qp_kkt_condense_weights(hm_ocp_qp_ipm_ws *ws)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    hm_ocp_qp_ipm_general *gs = &ws->u.f.gs;
    int n, k, j;
    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        hm_real h00 = HM_R(0.0), h10 = HM_R(0.0), h11 = HM_R(0.0);
        for (k = 0; k < HM_QP_NUX; k++) sn->Hd[k] = HM_R(0.0);
        for (k = 0; k < bd->nbp; k++) {
            const int c = bd->bc[k];
            sn->Hd[c] += bd->sg[k][0][n] * bd->sg[k][0][n] * bd->w[k][0][n]
                         + bd->sg[k][1][n] * bd->sg[k][1][n] * bd->w[k][1][n];
        }
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            /* a soft row with weight wr, slack-bound weight ws and slack Hessian Zl acts like a hard
             * row of weight wr (Zl + ws) / (Zl + wr + ws) (the two in series; as a product, not as
             * wr - wr^2 / (...), which cancels when wr is large) */
            const hm_real hinv = HM_R(1.0) / (sr->sZl[row] + gs->swr[row] + gs->sws[row]);
            const hm_real we = gs->swr[row] * (sr->sZl[row] + gs->sws[row]) * hinv;
            const hm_real wd0 = we * sr->sd0[row];
            gs->shi[row] = hinv;
            h00 += wd0 * sr->sd0[row];
            h10 += wd0 * sr->sd1[row];
            h11 += we * sr->sd1[row] * sr->sd1[row];
        }
        for (j = 0; j < sn->nh; j++) {
            const hm_real wd0 = sn->hr->hw[j] * sn->hr->hd0[j];
            h00 += wd0 * sn->hr->hd0[j];
            h10 += wd0 * sn->hr->hd1[j];
            h11 += sn->hr->hw[j] * sn->hr->hd1[j] * sn->hr->hd1[j];
        }
        sn->Hpp[0] = h00;
        sn->Hpp[1] = h10;
        sn->Hpp[2] = h11;
    }
}

HM_FUNC int ocp_qp_kkt_factorize(const hm_ocp_qp *qp, hm_ocp_qp_ipm_ws *ws)
{
    int n;
    for (n = HM_N; n >= 0; n--) {
        if (ocp_qp_kkt_factor_stage(qp, &ws->u.f.st[n], n < HM_N ? &ws->u.f.st[n + 1] : &ws->u.f.st[n], n,
                                    ws->cost_scale))
            return HM_QP_NUMERICAL;
    }
    return 0;
}

/* Gradient of the condensed stage QP for a general right-hand side: h = -(rhs_v + A_I' W rhs_z)
 * with the soft slacks folded in (their step at a zero position step into e). */
HM_FUNC void ocp_qp_kkt_condense(hm_ocp_qp_ipm_stage *sn, const hm_ocp_qp_ipm_bounds *bd,
                                 const hm_ocp_qp_ipm_rows *sr, hm_ocp_qp_ipm_general *gs,
                                 const hm_ocp_qp_ipm_vec *rhs, int n, hm_real *h)
{
    hm_real hp0 = HM_R(0.0), hp1 = HM_R(0.0);
    int i, k, j;
    for (i = 0; i < HM_QP_NUX; i++) h[i] = -rhs->ux[n][i];
    for (k = 0; k < bd->nbp; k++) {
        const int c = bd->bc[k];
        h[c] -= bd->sg[k][0][n] * bd->w[k][0][n] * rhs->zb[n][k][0]
                + bd->sg[k][1][n] * bd->w[k][1][n] * rhs->zb[n][k][1];
    }
    for (j = 0; j < sn->ns; j++) {
        const int row = sn->soff + j;
        hm_real coef = gs->swr[row] * rhs->zr[n][j];
        const hm_real ej = (rhs->s[n][j] - coef - gs->sws[row] * rhs->zs[n][j]) * gs->shi[row];
        gs->se[row] = ej;
        coef += gs->swr[row] * ej;
        hp0 += coef * sr->sd0[row];
        hp1 += coef * sr->sd1[row];
    }
    for (j = 0; j < sn->nh; j++) {
        const hm_real coef = sn->hr->hw[j] * rhs->zh[n][j];
        hp0 += coef * sn->hr->hd0[j];
        hp1 += coef * sn->hr->hd1[j];
    }
    h[HM_NU] += hp0;
    h[HM_NU + 1] += hp1;
}

/* dz of the inequalities of stage n and the soft slack steps, from the (u, x) step of the stage.
 * Reads each entry of rhs before it writes the same entry of sol, so the two may be one vector. */
HM_FUNC void ocp_qp_kkt_expand(const hm_ocp_qp_ipm_stage *sn, const hm_ocp_qp_ipm_bounds *bd,
                               const hm_ocp_qp_ipm_rows *sr, const hm_ocp_qp_ipm_general *gs,
                               const hm_ocp_qp_ipm_vec *rhs, hm_ocp_qp_ipm_vec *sol, int n)
{
    const hm_real *dux = sol->ux[n];
    const hm_real dp0 = dux[HM_NU], dp1 = dux[HM_NU + 1];
    int k, j, l;
    for (k = 0; k < bd->nbp; k++) {
        const int c = bd->bc[k];
        for (l = 0; l < 2; l++) sol->zb[n][k][l] = bd->w[k][l][n] * (bd->sg[k][l][n] * dux[c] - rhs->zb[n][k][l]);
    }
    for (j = 0; j < sn->ns; j++) {
        const int row = sn->soff + j;
        hm_real gd = -(sr->sd0[row] * dp0 + sr->sd1[row] * dp1);
        const hm_real dsl = gs->se[row] + gs->swr[row] * gs->shi[row] * gd;
        sol->s[n][j] = dsl;
        sol->zs[n][j] = gs->sws[row] * (-dsl - rhs->zs[n][j]);
        gd -= dsl;
        sol->zr[n][j] = gs->swr[row] * (gd - rhs->zr[n][j]);
    }
    for (j = 0; j < sn->nh; j++) {
        const hm_real gd = -(sn->hr->hd0[j] * dp0 + sn->hr->hd1[j] * dp1);
        sol->zh[n][j] = sn->hr->hw[j] * (gd - rhs->zh[n][j]);
    }
}

HM_FUNC void ocp_qp_kkt_solve(const hm_ocp_qp *qp, hm_ocp_qp_ipm_ws *ws, const hm_ocp_qp_ipm_vec *rhs,
                              hm_ocp_qp_ipm_vec *sol)
{
    int n, i;
    for (n = HM_N; n >= 0; n--) {
        hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        hm_real h[HM_QP_NUX];
        ocp_qp_kkt_condense(sn, &ws->u.f.bd, &ws->u.f.sr, &ws->u.f.gs, rhs, n, h);
        if (n < HM_N) {
            for (i = 0; i < HM_NX; i++) sn->ry[i] = rhs->y[n][i];
            ocp_qp_kkt_mv4(ws->u.f.st[n + 1].P, sn->ry, sn->Pry);
        }
        ocp_qp_kkt_backward_stage(qp, sn, n < HM_N ? &ws->u.f.st[n + 1] : sn, n, h);
    }
    for (i = 0; i < HM_NX; i++) sol->ux[0][HM_NU + i] = HM_R(0.0);
    for (n = 0; n < HM_N; n++) {
        hm_real u[HM_NU], xn[HM_NX], dy[HM_NX];
        ocp_qp_kkt_forward_stage(qp, &ws->u.f.st[n], &ws->u.f.st[n + 1], n, &sol->ux[n][HM_NU], u, xn, dy);
        sol->ux[n][0] = u[0];
        sol->ux[n][1] = u[1];
        for (i = 0; i < HM_NX; i++) {
            sol->ux[n + 1][HM_NU + i] = xn[i];
            sol->y[n][i] = dy[i];
        }
        ocp_qp_kkt_expand(&ws->u.f.st[n], &ws->u.f.bd, &ws->u.f.sr, &ws->u.f.gs, rhs, sol, n);
    }
    for (i = 0; i < HM_NU; i++) sol->ux[HM_N][i] = HM_R(0.0);
    ocp_qp_kkt_expand(&ws->u.f.st[HM_N], &ws->u.f.bd, &ws->u.f.sr, &ws->u.f.gs, rhs, sol, HM_N);
}
#endif /* HM_QP_POLISH */
