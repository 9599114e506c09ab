/* sc_cpu.c: the host CPU's kernel variant; see sc_cpu.h. */
#include "sc_cpu.h"

#include <stdlib.h>
#include <string.h>

#include "sc_err.h"

#if defined(__x86_64__) && defined(__clang__) && __clang_major__ < 16
/* Clang before 16 knows no level names: the features the kernels' code generation uses (the
 * vector ISA and FMA, BMI for the scalar glue); Clang checks the OS's vector state for AVX
 * and AVX-512 as GCC does */
#define SC_CPU_HAS_V3()                                                                            \
    (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&                           \
     __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2"))
#define SC_CPU_HAS_V4()                                                                            \
    (SC_CPU_HAS_V3() && __builtin_cpu_supports("avx512f") &&                                     \
     __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512cd") &&                  \
     __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
#elif defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
/* the level names test every feature of the level, and, for AVX and AVX-512, that the OS
 * saves the vector state (GCC and Clang check xgetbv) */
#define SC_CPU_HAS_V3() __builtin_cpu_supports("x86-64-v3")
#define SC_CPU_HAS_V4() __builtin_cpu_supports("x86-64-v4")
#endif

sc_simd sc_cpu_best_simd(void)
{
#ifdef SC_CPU_HAS_V4
    if (sc_simd_built(SC_SIMD_X86_64_V4) && SC_CPU_HAS_V4()) {
        return SC_SIMD_X86_64_V4;
    }
    if (sc_simd_built(SC_SIMD_X86_64_V3) && SC_CPU_HAS_V3()) {
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
