/*
 * hm_aliases.h: short names for the sized types of hm_types.h, for use inside the runtime.
 * Included once by the translation unit that compiles the runtime, with HM_NS still defined.
 */
#ifndef HM_ALIASES_H
#define HM_ALIASES_H

typedef HM_NS(ocp_qp) hm_ocp_qp;
typedef HM_NS(ocp_qp_sol) hm_ocp_qp_sol;
typedef HM_NS(ocp_qp_res) hm_ocp_qp_res;
typedef HM_NS(ocp_qp_ipm_arg) hm_ocp_qp_ipm_arg;
typedef HM_NS(ocp_qp_ipm_hard) hm_ocp_qp_ipm_hard;
typedef HM_NS(ocp_qp_ipm_stage) hm_ocp_qp_ipm_stage;
typedef HM_NS(ocp_qp_ipm_bounds) hm_ocp_qp_ipm_bounds;
typedef HM_NS(ocp_qp_ipm_rows) hm_ocp_qp_ipm_rows;
#ifdef HM_QP_POLISH
typedef HM_NS(ocp_qp_ipm_vec) hm_ocp_qp_ipm_vec;
typedef HM_NS(ocp_qp_ipm_general) hm_ocp_qp_ipm_general;
#endif
typedef HM_NS(ocp_qp_ipm_ws) hm_ocp_qp_ipm_ws;
typedef HM_NS(ocp_qp_ipm_warm) hm_ocp_qp_ipm_warm;
typedef HM_NS(ocp_qp_hsde_vec) hm_ocp_qp_hsde_vec;
typedef HM_NS(ocp_qp_hsde_ws) hm_ocp_qp_hsde_ws;

#endif /* HM_ALIASES_H */
