/* sc_hs_pool.c: the host simulator's serial worker pool, see sc_hs_pool.h. */
#include "sc_hs_pool.h"

#include <stddef.h>

static void hs_run(void *ctx, sc_pool_job_fn fn, void *arg, uint32_t ranges)
{
    sc_hs_pool *p = (sc_hs_pool *)ctx;
    p->jobs++;
    for (uint32_t w = p->workers; w-- > 0u;) {
        for (uint32_t r = w; r < ranges; r += p->workers) {
            fn(arg, r);
            p->ranges++;
        }
    }
}

static uint32_t hs_workers(void *ctx)
{
    return ((const sc_hs_pool *)ctx)->workers;
}

static const sc_pool_ops k_hs_pool_ops = {.run = hs_run, .workers = hs_workers};

void sc_hs_pool_init(sc_hs_pool *p, uint32_t workers, sc_pool_dev *dev)
{
    p->workers =
        workers < 1u ? 1u : (workers > SC_HS_POOL_MAX_WORKERS ? SC_HS_POOL_MAX_WORKERS : workers);
    p->jobs = 0u;
    p->ranges = 0u;
    dev->ops = &k_hs_pool_ops;
    dev->ctx = p;
}
