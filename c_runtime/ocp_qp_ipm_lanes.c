/*
 * ocp_qp_ipm_lanes.c: the inequality families of the interior-point iteration in vector lanes: the
 * bound pairs one side of one slot over all stages at once, the soft rows eight of the list at a
 * time, in passes A, C and E of every iteration and in the termination measures. Stateless: they
 * read and write the solve's stage-major arrays (ocp_qp_ipm_bounds, ocp_qp_ipm_rows).
 */
#include "ocp_qp_ipm_common.h"
#include "ocp_qp_ipm_lanes.h"

/* ------------------------------------------------------------------------------------------------
 * Bound pairs, one side of one slot over all stages at once (ocp_qp_ipm_bounds). Functions of their
 * own so that the arrays are restrict parameters: the compiler then runs the stages in vector lanes.
 * ---------------------------------------------------------------------------------------------- */

/* Pass A: the step, the weights and the side's parts of the diagonal and the gradients; per stage
 * t z, b z and the residual |rho + t|. (Its part of A' w, sign * z, only the stage measures read.) */
HM_FUNC void ocp_qp_ipm_bound_side_a(hm_real alpha, hm_real wmax, const hm_real *restrict sg,
                                     const hm_real *restrict b, const hm_real *restrict v,
                                     const hm_real *restrict dt, const hm_real *restrict dz, hm_real *restrict t,
                                     hm_real *restrict z, hm_real *restrict w, hm_real *restrict ti,
                                     hm_real *restrict zi, hm_real *restrict rho,
                                     hm_real *restrict Hd, hm_real *restrict hf, hm_real *restrict hmu,
                                     hm_real *restrict tz, hm_real *restrict bw, hm_real *restrict rp)
{
    int n;
    for (n = 0; n < HM_QP_NNP; n++) {
        const hm_real s = sg[n];
        const hm_real msk = s * s;
        const hm_real tn = msk * (t[n] + alpha * dt[n]) + (HM_R(1.0) - msk);
        const hm_real zn = msk * (z[n] + alpha * dz[n]) + (HM_R(1.0) - msk);
        const hm_real r = s * v[n] - b[n];
        const hm_real inv = HM_R(1.0) / (tn * zn);
        const hm_real tin = zn * inv, zin = tn * inv;
        const hm_real wn = OCP_QP_IPM_MIN(zn * tin, wmax);
        t[n] = tn;
        z[n] = zn;
        w[n] = wn;
        ti[n] = tin;
        zi[n] = zin;
        rho[n] = r;
        Hd[n] += msk * wn;
        hf[n] += s * wn * r;
        hmu[n] += s * wn * zin;
        tz[n] += msk * tn * zn;
        rp[n] = OCP_QP_IPM_MAX(rp[n], OCP_QP_IPM_ABS(r + tn));
        bw[n] += msk * b[n] * zn;
    }
}

/* Pass C: the predictor's steps from the (u, x) step dv, their products dt dz (kept in del), the
 * side's part of hdl, and per stage the step ratio, t dz + z dt and dt dz. */
HM_FUNC void ocp_qp_ipm_bound_side_c(const hm_real *restrict sg, const hm_real *restrict t,
                                     const hm_real *restrict z, const hm_real *restrict w,
                                     const hm_real *restrict ti, const hm_real *restrict zi,
                                     const hm_real *restrict rho, const hm_real *restrict dv,
                                     hm_real *restrict del, hm_real *restrict hdl, hm_real *restrict ratio,
                                     hm_real *restrict tdz, hm_real *restrict dtdz)
{
    int n;
    for (n = 0; n < HM_QP_NNP; n++) {
        const hm_real s = sg[n], msk = s * s;
        const hm_real dzn = w[n] * (s * dv[n] + rho[n]);
#ifdef OCP_QP_IPM_DT_PRIMAL
        const hm_real dtn = -(rho[n] + t[n]) - s * dv[n];
#else
        const hm_real dtn = -t[n] - t[n] * dzn * zi[n];
#endif
        const hm_real d = dtn * dzn;
        del[n] = d;
        hdl[n] -= s * w[n] * zi[n] * d;
        ratio[n] = OCP_QP_IPM_MAX(ratio[n], OCP_QP_IPM_MAX(-dtn * ti[n], -dzn * zi[n]));
        tdz[n] += msk * (t[n] * dzn + z[n] * dtn);
        dtdz[n] += msk * d;
    }
}

/* Pass E: the corrector's steps (target smu, second-order term kdel * del) and the step ratio. */
HM_FUNC void ocp_qp_ipm_bound_side_e(hm_real smu, hm_real kdel, const hm_real *restrict sg,
                                     const hm_real *restrict t, const hm_real *restrict z,
                                     const hm_real *restrict w, const hm_real *restrict ti,
                                     const hm_real *restrict zi, const hm_real *restrict rho,
                                     const hm_real *restrict del, const hm_real *restrict dv, hm_real *restrict dt,
                                     hm_real *restrict dz, hm_real *restrict ratio)
{
    int n;
    for (n = 0; n < HM_QP_NNP; n++) {
        const hm_real s = sg[n];
        const hm_real cc = smu - kdel * del[n];
        const hm_real dzn = w[n] * (s * dv[n] + rho[n] + cc * zi[n]);
#ifdef OCP_QP_IPM_DT_PRIMAL
        const hm_real dtn = -(rho[n] + t[n]) - s * dv[n];
        (void)z;
#else
        const hm_real dtn = -(t[n] * z[n] - cc + t[n] * dzn) * zi[n];
#endif
        dz[n] = dzn;
        dt[n] = dtn;
        ratio[n] = OCP_QP_IPM_MAX(ratio[n], OCP_QP_IPM_MAX(-dtn * ti[n], -dzn * zi[n]));
    }
}

/* The termination tests' measures: per stage |A_I v + t|, t and min(t, z) of the present sides. */
HM_FUNC void ocp_qp_ipm_bound_side_measures(const hm_real *restrict sg, const hm_real *restrict t,
                                            const hm_real *restrict z, const hm_real *restrict v,
                                            hm_real *restrict av, hm_real *restrict nt, hm_real *restrict ncr)
{
    int n;
    for (n = 0; n < HM_QP_NNP; n++) {
        const hm_real s = sg[n], msk = s * s;
        av[n] = OCP_QP_IPM_MAX(av[n], msk * OCP_QP_IPM_ABS(s * v[n] + t[n]));
        nt[n] = OCP_QP_IPM_MAX(nt[n], msk * t[n]);
        ncr[n] = OCP_QP_IPM_MAX(ncr[n], msk * OCP_QP_IPM_MIN(t[n], z[n]));
    }
}

/* ------------------------------------------------------------------------------------------------
 * Soft rows, eight rows of the list at a time (ocp_qp_ipm_rows): the same arithmetic for every row,
 * the stages' parts summed afterwards. Lanes keep the sums and maxima of the passes.
 * ---------------------------------------------------------------------------------------------- */

/* What the passes derive from a row's iterate (s, t, z, zs) and its slack's cost (Zl, zl): the
 * inverses, the weights z / t and zs / s (capped), the eliminated slack's 1 / (Zl + wr + ws) and the
 * slack's stationarity residual. Pass A derives them after its step, passes C and E again from the
 * same numbers (stored by pass A) by these same expressions: the same values, without a list for each. */
typedef struct {
    hm_real ti, zi, si, zsi, wr, wsl, hinv, rs;
} ocp_qp_ipm_row_terms;

HM_KERNEL ocp_qp_ipm_row_terms ocp_qp_ipm_row_derive(hm_real s, hm_real t, hm_real z, hm_real zs, hm_real Zl,
                                                     hm_real zl, hm_real wmax)
{
    ocp_qp_ipm_row_terms d;
    const hm_real ia = HM_R(1.0) / (t * z), ib = HM_R(1.0) / (s * zs);
    d.rs = Zl * s + zl - z - zs;
    d.ti = z * ia;
    d.zi = t * ia;
    d.si = zs * ib;
    d.zsi = s * ib;
    d.wr = OCP_QP_IPM_MIN(z * d.ti, wmax);
    d.wsl = OCP_QP_IPM_MIN(zs * d.si, wmax);
    d.hinv = HM_R(1.0) / (Zl + d.wr + d.wsl);
    return d;
}

/* Pass A: the step, the weights, the eliminated slack, and per row the factors of its parts of the
 * stage's (px, py) block and gradients, we (in sdr), e (in sdsb) and cmu (in se); lanes: t z, b w,
 * q v, v P v, the primal and the slack's dual residual. */
HM_FUNC void ocp_qp_ipm_rows_a(hm_ocp_qp_ipm_rows *restrict sr, int nrp, hm_real alpha, hm_real wmax,
                               hm_real (*restrict lane)[OCP_QP_IPM_LANES])
{
    int r0, l;
    for (r0 = 0; r0 < nrp; r0 += OCP_QP_IPM_LANES) {
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            const int q = r0 + l;
            const hm_real msk = sr->slive[q];
            const hm_real s = msk * (sr->ss[q] + alpha * sr->sds[q]) + (HM_R(1.0) - msk);
            const hm_real t = msk * (sr->st[q] + alpha * sr->sdt[q]) + (HM_R(1.0) - msk);
            const hm_real z = msk * (sr->sz[q] + alpha * sr->sdz[q]) + (HM_R(1.0) - msk);
            const hm_real zs = msk * (sr->szs[q] + alpha * sr->sdzs[q]) + (HM_R(1.0) - msk);
            const hm_real lg = sr->slg[q], Zl = sr->sZl[q];
            const hm_real rho = lg - sr->gp[q] - s;
            const ocp_qp_ipm_row_terms d = ocp_qp_ipm_row_derive(s, t, z, zs, Zl, sr->szl[q], wmax);
            const hm_real hw = d.hinv * d.wr;
            const hm_real we = hw * (Zl + d.wsl);
            const hm_real e = we * rho + hw * (d.rs + d.wsl * s);
            const hm_real cmu = we * d.zi - hw * d.wsl * d.zsi;
            sr->ss[q] = s;
            sr->st[q] = t;
            sr->sz[q] = z;
            sr->szs[q] = zs;
            sr->sdr[q] = we;
            sr->sdsb[q] = e;
            sr->se[q] = cmu;
            lane[0][l] += msk * (t * z + s * zs);
            lane[1][l] -= msk * lg * z;
            lane[2][l] += msk * sr->szl[q] * s;
            lane[3][l] += msk * Zl * s * s;
            lane[4][l] = OCP_QP_IPM_MAX(lane[4][l], OCP_QP_IPM_ABS(t + rho));
            lane[5][l] = OCP_QP_IPM_MAX(lane[5][l], OCP_QP_IPM_ABS(d.rs));
        }
    }
}

/* Pass C: the predictor's steps from the position steps (gd), their products (kept in sdr, sdsb for
 * the corrector), per row the factor of its part of hdl on (px, py) in se; lanes: the step ratio,
 * t dz + z dt and dt dz. */
HM_FUNC void ocp_qp_ipm_rows_c(hm_ocp_qp_ipm_rows *restrict sr, int nrp, hm_real wmax,
                               hm_real (*restrict lane)[OCP_QP_IPM_LANES])
{
    int r0, l;
    for (r0 = 0; r0 < nrp; r0 += OCP_QP_IPM_LANES) {
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            const int q = r0 + l;
            const hm_real msk = sr->slive[q];
            const hm_real s = sr->ss[q], t = sr->st[q], z = sr->sz[q], zs = sr->szs[q];
            const ocp_qp_ipm_row_terms d = ocp_qp_ipm_row_derive(s, t, z, zs, sr->sZl[q], sr->szl[q], wmax);
            const hm_real wr = d.wr, wsl = d.wsl, hinv = d.hinv;
            const hm_real zi = d.zi, zsi = d.zsi;
            const hm_real hw = hinv * wr, we = hw * (sr->sZl[q] + wsl);
            const hm_real gd = sr->gd[q];
            const hm_real rho = sr->slg[q] - sr->gp[q] - s;
            const hm_real ds = hinv * (wr * rho - wsl * s - d.rs) - hw * gd;
            const hm_real dz = wr * (rho - gd - ds);
            const hm_real dzs = -wsl * (s + ds);
#ifdef OCP_QP_IPM_DT_PRIMAL
            const hm_real dt = gd + ds - (t + rho);
#else
            const hm_real dt = -t - t * dz * zi;
#endif
            const hm_real dr = dt * dz, dsb = ds * dzs;
            const hm_real coef = we * zi * dr - hw * wsl * zsi * dsb;
            sr->sdr[q] = dr;
            sr->sdsb[q] = dsb;
            sr->se[q] = coef;
            lane[0][l] = OCP_QP_IPM_MAX(lane[0][l], OCP_QP_IPM_MAX(OCP_QP_IPM_MAX(-dt * d.ti, -dz * zi),
                                                                  OCP_QP_IPM_MAX(-ds * d.si, -dzs * zsi)));
            lane[1][l] += msk * (t * dz + z * dt + s * dzs + zs * ds);
            lane[2][l] += msk * (dr + dsb);
        }
    }
}

/* Pass E: the corrector's steps (target smu, second-order term kdel * (sdr, sdsb)); lane: the step
 * ratio. */
HM_FUNC void ocp_qp_ipm_rows_e(hm_ocp_qp_ipm_rows *restrict sr, int nrp, hm_real wmax, hm_real smu, hm_real kdel,
                               hm_real *restrict lane)
{
    int r0, l;
    for (r0 = 0; r0 < nrp; r0 += OCP_QP_IPM_LANES) {
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            const int q = r0 + l;
            const hm_real s = sr->ss[q], t = sr->st[q], z = sr->sz[q], zs = sr->szs[q];
            const ocp_qp_ipm_row_terms d = ocp_qp_ipm_row_derive(s, t, z, zs, sr->sZl[q], sr->szl[q], wmax);
            const hm_real wr = d.wr, wsl = d.wsl, hinv = d.hinv;
            const hm_real zi = d.zi, zsi = d.zsi;
            const hm_real cr = smu - kdel * sr->sdr[q], cs = smu - kdel * sr->sdsb[q];
            const hm_real hw = hinv * wr;
            const hm_real gd = sr->gd[q];
            const hm_real rho0 = sr->slg[q] - sr->gp[q] - s;
            const hm_real rho = rho0 + cr * zi;
            const hm_real rhos = cs * zsi - s;
            const hm_real ds = hinv * (wr * rho + wsl * rhos - d.rs) - hw * gd;
            const hm_real dz = wr * (rho - gd - ds);
            const hm_real dzs = wsl * (rhos - ds);
#ifdef OCP_QP_IPM_DT_PRIMAL
            const hm_real dt = gd + ds - (t + rho0);
            (void)z;
#else
            const hm_real dt = -(t * z - cr + t * dz) * zi;
#endif
            sr->sds[q] = ds;
            sr->sdt[q] = dt;
            sr->sdz[q] = dz;
            sr->sdzs[q] = dzs;
            lane[l] = OCP_QP_IPM_MAX(lane[l], OCP_QP_IPM_MAX(OCP_QP_IPM_MAX(-dt * d.ti, -dz * zi),
                                                             OCP_QP_IPM_MAX(-ds * d.si, -dzs * zsi)));
        }
    }
}

/* The termination tests' measures over the live rows (padding rows masked to 0): |A_I v + t|, t,
 * min(t, z) and min(s, zs), the slack's A' w and P v. */
HM_FUNC void ocp_qp_ipm_rows_measures(const hm_ocp_qp_ipm_rows *restrict sr, int nrp,
                                      hm_real (*restrict lane)[OCP_QP_IPM_LANES])
{
    int r0, l;
    for (r0 = 0; r0 < nrp; r0 += OCP_QP_IPM_LANES) {
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            const int q = r0 + l;
            const hm_real msk = sr->slive[q];
            const hm_real t = sr->st[q], z = sr->sz[q], s = sr->ss[q], zs = sr->szs[q];
            const hm_real av = t - sr->gp[q] - s;
            lane[0][l] = OCP_QP_IPM_MAX(lane[0][l], msk * OCP_QP_IPM_ABS(av));
            lane[1][l] = OCP_QP_IPM_MAX(lane[1][l], msk * t);
            lane[2][l] = OCP_QP_IPM_MAX(lane[2][l], msk * OCP_QP_IPM_MAX(OCP_QP_IPM_MIN(t, z), OCP_QP_IPM_MIN(s, zs)));
            lane[3][l] = OCP_QP_IPM_MAX(lane[3][l], msk * (z + zs));
            lane[4][l] = OCP_QP_IPM_MAX(lane[4][l], msk * OCP_QP_IPM_ABS(sr->sZl[q] * s));
        }
    }
}
