/* sc_simd.c: the process-wide kernel variant; see sc_simd.h. */
#include "sc_simd.h"

#include "sc_err.h"

static sc_simd s_selected = SC_SIMD_GENERIC;
static sc_simd_prefetch s_prefetch = SC_SIMD_PREFETCH_MESH;

int sc_simd_built(sc_simd v)
{
    switch (v) {
    case SC_SIMD_GENERIC:
        return 1;
    case SC_SIMD_X86_64_V3:
#if defined(SC_SIMD_X86_64_V3_BUILT)
        return 1;
#else
        return 0;
#endif
    case SC_SIMD_X86_64_V4:
#if defined(SC_SIMD_X86_64_V4_BUILT)
        return 1;
#else
        return 0;
#endif
    case SC_SIMD_COUNT:
    default:
        return 0;
    }
}

int sc_simd_select(sc_simd v)
{
    if ((unsigned)v >= (unsigned)SC_SIMD_COUNT) {
        return SC_ERR_INVALID_ARG;
    }
    if (!sc_simd_built(v)) {
        return SC_ERR_NOT_SUPPORTED;
    }
    s_selected = v;
    return SC_OK;
}

sc_simd sc_simd_selected(void)
{
    return s_selected;
}

const char *sc_simd_name(sc_simd v)
{
    switch (v) {
    case SC_SIMD_GENERIC:
        return "generic";
    case SC_SIMD_X86_64_V3:
        return "x86-64-v3";
    case SC_SIMD_X86_64_V4:
        return "x86-64-v4";
    case SC_SIMD_COUNT:
    default:
        return "?";
    }
}

int sc_simd_select_prefetch(sc_simd_prefetch p)
{
    if ((unsigned)p >= (unsigned)SC_SIMD_PREFETCH_COUNT) {
        return SC_ERR_INVALID_ARG;
    }
    s_prefetch = p;
    return SC_OK;
}

sc_simd_prefetch sc_simd_selected_prefetch(void)
{
    return s_prefetch;
}

const char *sc_simd_prefetch_name(sc_simd_prefetch p)
{
    switch (p) {
    case SC_SIMD_PREFETCH_MESH:
        return "mesh";
    case SC_SIMD_PREFETCH_ON:
        return "on";
    case SC_SIMD_PREFETCH_OFF:
        return "off";
    case SC_SIMD_PREFETCH_COUNT:
    default:
        return "?";
    }
}
