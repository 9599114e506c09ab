/* bench_pages.h: a benchmark's static state on the pages the appliance runs on. sonocomp advises
 * its engine object onto 2 MiB transparent huge pages (rt.hugepages, platform/linux/sc_rt.h); a
 * benchmark that times the same code does the same with its own static state, before anything
 * touches it, unless SC_BENCH_PAGES=4k asks for the kernel's default pages (to measure what the
 * page size buys). Returns what to print. */
#ifndef BENCH_PAGES_H
#define BENCH_PAGES_H

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "sc_rt.h"

static inline const char *bench_pages(void *p, size_t n)
{
    const char *e = getenv("SC_BENCH_PAGES");
    if (e != NULL && strcmp(e, "4k") == 0) {
        return "4 KiB (SC_BENCH_PAGES=4k)";
    }
    switch (sc_rt_advise_hugepages(p, n)) {
    case 0:
        return "2 MiB advised (as rt.hugepages; SC_BENCH_PAGES=4k for 4 KiB)";
    case 1:
        return "4 KiB (state under 2 MiB)";
    default:
        return "4 KiB (huge pages refused by the kernel)";
    }
}

#endif /* BENCH_PAGES_H */
