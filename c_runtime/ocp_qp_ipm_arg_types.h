/*
 * ocp_qp_ipm_arg_types.h: the sized types that both QP solvers share: the options of a solve
 * (ocp_qp_ipm_arg, set by the caller and read by every solve) and the outcome of a solve
 * (ocp_qp_outcome, written by it).
 * No include guard: instantiated once per solver under the HM_NS / HM_REAL / HM_N / HM_NG contract of
 * hm_types.h, which includes it.
 */
#include "hm_common.h"

/* Options of ocp_qp_ipm_solve; ocp_qp_ipm_arg_set_default gives working values. */
typedef struct HM_NS(ocp_qp_ipm_arg) {
    int max_iter;            /* interior-point iterations before HM_QP_MAX_ITER */
    HM_REAL tol;             /* on the scaled primal and dual residuals and the duality gap */
    HM_REAL tol_infeas;      /* certificate: no feasible point has ||(u, x, s)||_1 < 1 / tol_infeas */
    HM_REAL step_frac;       /* fraction of the step to the boundary that is taken */
    HM_REAL min_step;        /* a shorter step means no progress: HM_QP_NUMERICAL */
    int polish;              /* 1: refine a solution on its active set (ocp_qp_ipm.h; with HM_QP_POLISH) */
    int residuals;           /* 1: ws->out.res holds the KKT residuals of the returned solution; 0: a solved
                                QP's are left out (the polish still measures them) */
    int detect_unbounded;    /* 1: test stalling steps for a ray of unbounded descent (ocp_qp_ipm.h); 0 for
                                QPs bounded by construction */
    int recurrence;          /* 1: the residuals of the equations follow the steps by their recurrence between
                                exact evaluations (ocp_qp_ipm_pass_a.c); 0: exact in every iteration, whose steps
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
