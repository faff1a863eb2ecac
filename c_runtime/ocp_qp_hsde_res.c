/*
 * ocp_qp_hsde_res.c: the residuals of the fallback solver's embedding at a point, once or twice per
 * iteration: the stage Hessian products, the residuals of the embedding's equations and of its tau
 * row, the termination tests' scalars and, on request, the row weights of the next Newton matrix.
 */
#include "ocp_qp_hsde.h"
#include "ocp_qp_hsde_common.h"
#include "ocp_qp_hsde_res.h"
#include "ocp_qp_kkt.h"

/* y = c H_n x for the cost Hessian [R S'; S Q] of stage n on (u, x) and the cost scale c; parts
 * absent at stage 0 (x) and stage N (u) are zero in y and ignored in x. */
HM_FUNC void ocp_qp_hsde_stage_hess_mul(const hm_ocp_qp *restrict qp, int n, hm_real c, const hm_real *restrict x,
                                       hm_real *restrict y)
{
    int i, k;
    if (n < HM_N) {
        const hm_real *restrict R = qp->R[n];
        y[0] = c * (R[0] * x[0] + R[2] * x[1]);
        y[1] = c * (R[1] * x[0] + R[3] * x[1]);
    } else {
        y[0] = y[1] = HM_R(0.0);
    }
    if (n == 0) {
        for (i = 0; i < HM_NX; i++) y[HM_NU + i] = HM_R(0.0);
        return;
    }
    {
        const hm_real *restrict Q = qp->Q[n];
        hm_real yx[HM_NX] = {HM_R(0.0), HM_R(0.0), HM_R(0.0), HM_R(0.0)};
        for (k = 0; k < HM_NX; k++) {
            const hm_real xk = x[HM_NU + k];
            for (i = 0; i < HM_NX; i++) yx[i] += Q[i + k * HM_NX] * xk;
        }
        if (n < HM_N) {
            const hm_real *restrict S = qp->S[n];
            hm_real su0 = HM_R(0.0), su1 = HM_R(0.0);
            for (k = 0; k < HM_NX; k++) {
                const hm_real *restrict sk = &S[k * HM_NU];
                su0 += sk[0] * x[HM_NU + k];
                su1 += sk[1] * x[HM_NU + k];
                yx[k] += sk[0] * x[0] + sk[1] * x[1];
            }
            y[0] += c * su0;
            y[1] += c * su1;
        }
        for (i = 0; i < HM_NX; i++) y[HM_NU + i] = c * yx[i];
    }
}


/* Residuals of the embedding at the point (v, t, tau, ws->kappa) into ws->rv:
 *   rv.ux, rv.s = P v + A' w + q tau,   rv.y = A_E v - b_E tau,   rv.z = A_I v + t - b_I tau,
 *   rtau = kappa + q' v + b' w + v' P v / tau,
 * the vector c = q + 2 P v / tau of the tau row, and the scalars of the termination tests. With
 * weights, also the row weights of the Newton matrix at this point (ws->w). */
HM_FUNC void ocp_qp_hsde_residuals(const hm_ocp_qp *restrict qp, hm_ocp_qp_hsde_ws *restrict ws,
                                  const hm_ocp_qp_hsde_vec *restrict v, const hm_real *restrict t, hm_real tau,
                                  int weights, ocp_qp_hsde_sums *restrict sm)
{
    hm_ocp_qp_hsde_vec *restrict r = &ws->rv;
    const hm_real two_tinv = HM_R(2.0) / tau;
    const hm_real w_max = ws->w_max;
    hm_real qv = HM_R(0.0), bw = HM_R(0.0), vPv = HM_R(0.0), tz = HM_R(0.0);
    hm_real atw_n = HM_R(0.0), pv_n = HM_R(0.0), aveq_n = HM_R(0.0), avin_n = HM_R(0.0);
    hm_real rd = HM_R(0.0), rp = HM_R(0.0), nv = HM_R(0.0), nw = HM_R(0.0), nt = HM_R(0.0);
    int n, i, j, k;

    for (n = 0; n <= HM_N; n++) {
        const int so = ws->soff[n], ro = ws->roff[n];
        const hm_real *restrict ux = v->ux[n];
        const hm_real *restrict qn = ws->q_ux[n];
        const int off = ws->off[n];
        const int nb = ws->nb[n];
        const int base = off + nb;
        const int nr = ws->nr[n];
        const int ns = ws->ns[n];
        const int c0 = n == HM_N ? HM_NU : 0;
        const int c1 = n == 0 ? HM_NU : HM_QP_NUX;
        hm_real Pux[HM_QP_NUX], atw[HM_QP_NUX];

        ocp_qp_hsde_stage_hess_mul(qp, n, ws->cost_scale, ux, Pux);

        /* A' w on (u, x): dynamics, bounds, general rows */
        if (n < HM_N) {
            const hm_real *restrict B = qp->B[n];
            const hm_real *restrict y = v->y[n];
            atw[0] = -(B[0] * y[0] + B[1] * y[1] + B[2] * y[2] + B[3] * y[3]);
            atw[1] = -(B[4] * y[0] + B[5] * y[1] + B[6] * y[2] + B[7] * y[3]);
        } else {
            atw[0] = atw[1] = HM_R(0.0);
        }
        if (n > 0) {
            for (i = 0; i < HM_NX; i++) atw[HM_NU + i] = v->y[n - 1][i];
            if (n < HM_N) {
                const hm_real *restrict A = qp->A[n];
                const hm_real *restrict y = v->y[n];
                for (i = 0; i < HM_NX; i++) {
                    const hm_real *restrict a = &A[i * HM_NX];
                    atw[HM_NU + i] -= a[0] * y[0] + a[1] * y[1] + a[2] * y[2] + a[3] * y[3];
                }
            }
        } else {
            for (i = 0; i < HM_NX; i++) atw[HM_NU + i] = HM_R(0.0);
        }
        for (k = 0; k < nb; k++) {
            const int c = ws->box_comp[n][k];
            const hm_real sg = ws->box_sign[n][k];
            atw[c] += sg * v->z[off + k];
            r->z[off + k] = sg * ux[c] + t[off + k] - ws->b_ineq[off + k] * tau;
        }
        if (nr > 0) {
            const hm_real p0 = ux[HM_NU], p1 = ux[HM_NU + 1];
            hm_real a0 = HM_R(0.0), a1 = HM_R(0.0);
            for (k = 0; k < nr; k++) {
                const hm_real *restrict d = ws->D[ro + k];
                const hm_real zk = v->z[base + k];
                a0 += d[0] * zk;
                a1 += d[1] * zk;
                r->z[base + k] = t[base + k] - (d[0] * p0 + d[1] * p1) - ws->b_ineq[base + k] * tau;
                /* soft slack subtracted below */
            }
            atw[HM_NU] -= a0;
            atw[HM_NU + 1] -= a1;
        }
        for (j = 0; j < ns; j++) {
            const int jr = base + nr + j;
            const int kr = ws->soft_of[so + j];
            const hm_real s = v->s[ro + kr];
            const hm_real ps = ws->soft_Zl[so + j] * s;
            const hm_real atws = -v->z[base + kr] - v->z[jr];
            const hm_real rs = ps + atws + ws->q_s[ro + kr] * tau;
            r->s[ro + kr] = rs;
            ws->c_s[ro + kr] = ws->q_s[ro + kr] + two_tinv * ps;
            r->z[base + kr] -= s;
            r->z[jr] = t[jr] - s;
            qv += ws->q_s[ro + kr] * s;
            vPv += ps * s;
            atw_n = OCP_QP_HSDE_MAX(atw_n, hm_fabs(atws));
            pv_n = OCP_QP_HSDE_MAX(pv_n, hm_fabs(ps));
            rd = OCP_QP_HSDE_MAX(rd, hm_fabs(rs));
            nv = OCP_QP_HSDE_MAX(nv, hm_fabs(s));
        }
        for (i = 0; i < HM_QP_NUX; i++) {
            const hm_real ri = Pux[i] + atw[i] + qn[i] * tau;
            r->ux[n][i] = ri;
            ws->c_ux[n][i] = qn[i] + two_tinv * Pux[i];
        }
        for (i = c0; i < c1; i++) {
            qv += qn[i] * ux[i];
            vPv += Pux[i] * ux[i];
            atw_n = OCP_QP_HSDE_MAX(atw_n, hm_fabs(atw[i]));
            pv_n = OCP_QP_HSDE_MAX(pv_n, hm_fabs(Pux[i]));
            rd = OCP_QP_HSDE_MAX(rd, hm_fabs(r->ux[n][i]));
            nv = OCP_QP_HSDE_MAX(nv, hm_fabs(ux[i]));
        }

        /* dynamics rows x_{n+1} - A x_n - B u_n = b_n tau */
        if (n < HM_N) {
            const hm_real *restrict A = qp->A[n];
            const hm_real *restrict B = qp->B[n];
            const hm_real *restrict y = v->y[n];
            hm_real e[HM_NX];
            for (i = 0; i < HM_NX; i++) e[i] = v->ux[n + 1][HM_NU + i] - B[i] * ux[0] - B[i + HM_NX] * ux[1];
            if (n > 0) {
                for (k = 0; k < HM_NX; k++) {
                    const hm_real xk = ux[HM_NU + k];
                    for (i = 0; i < HM_NX; i++) e[i] -= A[i + k * HM_NX] * xk;
                }
            }
            for (i = 0; i < HM_NX; i++) {
                const hm_real bi = ws->b_eq[n][i];
                const hm_real ri = e[i] - bi * tau;
                r->y[n][i] = ri;
                aveq_n = OCP_QP_HSDE_MAX(aveq_n, hm_fabs(e[i]));
                rp = OCP_QP_HSDE_MAX(rp, hm_fabs(ri));
                bw += bi * y[i];
                nw = OCP_QP_HSDE_MAX(nw, hm_fabs(y[i]));
            }
        }
    }
    /* and, for the Newton matrix of this iterate, the row weights w = min(z / t, w_max) */
    for (j = 0; j < ws->m; j++) {
        const hm_real zj = v->z[j], tj = t[j];
        rp = OCP_QP_HSDE_MAX(rp, hm_fabs(r->z[j]));
        avin_n = OCP_QP_HSDE_MAX(avin_n, hm_fabs(r->z[j] + ws->b_ineq[j] * tau));
        bw += ws->b_ineq[j] * zj;
        tz += tj * zj;
        nw = OCP_QP_HSDE_MAX(nw, zj);
        nt = OCP_QP_HSDE_MAX(nt, tj);
    }
    for (j = 0; weights && j < ws->m; j++) ws->w[j] = ocp_qp_hsde_weight(t[j], v->z[j], w_max).w;
    ws->rtau = ws->kappa + qv + bw + vPv / tau;
    sm->qv = qv;
    sm->bw = bw;
    sm->vPv = vPv;
    sm->tz = tz;
    sm->atw = atw_n;
    sm->pv = pv_n;
    sm->av_eq = aveq_n;
    sm->av_ineq = avin_n;
    sm->rd = rd;
    sm->rp = rp;
    sm->nv = nv;
    sm->nw = nw;
    sm->nt = nt;
}
