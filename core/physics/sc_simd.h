/*
 * sc_simd.h: instruction-set variants of the core's hot kernels.
 *
 * A hot kernel (today the MSDS substep) is one C source compiled once per variant with that
 * variant's compiler flags; the compiler vectorises the same loops to the variant's vector
 * width. Every operation in those loops is a correctly rounded IEEE operation or an exact
 * select and nothing is re-associated (-ffp-contract=off), so every variant gives the same
 * bits: a variant is a speed choice only, and a session recorded on one machine replays
 * bit for bit on another (tests/unit/test_sc_simd.c compares the variants).
 *
 * The core never probes the CPU (it calls no OS and reads no machine state): the platform
 * knows what its CPU and OS support and selects a variant at boot, before the engine runs
 * (platform/hostsim/sc_hs_cpu.h on x86-64 hosts; the MCU image keeps the portable one).
 * Until then the portable variant runs.
 *
 * The grid mat-vec's software prefetch (sc_grid_kern.inc) is the same kind of choice: a hint
 * that changes no bit, worth 2x on the 64x32x32 product on the EPYC hosts of the earlier
 * sessions (1 MiB L2: 1.55 -> 0.77 ms) and costing 25 % on an Intel Xeon with 2 MiB of L2
 * (0.66 -> 0.85 ms, `bench-physics 30 cg`), whose own prefetchers follow the rows. So it is the
 * CPU's, not the mesh's: the platform selects it at boot as it selects the variant
 * (platform/linux/sc_cpu.h measures the product both ways); until then the mesh decides
 * (sc_grid.h, SC_GRID_PREFETCH_NODES).
 *
 * Thread rules: select at boot, from the thread that then runs the engine (a process-wide
 * setting, read at each substep or mat-vec; changing it between them is harmless as the
 * choices agree bit for bit). Never allocates.
 */
#ifndef SC_SIMD_H
#define SC_SIMD_H

typedef enum sc_simd {
    SC_SIMD_GENERIC = 0,   /* portable C: the compiler's baseline (SSE2 on x86-64, NEON on
                            * aarch64, scalar + FPU on the Cortex-M7) */
    SC_SIMD_X86_64_V3 = 1, /* x86-64-v3 (AVX2; psABI level, as glibc-hwcaps names it) */
    SC_SIMD_X86_64_V4 = 2, /* x86-64-v4 (AVX-512 F/BW/CD/DQ/VL) */
    SC_SIMD_COUNT
} sc_simd;

/* 1 if this build contains the variant's kernels, 0 otherwise (also for an invalid value). */
int sc_simd_built(sc_simd v);

/* Select the variant for all hot kernels. The caller vouches that the CPU and OS support it.
 * Errors: SC_ERR_INVALID_ARG (not a variant), SC_ERR_NOT_SUPPORTED (not in this build; the
 * selection is unchanged). */
int sc_simd_select(sc_simd v);

/* The selected variant (SC_SIMD_GENERIC until a select). */
sc_simd sc_simd_selected(void);

/* "generic", "x86-64-v3", "x86-64-v4"; "?" for an invalid value. */
const char *sc_simd_name(sc_simd v);

/* The grid mat-vec's software prefetch (above). */
typedef enum sc_simd_prefetch {
    SC_SIMD_PREFETCH_MESH = 0, /* by the mesh: on above SC_GRID_PREFETCH_NODES nodes (default) */
    SC_SIMD_PREFETCH_ON = 1,   /* on every mesh */
    SC_SIMD_PREFETCH_OFF = 2,  /* on none: the CPU's own prefetchers */
    SC_SIMD_PREFETCH_COUNT
} sc_simd_prefetch;

/* Select the mat-vec's prefetch for every grid. Errors: SC_ERR_INVALID_ARG (not a choice; the
 * selection is unchanged). O(1). */
int sc_simd_select_prefetch(sc_simd_prefetch p);

/* The selected prefetch (SC_SIMD_PREFETCH_MESH until a select). */
sc_simd_prefetch sc_simd_selected_prefetch(void);

/* "mesh", "on", "off"; "?" for an invalid value. */
const char *sc_simd_prefetch_name(sc_simd_prefetch p);

#endif /* SC_SIMD_H */
