/*
 * hm_types.h: every sized type of the QP layer, instantiated once per solver (the NLP's solver
 * struct, which embeds them, follows in ocp_nlp_types.h).
 *
 * Deliberately without an include guard: a generated solver's public header includes this file
 * after defining
 *     HM_NS(x)   the type-name prefix, e.g. paper_##x (so two solvers' headers can meet in one file)
 *     HM_REAL    the real type (double or float)
 *     HM_N       number of shooting intervals (stages 0..HM_N)
 *     HM_NG      maximum number of general (distance) rows per stage
 * and undefines them afterwards. Inside the runtime the types are used through the short names of
 * hm_aliases.h. Sizes are compile-time constants: all memory of a solver is one struct that the
 * caller may place statically.
 *
 * Matrices are dense and column-major: M[i + j * rows] is row i, column j (CasADi's and BLAS'
 * order).
 */
#include "hm_common.h"

/* One header per object, each without an include guard, in the order of their dependencies: the
 * QP; the options and outcome of a QP solve; the fallback solver, whose workspace the interior-point
 * solver's holds in a union; the interior-point solver. */
#include "ocp_qp_types.h"
#include "ocp_qp_ipm_arg_types.h"
#include "ocp_qp_hsde_types.h"
#include "ocp_qp_ipm_types.h"
