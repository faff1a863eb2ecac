/*
 * hm_math.h: sin, cos, exp and atan2 computed by the runtime itself, in double and in float.
 *
 * Why not <math.h>: C leaves these functions' last bit to the library, and libraries differ there
 * (glibc's sin against newlib's on the firmware, even glibc's own FMA and non-FMA variants). The
 * real-time iteration's warm start and the loop recovery amplify one bit into 1e-8 within a few
 * hundred periods, so the same controller gave other commands on a robot's computer than on its
 * Cortex-M. Built from +, -, *, / (IEEE, correctly rounded, not contracted under -std=c99), integer
 * conversion and the exact fmod and ldexp, these give the same bits on every C99 platform with IEEE
 * arithmetic and FLT_EVAL_METHOD 0 (x86-64 SSE, Arm VFP). Accuracy: within 3 ulp (double; 3.5 float)
 * of the true value (tests/test_portable_math.py measures it against glibc). The argument reduction
 * of sin and cos is exact for |x| < 8.2e5 rad (double) and 6.4e3 rad (float); beyond, an fmod by
 * 2 pi makes them less accurate but still the same everywhere (the controller's angles stay far
 * inside).
 *
 * Self-contained on purpose: the CasADi-generated model file includes it as well
 * (codegen/casadi_emit.py renames its sin/cos/exp calls to these), so model and runtime share one
 * set of functions. Polynomials: Taylor's series economised by Chebyshev polynomials on the reduced
 * interval (exact rational arithmetic; what is left out is below 1e-18 (double) or 2e-10 (float) of the
 * result), evaluated by Horner's rule from the highest term. No library call on the common path:
 * rounding by integer conversion, 2^k built from its bits (ldexp only near overflow and underflow).
 */
#ifndef HM_MATH_H
#define HM_MATH_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#if defined(__GNUC__)
#define HM_MATH_FUNC static __attribute__((unused))
#else
#define HM_MATH_FUNC static
#endif

/* ------------------------------------------------------------------------------------------------
 * double
 * ------------------------------------------------------------------------------------------------ */

/* pi/2 in parts of 33, 33 and 53 bits: k * part is exact for |k| < 2^20. */
#define HM_MATH_PIO2_1 1.5707963267341256
#define HM_MATH_PIO2_2 6.077100506303966e-11
#define HM_MATH_PIO2_3 2.0222662487959506e-21
#define HM_MATH_2_PI 0.6366197723675814
#define HM_MATH_REDUCE_MAX 823549.0 /* 2^19 pi/2 */
#define HM_MATH_PI 3.141592653589793
#define HM_MATH_PI_2 1.5707963267948966
#define HM_MATH_PI_4 0.7853981633974483
#define HM_MATH_TAN_PI_8 0.41421356237309503
/* ln 2 in a 32-bit part and the rest: k * hi is exact for |k| < 2^21. */
#define HM_MATH_LN2_HI 0.6931471806019545
#define HM_MATH_LN2_LO (-4.2009150726810846e-11)
#define HM_MATH_INV_LN2 1.4426950408889634

/* c[0] + z (c[1] + z (c[2] + ...)), from the highest term. */
HM_MATH_FUNC double hm_math_horner(const double *c, int n, double z) {
    double p = c[n - 1];
    int i;
    for (i = n - 2; i >= 0; --i) p = p * z + c[i];
    return p;
}

/* sin r = r + r z P(z), z = r^2, |r| <= pi/4 (P: -1/3! + z/5! - ..., economised to degree 6). */
HM_MATH_FUNC double hm_math_sin_kernel(double r) {
    static const double c[7] = {-0.16666666666666666,    0.008333333333333331,   -0.00019841269841265065,
                                2.755731921933988e-06,   -2.5052106232666854e-08, 1.605853165014853e-10,
                                -7.586698778125347e-13};
    const double z = r * r;
    return r + r * z * hm_math_horner(c, 7, z);
}

/* cos r = 1 - z Q(z) (Q: 1/2! - z/4! + ..., economised to degree 6). */
HM_MATH_FUNC double hm_math_cos_kernel(double r) {
    static const double c[7] = {0.5,                     -0.04166666666666664,  0.0013888888888880777,
                                -2.4801587293694825e-05, 2.7557315566764273e-07, -2.0875886798171374e-09,
                                1.1368001863024335e-11};
    const double z = r * r;
    return 1.0 - z * hm_math_horner(c, 7, z);
}

/* x = k pi/2 + r with |r| <= pi/4 (and rounding), k rounded half away from zero by conversion (exact
 * for |x| < HM_MATH_REDUCE_MAX); the quadrant k mod 4 in 0..3. */
HM_MATH_FUNC double hm_math_reduce(double x, int *quadrant) {
    const double t = x * HM_MATH_2_PI;
    const long ki = (long)(t < 0.0 ? t - 0.5 : t + 0.5);
    const double k = (double)ki;
    *quadrant = (int)(((ki % 4) + 4) % 4);
    return ((x - k * HM_MATH_PIO2_1) - k * HM_MATH_PIO2_2) - k * HM_MATH_PIO2_3;
}

/* Beyond the exact reduction: fmod by 2 pi rounded (fmod is exact), so that every input gives the same
 * bits; the angle is off by x * 2.4e-16 / (2 pi) (4e-11 rad at 1e6 rad). NaN and inf give NaN. */
HM_MATH_FUNC double hm_math_far(double x) {
    if (x != x || fabs(x) == HUGE_VAL) return x - x;
    return fmod(x, 2.0 * HM_MATH_PI);
}

HM_MATH_FUNC double hm_math_sin(double x) {
    int q;
    double r;
    if (!(fabs(x) < HM_MATH_REDUCE_MAX)) x = hm_math_far(x);
    if (x == 0.0) return x; /* sin(-0) = -0 */
    r = hm_math_reduce(x, &q);
    if (q == 0) return hm_math_sin_kernel(r);
    if (q == 1) return hm_math_cos_kernel(r);
    if (q == 2) return -hm_math_sin_kernel(r);
    return -hm_math_cos_kernel(r);
}

HM_MATH_FUNC double hm_math_cos(double x) {
    int q;
    double r;
    if (!(fabs(x) < HM_MATH_REDUCE_MAX)) x = hm_math_far(x);
    r = hm_math_reduce(x, &q);
    if (q == 0) return hm_math_cos_kernel(r);
    if (q == 1) return -hm_math_sin_kernel(r);
    if (q == 2) return -hm_math_cos_kernel(r);
    return hm_math_sin_kernel(r);
}

/* 2^k for an integer k, from its IEEE bits where 2^k is a normal double (exact either way). */
HM_MATH_FUNC double hm_math_pow2(double y, int k) {
    uint64_t bits;
    double scale;
    if (k < -1022 || k > 1023) return ldexp(y, k);
    bits = (uint64_t)(k + 1023) << 52;
    memcpy(&scale, &bits, sizeof scale);
    return y * scale;
}

/* exp x = 2^k exp r, |r| <= ln2 / 2, exp r = 1 + r + r^2 E(r) (E: 1/2! + r/3! + ..., economised to
 * degree 10). */
HM_MATH_FUNC double hm_math_exp(double x) {
    static const double c[11] = {0.5,                   0.1666666666666667,     0.04166666666666668,
                                 0.008333333333326136,  0.0013888888888879075,  0.00019841269874817515,
                                 2.480158733643862e-05, 2.75572554044176e-06,   2.7557263283119803e-07,
                                 2.510521516564936e-08, 2.091813619824862e-09};
    double t, k, r;
    int ki;
    if (x != x) return x;
    if (x > 709.8) return HUGE_VAL;
    if (x < -745.2) return 0.0;
    t = x * HM_MATH_INV_LN2;
    ki = (int)(t < 0.0 ? t - 0.5 : t + 0.5);
    k = (double)ki;
    r = (x - k * HM_MATH_LN2_HI) - k * HM_MATH_LN2_LO;
    {
        /* E(r) by Estrin's scheme: pairs, then powers r^2, r^4, r^8, a chain of 4 multiply-adds
         * instead of Horner's 10 (the collision cost's exp is on the RTI step's critical path) */
        const double r2 = r * r, r4 = r2 * r2, r8 = r4 * r4;
        const double e03 = (c[0] + c[1] * r) + (c[2] + c[3] * r) * r2;
        const double e47 = (c[4] + c[5] * r) + (c[6] + c[7] * r) * r2;
        const double e810 = (c[8] + c[9] * r) + c[10] * r2;
        return hm_math_pow2(1.0 + (r + r2 * ((e03 + e47 * r4) + e810 * r8)), ki);
    }
}

/* atan t for 0 <= t <= 1: above tan(pi/8), pi/4 + atan((t - 1) / (t + 1)), so that |t| <= tan(pi/8),
 * where atan t = t A(t^2) (A: 1 - z/3 + z^2/5 - ..., economised to degree 12). */
HM_MATH_FUNC double hm_math_atan01(double t) {
    static const double c[13] = {1.0,                  -0.33333333333333326,  0.1999999999999709,
                                 -0.14285714285337822, 0.11111111085776028,   -0.0909090807401841,
                                 0.07692281413729647,  -0.06666209585962121,  0.05876873797776205,
                                 -0.05217554392604461, 0.04500432793207413,   -0.03340846548588704,
                                 0.015133766371040192};
    double base = 0.0;
    if (t > HM_MATH_TAN_PI_8) {
        base = HM_MATH_PI_4;
        t = (t - 1.0) / (t + 1.0);
    }
    return base + t * hm_math_horner(c, 13, t * t);
}

/* C99's atan2, special values included (signed zeros, infinities, NaN). */
HM_MATH_FUNC double hm_math_atan2(double y, double x) {
    const double ax = fabs(x), ay = fabs(y);
    double a;
    if (x != x || y != y) return x + y;
    if (ax == HUGE_VAL && ay == HUGE_VAL) a = HM_MATH_PI_4;
    else if (ay > ax) a = HM_MATH_PI_2 - hm_math_atan01(ax / ay);
    else if (ax == 0.0) a = 0.0;
    else a = hm_math_atan01(ay / ax);
    if (signbit(x)) a = HM_MATH_PI - a;
    return signbit(y) ? -a : a;
}

/* ------------------------------------------------------------------------------------------------
 * float: the same methods with single-precision constants and fewer terms, no double anywhere (a
 * Cortex-M4F's FPU has single precision only).
 * ------------------------------------------------------------------------------------------------ */

/* pi/2 in parts of 12, 12 and 24 bits: k * part is exact for |k| < 2^12. */
#define HM_MATH_PIO2_1F 1.57080078f
#define HM_MATH_PIO2_2F (-4.45358455e-6f)
#define HM_MATH_PIO2_3F (-8.70551575e-10f)
#define HM_MATH_2_PIF 0.636619747f
#define HM_MATH_REDUCE_MAXF 6433.0f /* 2^12 pi/2, rounded down */
#define HM_MATH_PIF 3.14159274f
#define HM_MATH_PI_2F 1.57079637f
#define HM_MATH_PI_4F 0.785398185f
#define HM_MATH_TAN_PI_8F 0.414213568f
/* ln 2 in a 16-bit part and the rest: k * hi is exact for |k| < 2^8. */
#define HM_MATH_LN2_HIF 0.693145752f
#define HM_MATH_LN2_LOF 1.42860677e-6f
#define HM_MATH_INV_LN2F 1.44269502f

HM_MATH_FUNC float hm_math_hornerf(const float *c, int n, float z) {
    float p = c[n - 1];
    int i;
    for (i = n - 2; i >= 0; --i) p = p * z + c[i];
    return p;
}

/* P economised to degree 3. */
HM_MATH_FUNC float hm_math_sin_kernelf(float r) {
    static const float c[4] = {-0.166666672f, 0.00833333191f, -0.00019840087f, 2.72499619e-06f};
    const float z = r * r;
    return r + r * z * hm_math_hornerf(c, 4, z);
}

/* Q economised to degree 4. */
HM_MATH_FUNC float hm_math_cos_kernelf(float r) {
    static const float c[5] = {0.5f, -0.0416666679f, 0.00138888846f, -2.47998632e-05f, 2.72371665e-07f};
    const float z = r * r;
    return 1.0f - z * hm_math_hornerf(c, 5, z);
}

HM_MATH_FUNC float hm_math_reducef(float x, int *quadrant) {
    const float t = x * HM_MATH_2_PIF;
    const int ki = (int)(t < 0.0f ? t - 0.5f : t + 0.5f);
    const float k = (float)ki;
    *quadrant = ((ki % 4) + 4) % 4;
    return ((x - k * HM_MATH_PIO2_1F) - k * HM_MATH_PIO2_2F) - k * HM_MATH_PIO2_3F;
}

HM_MATH_FUNC float hm_math_farf(float x) {
    if (x != x || fabsf(x) == HUGE_VALF) return x - x;
    return fmodf(x, 2.0f * HM_MATH_PIF);
}

HM_MATH_FUNC float hm_math_sinf(float x) {
    int q;
    float r;
    if (!(fabsf(x) < HM_MATH_REDUCE_MAXF)) x = hm_math_farf(x);
    if (x == 0.0f) return x;
    r = hm_math_reducef(x, &q);
    if (q == 0) return hm_math_sin_kernelf(r);
    if (q == 1) return hm_math_cos_kernelf(r);
    if (q == 2) return -hm_math_sin_kernelf(r);
    return -hm_math_cos_kernelf(r);
}

HM_MATH_FUNC float hm_math_cosf(float x) {
    int q;
    float r;
    if (!(fabsf(x) < HM_MATH_REDUCE_MAXF)) x = hm_math_farf(x);
    r = hm_math_reducef(x, &q);
    if (q == 0) return hm_math_cos_kernelf(r);
    if (q == 1) return -hm_math_sin_kernelf(r);
    if (q == 2) return -hm_math_cos_kernelf(r);
    return hm_math_sin_kernelf(r);
}

HM_MATH_FUNC float hm_math_pow2f(float y, int k) {
    uint32_t bits;
    float scale;
    if (k < -126 || k > 127) return ldexpf(y, k);
    bits = (uint32_t)(k + 127) << 23;
    memcpy(&scale, &bits, sizeof scale);
    return y * scale;
}

/* E economised to degree 5. */
HM_MATH_FUNC float hm_math_expf(float x) {
    static const float c[6] = {0.5f, 0.166666672f, 0.0416664667f, 0.00833329838f, 0.00139336509f, 0.000198992857f};
    float t, k, r;
    int ki;
    if (x != x) return x;
    if (x > 88.73f) return HUGE_VALF;
    if (x < -103.98f) return 0.0f;
    t = x * HM_MATH_INV_LN2F;
    ki = (int)(t < 0.0f ? t - 0.5f : t + 0.5f);
    k = (float)ki;
    r = (x - k * HM_MATH_LN2_HIF) - k * HM_MATH_LN2_LOF;
    return hm_math_pow2f(1.0f + (r + r * r * hm_math_hornerf(c, 6, r)), ki);
}

/* A economised to degree 6. */
HM_MATH_FUNC float hm_math_atan01f(float t) {
    static const float c[7] = {1.f, -0.333333313f, 0.199998856f, -0.142816395f, 0.110410482f, -0.0845907703f,
                               0.0471292883f};
    float base = 0.0f;
    if (t > HM_MATH_TAN_PI_8F) {
        base = HM_MATH_PI_4F;
        t = (t - 1.0f) / (t + 1.0f);
    }
    return base + t * hm_math_hornerf(c, 7, t * t);
}

HM_MATH_FUNC float hm_math_atan2f(float y, float x) {
    const float ax = fabsf(x), ay = fabsf(y);
    float a;
    if (x != x || y != y) return x + y;
    if (ax == HUGE_VALF && ay == HUGE_VALF) a = HM_MATH_PI_4F;
    else if (ay > ax) a = HM_MATH_PI_2F - hm_math_atan01f(ax / ay);
    else if (ax == 0.0f) a = 0.0f;
    else a = hm_math_atan01f(ay / ax);
    if (signbit(x)) a = HM_MATH_PIF - a;
    return signbit(y) ? -a : a;
}

#endif /* HM_MATH_H */
