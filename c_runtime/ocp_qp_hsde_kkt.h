/*
 * ocp_qp_hsde_kkt.h: the Newton system of the fallback solver's embedding (ocp_qp_hsde_kkt.c).
 */
#ifndef OCP_QP_HSDE_KKT_H
#define OCP_QP_HSDE_KKT_H

#include "hm_common.h"

/* Factorises the Newton matrix at the row weights ws->w (Riccati over the stages: ws->P, ws->Lr,
 * ws->Y, the soft rows' ws->soft_hinv); 0, or HM_QP_NUMERICAL if a pivot of an input block is not
 * safely positive. */
HM_FUNC int ocp_qp_hsde_kkt_factorize(const hm_ocp_qp *restrict qp, hm_ocp_qp_hsde_ws *restrict ws);

/* Solves the factorised system for rhs into sol (which may be rhs); returns the tau row's product
 * c' sol.v + b' sol.w of the solution. */
HM_FUNC hm_real ocp_qp_hsde_kkt_solve(const hm_ocp_qp *restrict qp, hm_ocp_qp_hsde_ws *restrict ws,
                                 const hm_ocp_qp_hsde_vec *rhs, hm_ocp_qp_hsde_vec *sol);

#endif /* OCP_QP_HSDE_KKT_H */
