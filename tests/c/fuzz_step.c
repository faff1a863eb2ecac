/*
 * fuzz_step.c: libFuzzer harness over a generated solver's step function.
 *
 * The fuzzer's bytes become the step's input struct (and, past it, the runtime parameters), so
 * every field takes arbitrary values: NaN, infinities, denormals, absurd magnitudes, human counts
 * out of range, garbage flags. Whatever comes in, the command must be finite and a stop must carry
 * its reason; the sanitizers (address, undefined) watch every access.
 *
 * Build: clang -fsanitize=fuzzer,address,undefined -DSOLVER_HEADER='"fuzz.h"' -DSOLVER_PREFIX=fuzz_
 *        -I<dir> fuzz_step.c <dir>/fuzz.c <dir>/fuzz_model.c -lm
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include SOLVER_HEADER

#define CAT_(a, b) a##b
#define CAT(a, b) CAT_(a, b)
#define S(x) CAT(SOLVER_PREFIX, x)

static S(solver) solver;
static S(input) in;
static S(output) out;
static int initialised;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    S(params) *params;
    size_t n_in = size < sizeof in ? size : sizeof in;
    if (!initialised) {
        S(solver_init)(&solver);
        initialised = 1;
    }
    params = S(solver_params)(&solver);
    S(params_default)(params);
    params->deadline_ms = 1e4; /* sanitizers are slow; the deadline path is covered by the tests */
    memset(&in, 0, sizeof in);
    memcpy(&in, data, n_in);
    if (size > sizeof in) {
        size_t n_p = size - sizeof in < sizeof *params ? size - sizeof in : sizeof *params;
        memcpy(params, data + sizeof in, n_p);
    }
    if (size % 7 == 0) S(solver_reset)(&solver);
    S(solver_step)(&solver, &in, &out);
    if (!isfinite(out.u0[0]) || !isfinite(out.u0[1]) || !isfinite(out.command[0]) || !isfinite(out.command[1]))
        abort();
    if ((out.stop != 0) != (out.stop_reason != 0)) abort();
    return 0;
}
