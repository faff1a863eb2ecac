/*
 * ocp_qp_ipm_types.h: the sized types of the interior-point solver: one stage's blocks, the bound
 * pairs and the soft-row list of all stages, a vector in its layout, the iterate kept for the warm
 * start, and the workspace that holds them (or, in a union, the fallback's: ocp_qp_hsde_types.h).
 * Set up by every solve; only the warm start outlives one.
 * No include guard: instantiated once per solver under the HM_NS / HM_REAL / HM_N / HM_NG contract of
 * hm_types.h, which includes it.
 */
#include "hm_common.h"

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
 * The arrays below are sized by what a QP of this solver can have, written out since this file has no
 * include guard (ocp_qp_kkt.h gives the code's names of the same sizes, ocp_qp_ipm_common.h checks
 * that they agree):
 *   HM_NBP   components of (u, x) that may be bounded (bound-pair slots); the QP layer's default is
 *            all six, a generated solver's the OCP's three (HM_OCP_NBP: a, omega, v);
 *   HM_NGH   hard rows a stage may have; default HM_NG, a generated solver's none (HM_OCP_NGH: every
 *            distance row of the OCP is soft), which leaves one padding pair per stage;
 *   HM_QP_POLISH  when defined, the active-set polish and the general solve of the Newton system
 *            (ocp_qp_kkt.h) with their per-row weights and two vectors (the tests' QP builds); a
 *            generated solver never polishes and leaves them out.
 * A QP beyond these sizes is refused by the setup (HM_QP_NONFINITE: sizes out of range).
 * ---------------------------------------------------------------------------------------------- */
#ifdef HM_NBP
#define HM_TYPES_NBP_ (HM_NBP)
#else
#define HM_TYPES_NBP_ (HM_NU + HM_NX)
#endif
#ifdef HM_NGH
#define HM_TYPES_NGHP_ (((HM_NGH) + 1) / 2 * 2 + ((HM_NGH) == 0) * 2)
#define HM_TYPES_NHB_ ((HM_NGH) > 0 ? HM_N + 1 : 1)
#else
#define HM_TYPES_NGHP_ ((HM_NG + 1) / 2 * 2)
#define HM_TYPES_NHB_ (HM_N + 1)
#endif
#define HM_TYPES_NNP_ ((HM_N + 8) / 8 * 8)
#ifdef HM_NRC
#define HM_TYPES_NRC_ (HM_NRC)
#else
#define HM_TYPES_NRC_ ((HM_N + 1) * HM_NG)
#endif
#define HM_TYPES_MIN_(a, b) ((a) < (b) ? (a) : (b))
#define HM_TYPES_NR_                                                                                      \
    ((HM_TYPES_MIN_((HM_N + 1) * ((HM_NG + 1) / 2 * 2), HM_TYPES_NRC_ + HM_TYPES_MIN_(HM_TYPES_NRC_, HM_N + 1)) \
      + 7) / 8 * 8)


/* The hard rows of a stage: -d' p + t = -lg, in pairs (an odd count padded with a neutral row, live 0).
 * Kept apart from the stage so that a solver without hard rows (HM_NGH 0: every generated one) has
 * one block for all stages (HM_TYPES_NHB_), which no stage writes, instead of a pair of slots in each. */
typedef struct HM_NS(ocp_qp_ipm_hard) {
    unsigned char hrow[HM_TYPES_NGHP_];          /* QP row of hard row j */
    HM_REAL hd0[HM_TYPES_NGHP_], hd1[HM_TYPES_NGHP_], hlg[HM_TYPES_NGHP_];
    HM_REAL hlive[HM_TYPES_NGHP_];
    HM_REAL ht[HM_TYPES_NGHP_], hz[HM_TYPES_NGHP_];
    HM_REAL hdt[HM_TYPES_NGHP_], hdz[HM_TYPES_NGHP_];
    HM_REAL hw[HM_TYPES_NGHP_], hti[HM_TYPES_NGHP_], hzi[HM_TYPES_NGHP_];
    HM_REAL hdel[HM_TYPES_NGHP_];
} HM_NS(ocp_qp_ipm_hard);

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
    HM_NS(ocp_qp_ipm_hard) *hr;       /* its hard rows (ocp_qp_ipm_hard; set up by every solve) */
    /* cost gradient times the cost scale (stage 0: x_0 terms folded in), dynamics offset (stage 0:
     * b_0 + A_0 x_0). The Hessian blocks R, S, Q are not copied: the kernels read the QP's times the
     * cost scale (ocp_qp_kkt_factor_stage, ocp_qp_ipm_hess_mul) */
    HM_REAL q[HM_NU + HM_NX], beq[HM_NX];

    /* iterate and step of the stage; ry: right-hand side of the dynamics n -> n + 1 in the Newton
     * system (minus their residual) */
    HM_REAL ux[HM_NU + HM_NX], y[HM_NX], dux[HM_NU + HM_NX], dy[HM_NX], ry[HM_NX];
    /* the stationarity residual P v + q + A' w of (u, x); it and ry follow the iterate by the
     * recurrence r <- (1 - alpha) r between exact evaluations (ocp_qp_ipm_pass_a.c) */
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
    unsigned char bc[HM_TYPES_NBP_];
    HM_REAL sg[HM_TYPES_NBP_][2][HM_TYPES_NNP_];    /* sign */
    HM_REAL b[HM_TYPES_NBP_][2][HM_TYPES_NNP_];
    HM_REAL t[HM_TYPES_NBP_][2][HM_TYPES_NNP_];     /* slack */
    HM_REAL z[HM_TYPES_NBP_][2][HM_TYPES_NNP_];     /* multiplier */
    HM_REAL dt[HM_TYPES_NBP_][2][HM_TYPES_NNP_];    /* step */
    HM_REAL dz[HM_TYPES_NBP_][2][HM_TYPES_NNP_];
    HM_REAL w[HM_TYPES_NBP_][2][HM_TYPES_NNP_];     /* z / t, capped */
    HM_REAL ti[HM_TYPES_NBP_][2][HM_TYPES_NNP_];    /* 1 / t */
    HM_REAL zi[HM_TYPES_NBP_][2][HM_TYPES_NNP_];    /* 1 / z */
    HM_REAL rho[HM_TYPES_NBP_][2][HM_TYPES_NNP_];   /* predictor right-hand side */
    HM_REAL del[HM_TYPES_NBP_][2][HM_TYPES_NNP_];   /* predictor dt dz */
    /* per slot and stage: ux[c] of the iterate and of the step (pass C's predictor step until pass
     * E writes the corrector's); the pair's parts of the Newton diagonal and of the gradients ha,
     * hmu and hdl */
    HM_REAL v[HM_TYPES_NBP_][HM_TYPES_NNP_];
    HM_REAL dv[HM_TYPES_NBP_][HM_TYPES_NNP_];
    HM_REAL Hd[HM_TYPES_NBP_][HM_TYPES_NNP_];
    HM_REAL hf[HM_TYPES_NBP_][HM_TYPES_NNP_];
    HM_REAL hmu[HM_TYPES_NBP_][HM_TYPES_NNP_];
    HM_REAL hdl[HM_TYPES_NBP_][HM_TYPES_NNP_];
} HM_NS(ocp_qp_ipm_bounds);

/* The soft rows of all stages in one list: stage after stage, each stage's ns rows padded to an even
 * count (ns2, the padding row absent), the list padded to a multiple of 8 with absent rows (live 0,
 * d = 0, at the neutral state s = t = z = zs = 1; HM_QP_NR of ocp_qp_kkt.h). Row r of stage n:
 * -(d' p + s) + t = -lg, s >= 0, cost zl s + Zl s^2 / 2 (times the cost scale). The passes of the
 * interior-point method run over the list eight rows at a time, with d' p and d' dp of each row's
 * stage in gp and gd. What a pass derives from the iterate (the weights z / t, the inverses, the
 * slack's stationarity residual) is not kept: passes C and E derive it again from the same numbers by
 * the same expressions, which gives the same values for a few operations per present row (and the
 * list only holds present rows). sdr, sdsb (from pass C to pass E) are free in pass A, which keeps
 * its per-row terms there and in se until the stages have summed them (ocp_qp_ipm_pass_a.c). */
/* one value per row of the list */
typedef HM_REAL HM_NS(ocp_qp_ipm_row_vec)[HM_TYPES_NR_];
typedef struct HM_NS(ocp_qp_ipm_rows) {
    int nr;                           /* rows in the list, padding rows of the stages included */
    unsigned char srow[HM_TYPES_NR_];   /* QP row within its stage */
    HM_NS(ocp_qp_ipm_row_vec) sd0, sd1, slg, szl, sZl, slive;
    HM_NS(ocp_qp_ipm_row_vec) ss, st;        /* slack s, row slack t */
    HM_NS(ocp_qp_ipm_row_vec) sz, szs;       /* multipliers of the row, of s >= 0 */
    HM_NS(ocp_qp_ipm_row_vec) sds, sdt, sdz, sdzs;
    HM_NS(ocp_qp_ipm_row_vec) sdr, sdsb;     /* dt dz, ds dzs of the predictor */
    HM_NS(ocp_qp_ipm_row_vec) se;            /* pass A's and C's per-row terms of the stage gradients */
    HM_NS(ocp_qp_ipm_row_vec) gp, gd;        /* d' p at the iterate's position, d' dp at the step's */
} HM_NS(ocp_qp_ipm_rows);

#ifdef HM_QP_POLISH
/* A vector in the solver's layout (the Newton system's unknowns or right-hand side), used by the
 * general solve of ocp_qp_kkt.h (tests, polish): per stage ux, the soft slacks by soft row, y, and
 * one entry per inequality: bound lanes, soft rows, their s >= 0, hard rows. */
typedef struct HM_NS(ocp_qp_ipm_vec) {
    HM_REAL ux[HM_N + 1][HM_NU + HM_NX];
    HM_REAL s[HM_N + 1][(HM_NG + 1) / 2 * 2];
    HM_REAL y[HM_N][HM_NX];
    HM_REAL zb[HM_N + 1][HM_TYPES_NBP_][2];
    HM_REAL zr[HM_N + 1][(HM_NG + 1) / 2 * 2];
    HM_REAL zs[HM_N + 1][(HM_NG + 1) / 2 * 2];
    HM_REAL zh[HM_N + 1][HM_TYPES_NGHP_];
} HM_NS(ocp_qp_ipm_vec);

/* The general solve's weights of the soft rows (the bound sides' and the hard rows' are their
 * families' w and hw), the slack steps of its condensation, and the polish's two vectors. */
typedef struct HM_NS(ocp_qp_ipm_general) {
    HM_NS(ocp_qp_ipm_row_vec) swr, sws;      /* weights of the row and of s >= 0 */
    HM_NS(ocp_qp_ipm_row_vec) shi;           /* 1 / (Zl + wr + ws) */
    HM_NS(ocp_qp_ipm_row_vec) se;            /* slack step at a zero position step */
    HM_NS(ocp_qp_ipm_vec) va, vb;
} HM_NS(ocp_qp_ipm_general);
#endif

/* An iterate kept by a solve for the next one's start (arg->warm_start, warm_mu): its slacks and
 * multipliers (unscaled) by stage and bound slot (whose components bc are kept too) or QP row, so
 * that the next QP may have other bounds and rows. The rows are kept as the solve held them: the soft
 * rows of stage n at soff[n] .. soff[n] + ns[n] - 1 of a list without padding, its hard rows in its
 * slots, each with its QP row (ascending within a stage, as the setup lists them). */
typedef struct HM_NS(ocp_qp_ipm_warm) {
    int ready;                                   /* 1: the last solve kept one */
    int nbp;                                     /* bound slots of the kept iterate, and their components */
    unsigned char bc[HM_TYPES_NBP_];
    HM_REAL bt[HM_N + 1][HM_TYPES_NBP_][2];      /* bound sides (lower, upper): slack, 0 if absent */
    HM_REAL bz[HM_N + 1][HM_TYPES_NBP_][2];      /* and multiplier */
    int soff[HM_N + 1], ns[HM_N + 1], nh[HM_N + 1];
    unsigned char srow[HM_TYPES_NRC_];           /* soft rows: QP row, */
    HM_REAL st[HM_TYPES_NRC_], sz[HM_TYPES_NRC_];       /* row slack and multiplier, */
    HM_REAL ss[HM_TYPES_NRC_], szs[HM_TYPES_NRC_];      /* s and the multiplier of s >= 0 */
    unsigned char hrow[HM_TYPES_NHB_][HM_TYPES_NGHP_];  /* hard rows (by stage, as ocp_qp_ipm_hard): QP row, */
    HM_REAL ht[HM_TYPES_NHB_][HM_TYPES_NGHP_], hz[HM_TYPES_NHB_][HM_TYPES_NGHP_];   /* slack and multiplier */
} HM_NS(ocp_qp_ipm_warm);

/* All memory of a solve. Only the first block is meant for the caller. */
typedef struct HM_NS(ocp_qp_ipm_ws) {
    HM_NS(ocp_qp_outcome) out;        /* of the last solve */
    HM_NS(ocp_qp_ipm_warm) warm;      /* kept for the next solve (outside the fallback's memory) */

    /* the problem as the solver sees it, and its iterate */
    int m;                            /* inequalities (present bound sides, rows, s >= 0) */
    HM_REAL cost_scale;               /* the cost is solved scaled by this (ocp_qp_ipm_setup.c) */
    HM_REAL w_max;                    /* cap of the weights z / t (ocp_qp_ipm_setup.c) */
    HM_REAL norm_q, norm_b;
    int fallback;                     /* the solution came from the fallback solver (ocp_qp_hsde.h) */
    /* the stages and the families (and, with the polish, the general solve's memory); or the
     * fallback's memory: the fallback starts from scratch, after the interior-point iteration; or,
     * between solves, scratch for the caller */
    union {
        struct {
            HM_NS(ocp_qp_ipm_stage) st[HM_N + 1];
            HM_NS(ocp_qp_ipm_hard) hd[HM_TYPES_NHB_];   /* stage n's at n (or all at 0: HM_QP_NHB) */
            HM_NS(ocp_qp_ipm_bounds) bd;
            HM_NS(ocp_qp_ipm_rows) sr;
#ifdef HM_QP_POLISH
            HM_NS(ocp_qp_ipm_general) gs;
#endif
        } f;
        HM_NS(ocp_qp_hsde_ws) hsde;
        /* free between solves (a solve sets up all it reads here; only warm outlives one): the NLP's row
         * capacity keeps the margins of a QP's rows here while it picks them (ocp_nlp_screen.c). At most
         * HM_N HM_NG reals, below the size of the union but for the largest sizes */
        HM_REAL scratch[HM_N * HM_NG];
    } u;
} HM_NS(ocp_qp_ipm_ws);

#undef HM_TYPES_NBP_
#undef HM_TYPES_NGHP_
#undef HM_TYPES_NHB_
#undef HM_TYPES_NNP_
#undef HM_TYPES_NRC_
#undef HM_TYPES_MIN_
#undef HM_TYPES_NR_
