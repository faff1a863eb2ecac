/*
 * ocp_qp_kkt.h: the Newton system of the interior-point method, solved by a Riccati recursion.
 *
 * With v = (u_0, x_1, s_1, u_1, ..., x_N, s_N) the primal variables, P the QP Hessian (times the
 * cost scale), A_E v = b_E the dynamics (rows x_{n+1} - A_n x_n - B_n u_n), A_I v + t = b_I the
 * inequalities (t >= 0; the families of ocp_qp_ipm_types.h: bound sides, soft rows
 * -(D' p + s) + t = -lg, their s >= 0 as -s + t = 0, hard rows -D' p + t = -lg) and w > 0 one weight
 * per inequality (z / t in the interior-point method), the system is
 *
 *     [ P    A_E'  A_I'         ] [dv ]   [rhs.ux, rhs.s]
 *     [ A_E  0     0            ] [dy ] = [rhs.y        ]
 *     [ A_I  0     -diag(1 / w) ] [dz ]   [rhs.z        ].
 *
 * dz is eliminated inequality by inequality and the soft slacks row by row; what is left is an
 * equality-constrained QP over the stages, solved by a backward Riccati recursion and a forward
 * substitution. Inequalities enter the (u, x) Hessian of their stage as a diagonal term (bounds) or
 * as a scalar times d d' on the (px, py) block (rows): ws->st[n].Hd and .Hpp. The factorisation
 * depends on the weights only; one factorisation serves any number of right-hand sides.
 *
 * The stage kernels (ocp_qp_kkt_factor_stage, _backward_stage, _forward_stage) are what the
 * interior-point iteration runs, fused with its own passes (ocp_qp_ipm_pred_corr.c).
 * ocp_qp_kkt_condense_weights, ocp_qp_kkt_factorize and ocp_qp_kkt_solve are the same system for a
 * general right-hand side in the layout of ocp_qp_ipm_vec, with the weights taken from the stage
 * blocks (bw, swr, sws, hw): the tests compare them with a dense solve, and the active-set polish
 * uses them.
 */
#ifndef OCP_QP_KKT_H
#define OCP_QP_KKT_H

#include "hm_common.h"

#define HM_QP_NUX (HM_NU + HM_NX)
/* stages rounded up to a multiple of 8: the bound pairs are processed eight stages at a time */
#define HM_QP_NNP ((HM_N + 8) / 8 * 8)
/* rows per stage rounded up to even: rows are processed in pairs */
#define HM_QP_NGP ((HM_NG + 1) / 2 * 2)
/* soft rows a QP may hold in all stages together: the solver's HM_NRC (a generated solver's
 * solver.qp_rows), by default every row of every stage; a QP with more is refused by the setups */
#ifdef HM_NRC
#define HM_QP_NRC (HM_NRC)
#else
#define HM_QP_NRC ((HM_N + 1) * HM_NG)
#endif
#define HM_QP_MIN_(a, b) ((a) < (b) ? (a) : (b))
/* the soft rows' list: the rows of all stages, each stage padded to even (a padding row for a stage
 * with an odd count, so at most HM_N + 1 of them), the list to a multiple of 8 */
#define HM_QP_NR ((HM_QP_MIN_((HM_N + 1) * HM_QP_NGP, HM_QP_NRC + HM_QP_MIN_(HM_QP_NRC, HM_N + 1)) + 7) / 8 * 8)
/* components of (u, x) that may be bounded (bound-pair slots) and hard rows a stage may have: the
 * solver's HM_NBP and HM_NGH, by default all (ocp_qp_ipm_types.h); hard-row slots per stage, rounded
 * up to even and at least one pair */
#ifdef HM_NBP
#define HM_QP_NBP (HM_NBP)
#else
#define HM_QP_NBP HM_QP_NUX
#endif
#ifdef HM_NGH
#define HM_QP_NGH (HM_NGH)
#else
#define HM_QP_NGH HM_NG
#endif
#define HM_QP_NGHP ((HM_QP_NGH + 1) / 2 * 2 + (HM_QP_NGH == 0) * 2)
/* Hard-row blocks (ocp_qp_ipm_hard): one a stage, or one for all if no stage may have hard rows; the
 * block of stage n */
#define HM_QP_NHB (HM_QP_NGH > 0 ? HM_N + 1 : 1)
#define HM_QP_HB(n) (HM_QP_NGH > 0 ? (n) : 0)

/* The 2x2 input block and the (px, py) rows are written out for these sizes. */
typedef char ocp_qp_kkt_sizes_fixed[(HM_NU == 2 && HM_NX == 4 && HM_NPOS == 2 && HM_NG <= 255) ? 1 : -1];

/* Stage n of the factorisation: the stage matrix (the QP's cost Hessian times the cost scale c,
 * sn->Hd, sn->Hpp and, for n < HM_N, the cost-to-go sn1->P of stage n + 1) and its partial LDL' over
 * the inputs: sn->Ld, sn->Kx and, for n > 0, the cost-to-go Hessian sn->P and (n < HM_N) the
 * closed-loop matrix sn->F of the solves. 0, or HM_QP_NUMERICAL if a pivot of the input block is
 * not safely positive (the QP is not strictly convex in u along the current active set, or the
 * weights have overflowed). sn1 is unused for n = HM_N. Also sets sn->Pry = sn1->P sn->ry
 * (n < HM_N), the term of the dynamics' right-hand side that every solve with this factorisation
 * shares. */
HM_FUNC int ocp_qp_kkt_factor_stage(const hm_ocp_qp *qp, hm_ocp_qp_ipm_stage *sn,
                                    const hm_ocp_qp_ipm_stage *sn1, int n, hm_real c);

/* Stage n of the backward substitution for the stage gradient h (6 entries, of the condensed QP):
 * sn->yk and, for n > 0, sn->p, from sn1->p (and sn->Pry). */
HM_FUNC void ocp_qp_kkt_backward_stage(const hm_ocp_qp *qp, hm_ocp_qp_ipm_stage *sn,
                                       const hm_ocp_qp_ipm_stage *sn1, int n, const hm_real *h);

/* Stage n < HM_N of the forward substitution: from the state step x (zero for n = 0) the input
 * step u, the next state step xn = A x + B u + sn->ry and, unless dy is NULL (the interior-point
 * predictor needs no multiplier step), the multiplier step dy of the dynamics. */
HM_FUNC void ocp_qp_kkt_forward_stage(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_stage *sn,
                                      const hm_ocp_qp_ipm_stage *sn1, int n, const hm_real *x, hm_real *u,
                                      hm_real *xn, hm_real *dy);

#ifdef HM_QP_POLISH
/* General system (built with HM_QP_POLISH). ocp_qp_kkt_condense_weights: sn->Hd, sn->Hpp and the soft
 * rows' 1 / (Zl + wr + ws) from the weights in the bound pairs (w), the general solve's soft-row
 * weights (ws->u.f.gs) and the hard rows (hw). ocp_qp_kkt_factorize: all stages. 0 or HM_QP_NUMERICAL. */
HM_FUNC void ocp_qp_kkt_condense_weights(hm_ocp_qp_ipm_ws *ws);
HM_FUNC int ocp_qp_kkt_factorize(const hm_ocp_qp *qp, hm_ocp_qp_ipm_ws *ws);

/* Solve with the last factorisation (of ocp_qp_kkt_factorize); sol may be rhs. Uses the stage
 * blocks' ry, p, yk as scratch. */
HM_FUNC void ocp_qp_kkt_solve(const hm_ocp_qp *qp, hm_ocp_qp_ipm_ws *ws, const hm_ocp_qp_ipm_vec *rhs,
                              hm_ocp_qp_ipm_vec *sol);
#endif

/* 4x4 kernels of the recursion that the fallback solver and the interior-point method use too, inline
 * as in the recursion. F = P M for the symmetric 4x4 P (stored in full) and the 4 x ncol matrix M,
 * in axpy form. */
HM_KERNEL void ocp_qp_kkt_mul4(const hm_real *restrict P, const hm_real *restrict M, hm_real *restrict F, int ncol)
{
    int i, j, k;
    for (j = 0; j < ncol; j++) {
        hm_real f[HM_NX];
        for (i = 0; i < HM_NX; i++) f[i] = P[i] * M[j * HM_NX];
        for (k = 1; k < HM_NX; k++) {
            const hm_real mk = M[k + j * HM_NX];
            for (i = 0; i < HM_NX; i++) f[i] += P[i + k * HM_NX] * mk;
        }
        for (i = 0; i < HM_NX; i++) F[i + j * HM_NX] = f[i];
    }
}

HM_KERNEL hm_real ocp_qp_kkt_dot4(const hm_real *restrict a, const hm_real *restrict b)
{
    return (a[0] * b[0] + a[1] * b[1]) + (a[2] * b[2] + a[3] * b[3]);
}

#endif /* OCP_QP_KKT_H */
