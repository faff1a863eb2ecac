/*
 * psd_projection.c (white box): the exact Hessian's projection onto {eigenvalues >= floor}, as the
 * SQP applies it per stage (ocp_nlp_lin.c), on matrices read from stdin. The solver's translation unit
 * is included, so that its static projections are reachable.
 *
 * Build: cc -DSOLVER_SOURCE='"psd.c"' -I<dir> psd_projection.c <dir>/psd_model.c -lm
 * Input: lines "kind n floor m_00 m_10 ... m_(n-1)(n-1)" (column-major), kind "full" (the Jacobi
 *        projection of the whole matrix), "pair" (the closed form, n = 2) or "stage" (a stage's
 *        [Q S'; S R] through ocp_nlp_convexify_stage, n = NX + NU);
 * Output: per line the n * n entries of the projection, %.17g.
 */
#include <stdio.h>
#include SOLVER_SOURCE

static hm_ocp_qp qp;

int main(void)
{
    char kind[8];
    int n, i, j;
    double floor_in;
    while (scanf("%7s %d %lf", kind, &n, &floor_in) == 3) {
        double M[36];
        if (n < 1 || n > 6) return 2;
        for (i = 0; i < n * n; i++)
            if (scanf("%lf", &M[i]) != 1) return 2;
        if (kind[0] == 'f') {
            ocp_nlp_project_psd(M, n, floor_in);
        } else if (kind[0] == 'p') {
            if (n != 2) return 2;
            ocp_nlp_project_psd2(&M[0], &M[2], &M[3], floor_in);
            M[1] = M[2];
        } else {
            if (n != HM_NX + HM_NU) return 2;
            for (j = 0; j < HM_NX; j++)
                for (i = 0; i < HM_NX; i++) qp.Q[0][i + j * HM_NX] = M[i + j * n];
            for (j = 0; j < HM_NX; j++)
                for (i = 0; i < HM_NU; i++) qp.S[0][i + j * HM_NU] = M[HM_NX + i + j * n];
            for (j = 0; j < HM_NU; j++)
                for (i = 0; i < HM_NU; i++) qp.R[0][i + j * HM_NU] = M[HM_NX + i + (HM_NX + j) * n];
            ocp_nlp_convexify_stage(&qp, 0, floor_in);
            for (j = 0; j < HM_NX; j++)
                for (i = 0; i < HM_NX; i++) M[i + j * n] = qp.Q[0][i + j * HM_NX];
            for (j = 0; j < HM_NX; j++)
                for (i = 0; i < HM_NU; i++) M[HM_NX + i + j * n] = M[j + (HM_NX + i) * n] = qp.S[0][i + j * HM_NU];
            for (j = 0; j < HM_NU; j++)
                for (i = 0; i < HM_NU; i++) M[HM_NX + i + (HM_NX + j) * n] = qp.R[0][i + j * HM_NU];
        }
        for (i = 0; i < n * n; i++) printf("%.17g%c", M[i], i + 1 < n * n ? ' ' : '\n');
    }
    return 0;
}
