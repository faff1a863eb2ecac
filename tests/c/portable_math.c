/* The runtime's sin/cos/exp/atan2 (c_runtime/hm_math.h) against glibc's long-double functions, an
 * independent reference about 11 bits finer than double. Prints, per function, the largest error in
 * units in the last place of the result's precision over a dense sweep of the ranges the solver
 * uses, and a checksum of every result's bits (the same checksum from every compiler and
 * optimisation level is the point of hm_math.h). */
#include <float.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "hm_math.h"

#define SWEEP 400000L

static uint64_t checksum = 1469598103934665603ULL; /* FNV-1a over the results' bytes */

static void mix(const void *p, size_t n) {
    const unsigned char *b = (const unsigned char *)p;
    size_t i;
    for (i = 0; i < n; ++i) checksum = (checksum ^ b[i]) * 1099511628211ULL;
}

static double ulps(long double got, long double ref, int mant_bits, int min_exp) {
    int e;
    long double unit;
    if (ref == 0.0L) return got == 0.0L ? 0.0 : 1e300;
    frexpl(ref, &e);
    unit = ldexpl(1.0L, (e - mant_bits < min_exp) ? min_exp : e - mant_bits);
    return (double)(fabsl(got - ref) / unit);
}

#define WORST(var, got, ref, bits, emin)                                                                       \
    do {                                                                                                       \
        const double u_ = ulps((long double)(got), (ref), (bits), (emin));                                   \
        if (u_ > (var)) (var) = u_;                                                                            \
    } while (0)

int main(void) {
    double s = 0, c = 0, e = 0, a = 0, sf = 0, cf = 0, ef = 0, af = 0;
    long i;
    for (i = 0; i <= SWEEP; ++i) {
        const double t = (double)i / (double)SWEEP;
        const double x = -50.0 + 100.0 * t;       /* angles: headings over several turns */
        const double xe = -700.0 + 1409.0 * t;    /* exp without overflow or subnormal results */
        const float xf = (float)x, xef = (float)(-87.0 + 175.0 * t);
        const double y = sin(0.37 * (double)i), xa = cos(0.37 * (double)i) * (double)(1 + i % 7);
        const float yf = (float)y, xaf = (float)xa;
        double r[4];
        float rf[4];
        r[0] = hm_math_sin(x);
        r[1] = hm_math_cos(x);
        r[2] = hm_math_exp(xe);
        r[3] = hm_math_atan2(y, xa);
        rf[0] = hm_math_sinf(xf);
        rf[1] = hm_math_cosf(xf);
        rf[2] = hm_math_expf(xef);
        rf[3] = hm_math_atan2f(yf, xaf);
        mix(r, sizeof r);
        mix(rf, sizeof rf);
        WORST(s, r[0], sinl((long double)x), 53, -1074);
        WORST(c, r[1], cosl((long double)x), 53, -1074);
        WORST(e, r[2], expl((long double)xe), 53, -1074);
        WORST(a, r[3], atan2l((long double)y, (long double)xa), 53, -1074);
        WORST(sf, rf[0], sinl((long double)xf), 24, -149);
        WORST(cf, rf[1], cosl((long double)xf), 24, -149);
        WORST(ef, rf[2], expl((long double)xef), 24, -149);
        WORST(af, rf[3], atan2l((long double)yf, (long double)xaf), 24, -149);
    }
    printf("ulp double sin %.4f cos %.4f exp %.4f atan2 %.4f\n", s, c, e, a);
    printf("ulp float sin %.4f cos %.4f exp %.4f atan2 %.4f\n", sf, cf, ef, af);
    printf("checksum %016llx\n", (unsigned long long)checksum);
    return 0;
}
