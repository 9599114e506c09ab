/* sc_cpu.c: the host CPU's kernel variant; see sc_cpu.h. */
#include "sc_cpu.h"

#include <stdlib.h>
#include <string.h>

#include "sc_err.h"

sc_simd sc_cpu_best_simd(void)
{
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    /* the level names test every feature of the level, and, for AVX and AVX-512, that the
     * OS saves the vector state (GCC and Clang check xgetbv) */
    if (sc_simd_built(SC_SIMD_X86_64_V4) && __builtin_cpu_supports("x86-64-v4")) {
        return SC_SIMD_X86_64_V4;
    }
    if (sc_simd_built(SC_SIMD_X86_64_V3) && __builtin_cpu_supports("x86-64-v3")) {
        return SC_SIMD_X86_64_V3;
    }
#endif
    return SC_SIMD_GENERIC;
}

int sc_cpu_select_simd(void)
{
    const sc_simd best = sc_cpu_best_simd();
    const char *want = getenv("SONOCOMP_SIMD");
    if (want == NULL || want[0] == '\0') {
        return sc_simd_select(best);
    }
    for (int v = 0; v < (int)SC_SIMD_COUNT; v++) {
        /* a level up to the best one (the levels are nested) */
        if (strcmp(want, sc_simd_name((sc_simd)v)) == 0 && v <= (int)best) {
            return sc_simd_select((sc_simd)v);
        }
    }
    (void)sc_simd_select(best);
    return SC_ERR_INVALID_ARG;
}
