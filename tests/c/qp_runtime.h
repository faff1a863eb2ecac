/*
 * qp_runtime.h: the QP layer of the C runtime (c_runtime/ocp_qp*.c) for the test programs that
 * compile it without a generated solver, after defining its sizes and types as a solver does. The
 * sources in the order of the solver's translation unit (codegen/render.py: RUNTIME_SOURCES, whose
 * QP part tests/test_ocp_qp.py compares with this list).
 */
#include "ocp_qp.c"
#include "ocp_qp_res.c"
#include "ocp_qp_kkt.c"
#include "ocp_qp_hsde_kkt.c"
#include "ocp_qp_hsde_setup.c"
#include "ocp_qp_hsde_res.c"
#include "ocp_qp_hsde.c"
#include "ocp_qp_ipm_setup.c"
#include "ocp_qp_ipm_lanes.c"
#include "ocp_qp_ipm_pass_a.c"
#include "ocp_qp_ipm_measures.c"
#include "ocp_qp_ipm_pred_corr.c"
#include "ocp_qp_ipm_sol.c"
#include "ocp_qp_ipm_cert.c"
#include "ocp_qp_ipm_polish.c"
#include "ocp_qp_ipm_warm.c"
#include "ocp_qp_ipm.c"
