/*
 * sc_fuzz.h: the contract of a fuzz target.
 *
 * Each tests/fuzz/fuzz_<name>.c defines LLVMFuzzerTestOneInput (libFuzzer's entry point) and
 * sc_fuzz_seed (valid inputs to start mutating from). The same file builds two ways
 * (tests/fuzz.cmake):
 *  - with the fuzz preset (clang, -DSC_FUZZ=ON, every library instrumented) as a libFuzzer
 *    binary, run by tools/fuzz.sh NAME SECONDS and in CI by tools/check-fuzz.sh, starting from
 *    the checked-in corpus tests/fuzz/corpus/<name>/ (tools/fuzz-seeds.sh writes the seeds
 *    there);
 *  - always, as a ctest "smoke" binary with tests/fuzz/sc_fuzz_main.c: it replays that corpus
 *    and the crash regressions tests/fuzz/regress/<name>/, then runs a deterministic
 *    mutational driver (bit flips, byte sets, truncation, extension, splices of seeds) for a
 *    fixed number of inputs under ASan/UBSan in the dev preset.
 * Optional beside it: fuzz_<name>.libs (libraries to link besides sc_hostsim, whitespace
 * separated) and fuzz_<name>.dict (a libFuzzer dictionary).
 * A target must accept any input without crashing, hanging or leaking, and may check its own
 * invariants with SC_FUZZ_CHECK (aborts with a message).
 */
#ifndef SC_FUZZ_H
#define SC_FUZZ_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
/* Write seed number i into buf (capacity cap); return its size, or 0 when there is no seed i. */
size_t sc_fuzz_seed(uint32_t i, uint8_t *buf, size_t cap);

#define SC_FUZZ_CHECK(c)                                                                       \
    do {                                                                                       \
        if (!(c)) {                                                                            \
            fprintf(stderr, "%s:%d: fuzz invariant failed: %s\n", __FILE__, __LINE__, #c);     \
            abort();                                                                           \
        }                                                                                      \
    } while (0)

#endif /* SC_FUZZ_H */
