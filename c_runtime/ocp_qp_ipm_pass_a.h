/*
 * ocp_qp_ipm_pass_a.h: pass A of an interior-point iteration (ocp_qp_ipm_pass_a.c) and the record of
 * its residual evaluation, which the termination measures complete and the solve loop tests.
 */
#ifndef OCP_QP_IPM_PASS_A_H
#define OCP_QP_IPM_PASS_A_H

#include "ocp_qp_ipm_common.h"

/* Scalars of one residual evaluation. Pass A computes the inequalities' parts exactly and takes the
 * residuals of the dynamics (ry) and of the stationarity of (u, x) (rv) by their recurrence: a
 * Newton step solves those linear equations, so a step of length alpha leaves (1 - alpha) of them.
 * The recurrence saves the stage products (P v, A' w, A_E v) in most iterations; they are evaluated
 * exactly (ocp_qp_ipm_stage_measures: the residuals afresh, the norms of the stage vectors, the
 * cost) in the first iteration and whenever the termination tests could pass, so no test passes on
 * recurred values and rounding drift cannot accumulate into the solution (ocp_qp_ipm_solve). The
 * norms over the inequalities (av_ineq .. pv_s) only enter the termination tests' normalisation,
 * the natural residual and the certificate test, and are computed by ocp_qp_ipm_row_measures only
 * when one of those tests can pass. */
typedef struct {
    hm_real qv, bw, vPv, tz;          /* q' v, b' w, v' P v, t' z (q' v, v' P v: after stage measures) */
    hm_real atw, pv, av_eq;           /* inf-norms over (u, x) of A' w and P v; of A_E v (the same) */
    hm_real rd, rp;                   /* inf-norms of the dual and primal residuals */
    hm_real rd_eq, rp_eq;             /* their parts of the stationarity of (u, x), of the dynamics */
    hm_real rd_in, rp_in;             /* and of the soft slacks, of the inequalities */
    hm_real qv_in, vPv_in;            /* the soft slacks' parts of q' v and v' P v */
    hm_real vz;                       /* 0 * sum of v: NaN if v holds a NaN or an infinity */
    int exact;                        /* the stage measures are of this iterate */
    int measured;                     /* so are the inequality measures */
    hm_real av_ineq, nt;              /* inf-norms of A_I v + t and of t */
    hm_real ncr;                      /* max over inequalities of min(t, z) */
    hm_real atw_s, pv_s;              /* inf-norms over the soft slacks of A' w and P v */
} ocp_qp_ipm_sums;

/* Pass A: takes the last step (length alpha), evaluates the residuals and the weights, condenses the
 * inequalities into their stages; the sums into *sm, measured neither exactly nor over the
 * inequalities (sm->exact = sm->measured = 0). */
HM_FUNC void ocp_qp_ipm_pass_a(hm_ocp_qp_ipm_ws *restrict ws, hm_real alpha, ocp_qp_ipm_sums *restrict sm);

#endif /* OCP_QP_IPM_PASS_A_H */
