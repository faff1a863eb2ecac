/*
 * ocp_qp_ipm_cert.c: the certificates of the interior-point method: the Farkas test of a dual vector
 * (infeasible QP), the test of the last step as a direction of unbounded descent, and the candidate
 * certificate from the last step's multipliers. Tried by the solve loop when its steps stall.
 */
#include "ocp_qp_kkt.h"
#include "ocp_qp_ipm_common.h"
#include "ocp_qp_ipm_cert.h"

/* The candidate certificate of a stalling iteration: the dual part of the last step's direction,
 * its multiplier steps clipped at 0 (when the multipliers diverge along a certificate, their steps
 * point along it with less of the bounded part that the iterate carries), read where the step is
 * kept: y = dy, z = max(dz, 0) of each inequality. */
HM_KERNEL hm_real ocp_qp_ipm_ray_z(hm_real dz)
{
    return OCP_QP_IPM_MAX(dz, HM_R(0.0));
}

/* Farkas test of that ray w = (y, z): b' w < 0 and ||A' w||_inf <= tol_infeas * (-b' w) (z >= 0 by
 * the clipping). Returns 1 if it passes, with b' w. */
HM_FUNC int ocp_qp_ipm_farkas_step(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, hm_real tol_infeas,
                                   hm_real *bw_out)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    hm_real bw = HM_R(0.0), atw_n = HM_R(0.0);
    int n, i, k, j, l;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        const int c0 = n == HM_N ? HM_NU : 0;
        const int c1 = n == 0 ? HM_NU : HM_QP_NUX;
        hm_real atw[HM_QP_NUX];
        for (i = 0; i < HM_QP_NUX; i++) atw[i] = HM_R(0.0);
        if (n < HM_N) {
            const hm_real *y = sn->dy;
            for (i = 0; i < HM_NU; i++) atw[i] -= ocp_qp_kkt_dot4(qp->B[n] + i * HM_NX, y);
            if (n > 0) {
                for (i = 0; i < HM_NX; i++) atw[HM_NU + i] -= ocp_qp_kkt_dot4(qp->A[n] + i * HM_NX, y);
            }
            for (i = 0; i < HM_NX; i++) bw += sn->beq[i] * y[i];
        }
        if (n > 0) {
            for (i = 0; i < HM_NX; i++) atw[HM_NU + i] += ws->u.f.st[n - 1].dy[i];
        }
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) {
                const hm_real sg = bd->sg[k][l][n];
                const hm_real zb = ocp_qp_ipm_ray_z(bd->dz[k][l][n]);
                atw[bd->bc[k]] += sg * zb;
                bw += sg * sg * bd->b[k][l][n] * zb;
            }
        }
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            const hm_real zr = ocp_qp_ipm_ray_z(sr->sdz[row]), zs = ocp_qp_ipm_ray_z(sr->sdzs[row]);
            const hm_real as = OCP_QP_IPM_ABS(zr + zs);
            atw[HM_NU] -= sr->sd0[row] * zr;
            atw[HM_NU + 1] -= sr->sd1[row] * zr;
            bw -= sr->slg[row] * zr;
            atw_n = OCP_QP_IPM_MAX(atw_n, as);
        }
        for (j = 0; j < sn->nh; j++) {
            const hm_real zh = ocp_qp_ipm_ray_z(sn->hr->hdz[j]);
            atw[HM_NU] -= sn->hr->hd0[j] * zh;
            atw[HM_NU + 1] -= sn->hr->hd1[j] * zh;
            bw -= sn->hr->hlg[j] * zh;
        }
        for (i = c0; i < c1; i++) atw_n = OCP_QP_IPM_MAX(atw_n, OCP_QP_IPM_ABS(atw[i]));
    }
    *bw_out = bw;
    return bw < HM_R(0.0) && atw_n <= tol_infeas * -bw;
}

/* Test of the last step's primal direction d = (du, dx, ds) as a direction of unbounded descent:
 * q' d < 0 and ||P d||, ||A_E d||, ||(A_I d)_+|| (inf-norms) <= tol_infeas * (-q' d), in the units
 * of the data. Along such a d every feasible point can be improved without bound. */
HM_FUNC int ocp_qp_ipm_unbounded_ray(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, hm_real tol_infeas)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    const hm_real cinv = HM_R(1.0) / ws->cost_scale;
    hm_real qd = HM_R(0.0), pd = HM_R(0.0), ad = HM_R(0.0);
    int n, i, k, j, l;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        const hm_real *d = sn->dux;
        const int c0 = n == HM_N ? HM_NU : 0;
        const int c1 = n == 0 ? HM_NU : HM_QP_NUX;
        hm_real Pd[HM_QP_NUX];
        ocp_qp_ipm_hess_mul(qp, n, ws->cost_scale, d, Pd);
        for (i = c0; i < c1; i++) {
            qd += sn->q[i] * d[i];
            pd = OCP_QP_IPM_MAX(pd, OCP_QP_IPM_ABS(Pd[i]));
        }
        if (n < HM_N) {
            const hm_real *A = qp->A[n];
            const hm_real *B = qp->B[n];
            const hm_real *dn = &ws->u.f.st[n + 1].dux[HM_NU];
            for (i = 0; i < HM_NX; i++) {
                hm_real e = dn[i] - B[i] * d[0] - B[i + HM_NX] * d[1];
                if (n > 0) {
                    for (k = 0; k < HM_NX; k++) e -= A[i + k * HM_NX] * d[HM_NU + k];
                }
                ad = OCP_QP_IPM_MAX(ad, OCP_QP_IPM_ABS(e));
            }
        }
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) ad = OCP_QP_IPM_MAX(ad, bd->sg[k][l][n] * d[bd->bc[k]]);
        }
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            const hm_real gd = sr->sd0[row] * d[HM_NU] + sr->sd1[row] * d[HM_NU + 1];
            qd += sr->szl[row] * sr->sds[row];
            pd = OCP_QP_IPM_MAX(pd, OCP_QP_IPM_ABS(sr->sZl[row] * sr->sds[row]));
            ad = OCP_QP_IPM_MAX(ad, OCP_QP_IPM_MAX(-(gd + sr->sds[row]), -sr->sds[row]));
        }
        for (j = 0; j < sn->nh; j++)
            ad = OCP_QP_IPM_MAX(ad, -(sn->hr->hd0[j] * d[HM_NU] + sn->hr->hd1[j] * d[HM_NU + 1]));
    }
    return qd < HM_R(0.0) && OCP_QP_IPM_MAX(pd * cinv, ad) <= tol_infeas * -qd * cinv;
}
