/*
 * ocp_qp_kkt.h: the Newton system of the interior-point method, solved by a Riccati recursion.
 *
 * With v = (u_0, x_1, s_1, u_1, ..., x_N, s_N) the primal variables, P the QP Hessian, A_E v = b_E
 * the dynamics, A_I v + t = b_I (t >= 0) the packed inequality rows and w > 0 one weight per row
 * (z / t in the interior-point method), the system is
 *
 *     [ P    A_E'  A_I'         ] [dv ]   [rhs.ux, rhs.s]
 *     [ A_E  0     0            ] [dy ] = [rhs.y        ]
 *     [ A_I  0     -diag(1 / w) ] [dz ]   [rhs.z        ].
 *
 * dz is eliminated row by row and the soft slacks stage by stage; what is left is an
 * equality-constrained QP over the stages, solved by a backward Riccati recursion and a forward
 * substitution. Rows enter the (u, x) Hessian of their stage as a diagonal term (bounds) or as a
 * scalar times D D' on the (px, py) block (general rows). The factorisation depends on w only; one
 * factorisation serves any number of right-hand sides.
 */
#ifndef OCP_QP_KKT_H
#define OCP_QP_KKT_H

#include "hm_common.h"

#define HM_QP_NUX (HM_NU + HM_NX)

/* The 2x2 input block and the (px, py) rows are written out for these sizes. */
typedef char ocp_qp_kkt_sizes_fixed[(HM_NU == 2 && HM_NP == 2 && HM_NG <= 255) ? 1 : -1];

/* Factorise with the row weights ws->w over the row map of ws. 0, or HM_QP_NUMERICAL if a pivot of
 * the reduced input Hessian is not safely positive (the QP is not strictly convex in u along the
 * current active set, or the weights have overflowed). */
HM_FUNC int ocp_qp_kkt_factorize(const hm_ocp_qp *qp, hm_ocp_qp_ipm_ws *ws);

/* Solve with the last factorisation; sol may be rhs (solved in place). Returns c' sol_v + b' sol_w
 * for the vectors c = (ws->c_ux, ws->c_s) and b = (ws->b_eq, ws->b_ineq) of the interior-point method
 * (the tau row of its Newton system), accumulated stage by stage during the forward pass. */
HM_FUNC hm_real ocp_qp_kkt_solve(const hm_ocp_qp *qp, hm_ocp_qp_ipm_ws *ws, const hm_ocp_qp_ipm_vec *rhs,
                                 hm_ocp_qp_ipm_vec *sol);

#endif /* OCP_QP_KKT_H */
