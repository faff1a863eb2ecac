/*
 * hm_types.h: every sized type of the runtime, instantiated once per solver.
 *
 * Deliberately without an include guard: a generated solver's public header includes this file
 * after defining
 *     HM_NS(x)   the type-name prefix, e.g. paper_##x (so two solvers' headers can meet in one file)
 *     HM_REAL    the real type (double or float)
 *     HM_N       number of shooting intervals (stages 0..HM_N)
 *     HM_NG      maximum number of general (distance) rows per stage
 * and undefines them afterwards. Inside the runtime the types are used through the short names of
 * hm_aliases.h. Sizes are compile-time constants: all memory of a solver is one struct that the
 * caller may place statically.
 *
 * Matrices are dense and column-major: M[i + j * rows] is row i, column j (CasADi's and BLAS'
 * order).
 */
#include "hm_common.h"

/* ------------------------------------------------------------------------------------------------
 * ocp_qp: the stage-structured QP solved at every SQP iteration.
 *
 *   minimise  sum_{n=0}^{N-1} [ 1/2 x_n' Q_n x_n + u_n' S_n x_n + 1/2 u_n' R_n u_n + q_n' x_n + r_n' u_n ]
 *             + 1/2 x_N' Q_N x_N + q_N' x_N
 *             + sum_{n=1}^{N} sum_{i<ng_n, soft} [ zl_{n,i} s_{n,i} + 1/2 Zl_{n,i} s_{n,i}^2 ]
 *   subject to
 *     x_0 = x0                                              (the initial state is fixed)
 *     x_{n+1} = A_n x_n + B_n u_n + b_n                     n = 0..N-1
 *     lbu_n <= u_n <= ubu_n                                 n = 0..N-1 (per component)
 *     lbx_n <= x_n <= ubx_n                                 n = 1..N   (per component)
 *     D_{n,i}' [x_n(0); x_n(1)] + s_{n,i} >= lg_{n,i}       n = 1..N, i < ng_n
 *     s_{n,i} >= 0                                          soft rows; s_{n,i} = 0 for hard rows
 *
 * A bound with magnitude >= HM_INF is absent. Rows i >= ng_n are absent and cost nothing: that is
 * how humans who are not present drop out. Row i is soft iff soft_{n,i} != 0. Stage-0 state bounds
 * and rows are ignored (x_0 is fixed).
 * ---------------------------------------------------------------------------------------------- */
typedef struct HM_NS(ocp_qp) {
    HM_REAL A[HM_N][HM_NX * HM_NX];
    HM_REAL B[HM_N][HM_NX * HM_NU];
    HM_REAL b[HM_N][HM_NX];
    HM_REAL Q[HM_N + 1][HM_NX * HM_NX];
    HM_REAL S[HM_N][HM_NU * HM_NX];
    HM_REAL R[HM_N][HM_NU * HM_NU];
    HM_REAL q[HM_N + 1][HM_NX];
    HM_REAL r[HM_N][HM_NU];
    HM_REAL x0[HM_NX];
    HM_REAL lbx[HM_N + 1][HM_NX];
    HM_REAL ubx[HM_N + 1][HM_NX];
    HM_REAL lbu[HM_N][HM_NU];
    HM_REAL ubu[HM_N][HM_NU];
    int ng[HM_N + 1];
    HM_REAL D[HM_N + 1][HM_NG][HM_NP];
    HM_REAL lg[HM_N + 1][HM_NG];
    int soft[HM_N + 1][HM_NG];
    HM_REAL zl[HM_N + 1][HM_NG];
    HM_REAL Zl[HM_N + 1][HM_NG];
} HM_NS(ocp_qp);

/* ocp_qp_sol: primal and dual solution of an ocp_qp (sign conventions in ocp_qp.h). */
typedef struct HM_NS(ocp_qp_sol) {
    HM_REAL x[HM_N + 1][HM_NX];
    HM_REAL u[HM_N][HM_NU];
    HM_REAL s[HM_N + 1][HM_NG];
    HM_REAL pi[HM_N][HM_NX];
    HM_REAL lam_lbx[HM_N + 1][HM_NX];
    HM_REAL lam_ubx[HM_N + 1][HM_NX];
    HM_REAL lam_lbu[HM_N][HM_NU];
    HM_REAL lam_ubu[HM_N][HM_NU];
    HM_REAL lam_lg[HM_N + 1][HM_NG];
    HM_REAL lam_ls[HM_N + 1][HM_NG];
} HM_NS(ocp_qp_sol);

/* ------------------------------------------------------------------------------------------------
 * ocp_qp_ipm: the interior-point solver of ocp_qp (ocp_qp_ipm.h, ocp_qp_kkt.h, ocp_qp.h).
 *
 * A primal-dual (infeasible-start, Mehrotra predictor-corrector) method. Its inequalities are kept
 * per stage in fixed-size blocks of three families, so that every loop has a compile-time bound or
 * visits only what is present:
 *   bound pairs   a component of (u, x) with a lower and/or an upper bound somewhere on the horizon:
 *                 one slot per such component for all stages, stored stage-major (ocp_qp_ipm_bounds)
 *                 so that the passes treat eight stages at once in vector lanes; a side absent at a
 *                 stage has sign 0 and a neutral state;
 *   soft rows     D' p + s >= lg with its slack s >= 0 (s is its own slack: no second slack);
 *   hard rows     D' p >= lg.
 * Rows are processed two at a time (2-wide SIMD where the compiler can); a stage with an odd count
 * pads its family with one neutral row (D = 0, state reset to 1, masked out of every sum).
 * The arrays below are sized HM_QP_NGP = HM_NG rounded up to even, written out since this file has
 * no include guard.
 * ---------------------------------------------------------------------------------------------- */

/* Residuals of a primal-dual pair (ocp_qp_res_compute), infinity norms in the units of the data. */
typedef struct HM_NS(ocp_qp_res) {
    HM_REAL stat;    /* gradient of the Lagrangian with respect to u, x and s */
    HM_REAL eq;      /* dynamics */
    HM_REAL ineq;    /* largest violation of a bound, a row (hard or with its slack) or of s >= 0 */
    HM_REAL comp;    /* largest |multiplier * constraint value| */
    HM_REAL dual;    /* largest violation of multiplier >= 0 */
    HM_REAL obj;     /* objective, including the constant terms of the fixed x_0 */
} HM_NS(ocp_qp_res);

/* Options of ocp_qp_ipm_solve; ocp_qp_ipm_arg_set_default gives working values. */
typedef struct HM_NS(ocp_qp_ipm_arg) {
    int max_iter;            /* interior-point iterations before HM_QP_MAX_ITER */
    HM_REAL tol;             /* on the scaled primal and dual residuals and the duality gap */
    HM_REAL tol_infeas;      /* certificate: no feasible point has ||(u, x, s)||_1 < 1 / tol_infeas */
    HM_REAL step_frac;       /* fraction of the step to the boundary that is taken */
    HM_REAL min_step;        /* a shorter step means no progress: HM_QP_NUMERICAL */
    int polish;              /* 1: refine a solution on its active set (ocp_qp_ipm.h) */
    int residuals;           /* 1: ws->out.res holds the KKT residuals of the returned solution; 0: a solved
                                QP's are left out (the polish still measures them) */
    int detect_unbounded;    /* 1: test stalling steps for a ray of unbounded descent (ocp_qp_ipm.h); 0 for
                                QPs bounded by construction */
    int recurrence;          /* 1: the residuals of the equations follow the steps by their recurrence between
                                exact evaluations (ocp_qp_ipm.c); 0: exact in every iteration, whose steps
                                then leave the residuals far below tol (a reference solve) */
    int (*should_stop)(void *ctx);   /* polled once per iteration; nonzero ends with HM_QP_TIMEOUT */
    void *stop_ctx;
    int warm_start;          /* 0: the cold start; from the iterate the last solve kept (ws->warm), where it
                                has the same inequality: 1 its stage n + 1 for stage n (the real-time
                                iteration's shift), 2 stage n for stage n (a re-solve) */
    HM_REAL warm_mu;         /* > 0: keep the first iterate after the start with mu <= warm_mu (scaled; the
                                cold start has mu = 1) for the next solve; 0: keep none */
} HM_NS(ocp_qp_ipm_arg);

/* Outcome of a solve, as both QP solvers report it (the interior-point solver hands over its
 * fallback's as its own). */
typedef struct HM_NS(ocp_qp_outcome) {
    int status;
    int iter;                         /* interior-point iterations done */
    HM_NS(ocp_qp_res) res;            /* residuals of the returned solution (ocp_qp_res_compute) */
    HM_REAL res_primal, res_dual, gap;   /* the scaled measures compared with arg->tol */
    HM_REAL mu;                       /* of the last iterate */
    int unbounded;                    /* NUMERICAL because a direction of unbounded descent was found */
    int polished;                     /* the solution is the active-set refinement of the iterate */
} HM_NS(ocp_qp_outcome);

/* One stage of the solver: its inequality families, its part of the iterate and of the direction,
 * and its part of the Newton system. Stage n carries (u_n, x_n) as one 6-vector ux (u first; u of
 * stage HM_N and x of stage 0 unused), and y_n, the multiplier of the dynamics from n to n + 1. */
typedef struct HM_NS(ocp_qp_ipm_stage) {
    /* structure, set up by every solve */
    int ns, nh;                       /* soft rows, hard rows */
    int soff;                         /* soft row j of the stage is row soff + j of ocp_qp_ipm_rows */
    int ns2, nh2;                     /* the same rounded up to even (rows go in pairs) */
    int a_id;                         /* 1: the first two columns of A_n are e_0, e_1 */
    int ab_int;                       /* 1: a_id, and rows 2 and 3 of [A_n B_n] are two integrators' (the
                                         robot's; ocp_qp_kkt.c: ocp_qp_kkt_factor_stage_integrators) */
    unsigned char hrow[(HM_NG + 1) / 2 * 2];   /* QP row of hard row j */
    /* cost times the cost scale (stage 0: x_0 terms folded into q), dynamics offset (stage 0:
     * b_0 + A_0 x_0); column-major like ocp_qp */
    HM_REAL R[HM_NU * HM_NU], S[HM_NU * HM_NX], Q[HM_NX * HM_NX], q[HM_NU + HM_NX], beq[HM_NX];

    /* hard rows: -d' p + t = -lg */
    HM_REAL hd0[(HM_NG + 1) / 2 * 2], hd1[(HM_NG + 1) / 2 * 2], hlg[(HM_NG + 1) / 2 * 2];
    HM_REAL hlive[(HM_NG + 1) / 2 * 2];
    HM_REAL ht[(HM_NG + 1) / 2 * 2], hz[(HM_NG + 1) / 2 * 2];
    HM_REAL hdt[(HM_NG + 1) / 2 * 2], hdz[(HM_NG + 1) / 2 * 2];
    HM_REAL hw[(HM_NG + 1) / 2 * 2], hti[(HM_NG + 1) / 2 * 2], hzi[(HM_NG + 1) / 2 * 2];
    HM_REAL hdel[(HM_NG + 1) / 2 * 2];

    /* iterate and step of the stage; ry: right-hand side of the dynamics n -> n + 1 in the Newton
     * system (minus their residual) */
    HM_REAL ux[HM_NU + HM_NX], y[HM_NX], dux[HM_NU + HM_NX], dy[HM_NX], ry[HM_NX];
    /* the stationarity residual P v + q + A' w of (u, x); it and ry follow the iterate by the
     * recurrence r <- (1 - alpha) r between exact evaluations (ocp_qp_ipm.c) */
    HM_REAL rv[HM_NU + HM_NX];
    /* Newton system: the families condensed into the stage (diagonal, (px, py) block), gradients of
     * the predictor and the two parts of the corrector's change, and the Riccati factor */
    HM_REAL Hd[HM_NU + HM_NX], Hpp[3];
    HM_REAL ha[HM_NU + HM_NX], hdl[HM_NU + HM_NX], hmu[HM_NU + HM_NX];
    HM_REAL P[HM_NX * HM_NX], p[HM_NX], Pry[HM_NX];
    HM_REAL Ld[3];                    /* LDL' of the input block: 1 / d0, l10, 1 / d1 */
    HM_REAL Kx[HM_NU * HM_NX];        /* L^-1 (input-state block), row j at Kx[j * HM_NX] */
    HM_REAL F[HM_NX * HM_NX];         /* closed-loop dynamics A - B G of the step's feedback u = -G x + .. */
    HM_REAL yk[HM_NU];
} HM_NS(ocp_qp_ipm_stage);

/* The bound pairs of all stages, stage-major: slot k (< nbp) is component bc[k] of (u, x), side 0
 * the lower and side 1 the upper bound, sign * ux[c] + t = b (sign -1 and b = -lb, sign +1 and
 * b = ub; an absent side has sign 0, b = 1 and stays at t = z = 1). The stages run to HM_N + 1
 * rounded up to a multiple of 8 (HM_QP_NNP of ocp_qp_kkt.h), those past HM_N absent on both sides. */
typedef struct HM_NS(ocp_qp_ipm_bounds) {
    int nbp;
    unsigned char bc[HM_NU + HM_NX];
    HM_REAL sg[HM_NU + HM_NX][2][(HM_N + 8) / 8 * 8];    /* sign */
    HM_REAL b[HM_NU + HM_NX][2][(HM_N + 8) / 8 * 8];
    HM_REAL t[HM_NU + HM_NX][2][(HM_N + 8) / 8 * 8];     /* slack */
    HM_REAL z[HM_NU + HM_NX][2][(HM_N + 8) / 8 * 8];     /* multiplier */
    HM_REAL dt[HM_NU + HM_NX][2][(HM_N + 8) / 8 * 8];    /* step */
    HM_REAL dz[HM_NU + HM_NX][2][(HM_N + 8) / 8 * 8];
    HM_REAL w[HM_NU + HM_NX][2][(HM_N + 8) / 8 * 8];     /* z / t, capped */
    HM_REAL ti[HM_NU + HM_NX][2][(HM_N + 8) / 8 * 8];    /* 1 / t */
    HM_REAL zi[HM_NU + HM_NX][2][(HM_N + 8) / 8 * 8];    /* 1 / z */
    HM_REAL rho[HM_NU + HM_NX][2][(HM_N + 8) / 8 * 8];   /* predictor right-hand side */
    HM_REAL del[HM_NU + HM_NX][2][(HM_N + 8) / 8 * 8];   /* predictor dt dz */
    /* per slot and stage: ux[c] of the iterate and of the step (pass C's predictor step until pass
     * E writes the corrector's); the pair's parts of the Newton diagonal and of the gradients ha,
     * hmu and hdl */
    HM_REAL v[HM_NU + HM_NX][(HM_N + 8) / 8 * 8];
    HM_REAL dv[HM_NU + HM_NX][(HM_N + 8) / 8 * 8];
    HM_REAL Hd[HM_NU + HM_NX][(HM_N + 8) / 8 * 8];
    HM_REAL hf[HM_NU + HM_NX][(HM_N + 8) / 8 * 8];
    HM_REAL hmu[HM_NU + HM_NX][(HM_N + 8) / 8 * 8];
    HM_REAL hdl[HM_NU + HM_NX][(HM_N + 8) / 8 * 8];
} HM_NS(ocp_qp_ipm_bounds);

/* The soft rows of all stages in one list: stage after stage, each stage's ns rows padded to an even
 * count (ns2, the padding row absent), the list padded to a multiple of 8 with absent rows (live 0,
 * d = 0, at the neutral state s = t = z = zs = 1; HM_QP_NR of ocp_qp_kkt.h). Row r of stage n:
 * -(d' p + s) + t = -lg, s >= 0, cost zl s + Zl s^2 / 2 (times the cost scale). The passes of the
 * interior-point method run over the list eight rows at a time, with d' p and d' dp of each row's
 * stage in gp and gd. sdr, sdsb (from pass C to pass E) and se (the general solve's) are free in
 * pass A, which keeps its per-row terms there until the stages have summed them (ocp_qp_ipm.c). */
/* one value per row of the list */
typedef HM_REAL HM_NS(ocp_qp_ipm_row_vec)[((HM_N + 1) * ((HM_NG + 1) / 2 * 2) + 7) / 8 * 8];
typedef struct HM_NS(ocp_qp_ipm_rows) {
    int nr;                           /* rows in the list, padding rows of the stages included */
    unsigned char srow[((HM_N + 1) * ((HM_NG + 1) / 2 * 2) + 7) / 8 * 8];   /* QP row within its stage */
    HM_NS(ocp_qp_ipm_row_vec) sd0, sd1, slg, szl, sZl, slive;
    HM_NS(ocp_qp_ipm_row_vec) ss, st;        /* slack s, row slack t */
    HM_NS(ocp_qp_ipm_row_vec) sz, szs;       /* multipliers of the row, of s >= 0 */
    HM_NS(ocp_qp_ipm_row_vec) sds, sdt, sdz, sdzs;
    HM_NS(ocp_qp_ipm_row_vec) swr, sws;      /* weights z/t, zs/s */
    HM_NS(ocp_qp_ipm_row_vec) shi;           /* 1 / (Zl + wr + ws) */
    HM_NS(ocp_qp_ipm_row_vec) sti, szi;      /* 1/t, 1/z */
    HM_NS(ocp_qp_ipm_row_vec) ssi, szsi;     /* 1/s, 1/zs */
    HM_NS(ocp_qp_ipm_row_vec) srs;           /* stationarity residual of s */
    HM_NS(ocp_qp_ipm_row_vec) sdr, sdsb;     /* dt dz, ds dzs of the predictor */
    HM_NS(ocp_qp_ipm_row_vec) se;            /* general solve: slack step at a zero position step */
    HM_NS(ocp_qp_ipm_row_vec) gp, gd;        /* d' p at the iterate's position, d' dp at the step's */
} HM_NS(ocp_qp_ipm_rows);

/* A vector in the solver's layout (the Newton system's unknowns or right-hand side), used by the
 * general solve of ocp_qp_kkt.h (tests, polish): per stage ux, the soft slacks by soft row, y, and
 * one entry per inequality: bound lanes, soft rows, their s >= 0, hard rows. */
typedef struct HM_NS(ocp_qp_ipm_vec) {
    HM_REAL ux[HM_N + 1][HM_NU + HM_NX];
    HM_REAL s[HM_N + 1][(HM_NG + 1) / 2 * 2];
    HM_REAL y[HM_N][HM_NX];
    HM_REAL zb[HM_N + 1][HM_NU + HM_NX][2];
    HM_REAL zr[HM_N + 1][(HM_NG + 1) / 2 * 2];
    HM_REAL zs[HM_N + 1][(HM_NG + 1) / 2 * 2];
    HM_REAL zh[HM_N + 1][(HM_NG + 1) / 2 * 2];
} HM_NS(ocp_qp_ipm_vec);

/* The variables of the embedding that live in the QP's shape: per stage (u, x) (u of stage HM_N and
 * x of stage 0 unused), slacks s[n][k] of the k-th general row if it is soft, multipliers y of the
 * dynamics and z of the packed inequality rows. Used for the iterate, the step, the residuals and a
 * constant solve. */
typedef struct HM_NS(ocp_qp_hsde_vec) {
    HM_REAL ux[HM_N + 1][HM_NU + HM_NX];
    HM_REAL s[HM_N + 1][HM_NG];
    HM_REAL y[HM_N][HM_NX];
    HM_REAL z[(HM_N + 1) * (2 * (HM_NU + HM_NX) + 2 * HM_NG)];
} HM_NS(ocp_qp_hsde_vec);

/* The fallback solver (ocp_qp_hsde.h): inequality rows (present bounds, general rows, s >= 0 of
 * soft rows) packed stage after stage into flat arrays. */
typedef struct HM_NS(ocp_qp_hsde_ws) {
    HM_NS(ocp_qp_outcome) out;        /* of the last solve */
    HM_REAL tau, kappa;               /* of the last iterate */

    /* packed inequality rows of stage n from off[n]: nb[n] bounds, nr[n] general rows, ns[n] rows
     * s >= 0 of the soft ones among them; m rows in all */
    int m;
    int off[HM_N + 1];
    int nb[HM_N + 1];
    int nr[HM_N + 1];
    int ns[HM_N + 1];
    unsigned char box_comp[HM_N + 1][2 * (HM_NU + HM_NX)];   /* component of (u, x) */
    HM_REAL box_sign[HM_N + 1][2 * (HM_NU + HM_NX)];          /* +1 upper bound, -1 lower bound */
    unsigned char row_idx[HM_N + 1][HM_NG];   /* QP row i of the k-th general row */
    unsigned char soft_of[HM_N + 1][HM_NG];   /* k of the j-th soft row */
    HM_REAL D[HM_N + 1][HM_NG][HM_NP];        /* D of the k-th general row */
    HM_REAL soft_Zl[HM_N + 1][HM_NG];         /* Zl of the j-th soft row, times cost_scale */
    /* the data of the embedding: cost gradient q and right-hand sides b (dynamics, inequality rows),
     * with the terms of the fixed x_0 moved into stage 0 */
    HM_REAL q_ux[HM_N + 1][HM_NU + HM_NX];
    HM_REAL q_s[HM_N + 1][HM_NG];
    HM_REAL b_eq[HM_N][HM_NX];
    HM_REAL b_ineq[(HM_N + 1) * (2 * (HM_NU + HM_NX) + 2 * HM_NG)];
    HM_REAL norm_q, norm_b;
    HM_REAL cost_scale;               /* the cost is solved scaled by this */
    HM_REAL w_max;                    /* cap of the row weights */

    /* iterate (v, t, tau, kappa), step, constant solve, residuals */
    HM_NS(ocp_qp_hsde_vec) v, dv, v1, rv;
    HM_REAL t[(HM_N + 1) * (2 * (HM_NU + HM_NX) + 2 * HM_NG)];
    HM_REAL dt[(HM_N + 1) * (2 * (HM_NU + HM_NX) + 2 * HM_NG)];
    HM_REAL dtau, dkappa, rtau;
    HM_REAL c_ux[HM_N + 1][HM_NU + HM_NX];   /* q + 2 P v / tau, the tau row of the Newton system */
    HM_REAL c_s[HM_N + 1][HM_NG];
    HM_REAL ds[(HM_N + 1) * (2 * (HM_NU + HM_NX) + 2 * HM_NG)];   /* complementarity target */
    HM_REAL zinv[(HM_N + 1) * (2 * (HM_NU + HM_NX) + 2 * HM_NG)];   /* 1 / z */
    HM_REAL winv[(HM_N + 1) * (2 * (HM_NU + HM_NX) + 2 * HM_NG)];   /* 1 / w */

    /* Newton system: row weights z / t, stage-wise eliminated soft slacks, Riccati */
    HM_REAL w[(HM_N + 1) * (2 * (HM_NU + HM_NX) + 2 * HM_NG)];
    HM_REAL soft_hinv[HM_N + 1][HM_NG];     /* of the j-th soft row: 1 / (Zl + w_row + w_slack) */
    HM_REAL soft_e[HM_N + 1][HM_NG];        /* per solve: its slack step at a zero position step */
    HM_REAL P[HM_N + 1][HM_NX * HM_NX];     /* cost-to-go Hessians */
    HM_REAL p[HM_N + 1][HM_NX];             /* cost-to-go gradients, per solve */
    HM_REAL Lr[HM_N][3];                    /* Cholesky factor of the reduced input Hessian:
                                               1 / l00, l10, 1 / l11 */
    HM_REAL Y[HM_N][HM_NU * HM_NX];         /* Lr^-1 (S + B' P A) */
    HM_REAL yk[HM_N][HM_NU];                /* per solve: Lr^-1 (reduced input gradient) */
} HM_NS(ocp_qp_hsde_ws);

/* An iterate kept by a solve for the next one's start (arg->warm_start, warm_mu): its slacks and
 * multipliers (unscaled) by stage and (u, x) component or QP row, so that the next QP may have
 * other bounds and rows. */
typedef struct HM_NS(ocp_qp_ipm_warm) {
    int ready;                                   /* 1: the last solve kept one */
    HM_REAL bt[HM_N + 1][HM_NU + HM_NX][2];      /* bound sides (lower, upper): slack, 0 if absent */
    HM_REAL bz[HM_N + 1][HM_NU + HM_NX][2];      /* and multiplier */
    HM_REAL rt[HM_N + 1][HM_NG], rz[HM_N + 1][HM_NG];     /* rows: slack, multiplier */
    HM_REAL rs[HM_N + 1][HM_NG], rzs[HM_N + 1][HM_NG];    /* soft rows: s, multiplier of s >= 0 */
    unsigned char kind[HM_N + 1][HM_NG];         /* 0 absent, 1 soft, 2 hard */
} HM_NS(ocp_qp_ipm_warm);

/* All memory of a solve. Only the first block is meant for the caller. */
typedef struct HM_NS(ocp_qp_ipm_ws) {
    HM_NS(ocp_qp_outcome) out;        /* of the last solve */
    HM_NS(ocp_qp_ipm_warm) warm;      /* kept for the next solve (outside the fallback's memory) */

    /* the problem as the solver sees it, and its iterate */
    int m;                            /* inequalities (present bound sides, rows, s >= 0) */
    HM_REAL cost_scale;               /* the cost is solved scaled by this (ocp_qp_ipm.c) */
    HM_REAL w_max;                    /* cap of the weights z / t (ocp_qp_ipm.c) */
    HM_REAL norm_q, norm_b;
    int fallback;                     /* the solution came from the fallback solver (ocp_qp_hsde.h) */
    /* the stages, and two vectors for the polish and the general solve; or the fallback's memory */
    union {
        struct {
            HM_NS(ocp_qp_ipm_stage) st[HM_N + 1];
            HM_NS(ocp_qp_ipm_bounds) bd;
            HM_NS(ocp_qp_ipm_rows) sr;
            HM_NS(ocp_qp_ipm_vec) va, vb;
        } f;
        HM_NS(ocp_qp_hsde_ws) hsde;
    } u;
} HM_NS(ocp_qp_ipm_ws);
