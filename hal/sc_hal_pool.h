/*
 * sc_hal_pool.h: a fixed pool of workers that runs one job over N ranges.
 *
 * The core splits a loop into a fixed number of ranges that depends on the problem alone
 * (never on how many workers there are) and asks the pool to call fn(arg, r) once for every
 * r in 0 .. ranges - 1; run returns when every call has returned. Ranges may run at the same
 * time on different workers and in any order, so a job writes disjoint memory per range and
 * any sum over ranges is combined by the caller afterwards, in range order: the result is then
 * bit-identical for every worker count.
 *
 * Platforms: Linux: threads created at start-up and pinned one per core, the calling thread
 * being worker 0 (platform/linux/sc_pool_linux.h); host simulator: the same ranges run one
 * after the other on the caller, in reverse order, so a job that depended on the order would
 * show in the tests (platform/hostsim/sc_hs_pool.h); bare metal: none (NULL ops).
 *
 * Ops: run is mandatory when ops is non-NULL; workers is optional (absent: 1). NULL ops: the
 * wrapper runs the ranges in order on the caller. run never fails by contract: a pool that
 * cannot reach its workers runs the ranges itself. Never allocates at run time.
 * Threads: one caller at a time per pool; fn must not call run again (no nesting).
 */
#ifndef SC_HAL_POOL_H
#define SC_HAL_POOL_H

#include <stdint.h>

/* one range of a job: r in 0 .. ranges - 1 */
typedef void (*sc_pool_job_fn)(void *arg, uint32_t r);

typedef struct sc_pool_ops {
    /* mandatory: fn(arg, r) for every r < ranges, each exactly once; returns when all have */
    void (*run)(void *ctx, sc_pool_job_fn fn, void *arg, uint32_t ranges);
    /* optional: number of workers (the caller included), >= 1 */
    uint32_t (*workers)(void *ctx);
} sc_pool_ops;

typedef struct sc_pool_dev {
    const sc_pool_ops *ops;
    void *ctx;
} sc_pool_dev;

/* Run a job over `ranges` ranges (0: nothing). Cost: the ranges' work divided among the
 * workers, plus the platform's hand-over. NULL dev or ops: serial, in range order. */
static inline void sc_pool_run(const sc_pool_dev *dev, sc_pool_job_fn fn, void *arg,
                               uint32_t ranges)
{
    if (dev != 0 && dev->ops != 0 && dev->ops->run != 0 && ranges > 1u) {
        dev->ops->run(dev->ctx, fn, arg, ranges);
        return;
    }
    for (uint32_t r = 0; r < ranges; r++) {
        fn(arg, r);
    }
}

/* Number of workers, >= 1 (1 without a pool). O(1). */
static inline uint32_t sc_pool_workers(const sc_pool_dev *dev)
{
    if (dev == 0 || dev->ops == 0 || dev->ops->workers == 0) {
        return 1u;
    }
    const uint32_t w = dev->ops->workers(dev->ctx);
    return w == 0u ? 1u : w;
}

#endif /* SC_HAL_POOL_H */
