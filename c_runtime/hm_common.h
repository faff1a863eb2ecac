/*
 * hm_common.h: what every part of the humanmpc C runtime shares, independent of any solver's sizes.
 *
 * The runtime is compiled inside each generated solver's single translation unit (see
 * docs/ARCHITECTURE.md): the including file defines hm_real, the size macros HM_N and HM_NG, and
 * HM_NS (the type-name prefix), then includes the runtime .c files. Every runtime function is
 * HM_FUNC (static), so two solvers with different sizes link into one binary without clashes.
 */
#ifndef HM_COMMON_H
#define HM_COMMON_H

#include <math.h>
#include <stddef.h>

#include "hm_math.h"
#include "hm_status.h"

/* The robot model is fixed by the product: unicycle state [px, py, theta, v], control [a, omega].
 * General (distance) rows touch only the position [px, py]. */
#define HM_NX 4
#define HM_NU 2
#define HM_NPOS 2

/* What the OCP's QPs have (ocp_nlp_lin.c), which sizes a generated solver's QP memory
 * (ocp_qp_ipm_types.h: HM_NBP, HM_NGH): bounds on three components of (u, x), a and omega (u) and
 * v (x); no hard rows, every distance row is soft (an exact penalty). */
#define HM_OCP_NBP 3
#define HM_OCP_NGH 0

/* Runtime functions are private to the translation unit that includes them. A solver need not use
 * every helper of the runtime, so unused ones must not warn. */
#ifndef HM_FUNC
#if defined(__GNUC__)
#define HM_FUNC static __attribute__((unused))
#else
#define HM_FUNC static
#endif
#endif

/* The 4x4 kernels of the Riccati recursion, called several times per stage: inline, so that their
 * operands stay in registers (as calls, every result went through memory). */
#ifndef HM_KERNEL
#if defined(__GNUC__)
#define HM_KERNEL static inline __attribute__((unused, always_inline))
#else
#define HM_KERNEL static inline
#endif
#endif

#define HM_CONCAT_(a, b) a##b
#define HM_CONCAT(a, b) HM_CONCAT_(a, b)

/* Single precision is selected with HM_REAL_IS_FLOAT; all literals go through HM_R so that a float
 * build never promotes to double (an explicit cast of a constant is folded at compile time), and
 * all math goes through these wrappers: sin, cos, exp and atan2 to the runtime's own (hm_math.h), whose
 * bits do not depend on the C library, the exactly rounded rest to <math.h>. */
#ifdef HM_REAL_IS_FLOAT
#define HM_R(x) ((float)(x))
#define hm_sqrt sqrtf
#define hm_fabs fabsf
#define hm_exp hm_math_expf
#define hm_fmax fmaxf
#define hm_fmin fminf
#define hm_atan2 hm_math_atan2f
#define hm_cos hm_math_cosf
#define hm_sin hm_math_sinf
#define hm_floor floorf
#define HM_EPS 1.1920929e-07f
#define HM_INF 1.0e30f
#else
#define HM_R(x) ((double)(x))
#define hm_sqrt sqrt
#define hm_fabs fabs
#define hm_exp hm_math_exp
#define hm_fmax fmax
#define hm_fmin fmin
#define hm_atan2 hm_math_atan2
#define hm_cos hm_math_cos
#define hm_sin hm_math_sin
#define hm_floor floor
#define HM_EPS 2.220446049250313e-16
#define HM_INF 1.0e30
#endif

/* A bound whose magnitude reaches HM_INF is absent (no row is created for it). */
#define HM_IS_INF(x) (hm_fabs(x) >= HM_INF)

/* Status of a QP solve: HM_QP_SOLVED, HM_QP_MAX_ITER, ... (rows of hm_status.h, their single
 * source; fixed values, part of the public C and Python API). */
enum hm_qp_status { HM_QP_STATUS_TABLE(HM_STATUS_ENUM_ROW) };

#endif /* HM_COMMON_H */
