/*
 * sc_hs_pool.h: the host simulator's worker pool (hal/sc_hal_pool.h): it claims a number of
 * workers (1..SC_HS_POOL_MAX_WORKERS) and runs the very ranges a Linux pool of that size would
 * hand out, on the calling thread, worker by worker (worker w takes ranges w, w + W, ...), the
 * last worker first: a job whose result depended on the order of its ranges, or a range that
 * read what another range of the same job writes, would show in the tests. Deterministic, never
 * allocates, no threads.
 */
#ifndef SC_HS_POOL_H
#define SC_HS_POOL_H

#include <stdint.h>

#include "sc_hal_pool.h"

#define SC_HS_POOL_MAX_WORKERS 64u

typedef struct sc_hs_pool {
    uint32_t workers;
    uint64_t jobs;   /* run calls */
    uint64_t ranges; /* ranges run */
} sc_hs_pool;

/* A pool of `workers` (clamped to 1..SC_HS_POOL_MAX_WORKERS) behind dev. O(1). */
void sc_hs_pool_init(sc_hs_pool *p, uint32_t workers, sc_pool_dev *dev);

#endif /* SC_HS_POOL_H */
