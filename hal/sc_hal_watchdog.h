/*
 * sc_hal_watchdog.h: the watchdog the frame loop feeds.
 *
 * start arms it with a timeout; kick feeds it once per completed frame. On the appliance this
 * is the kernel watchdog device; on a host a software one; both optional (NULL ops: the
 * wrappers answer SC_ERR_NOT_SUPPORTED and the engine runs unguarded, which it reports).
 */
#ifndef SC_HAL_WATCHDOG_H
#define SC_HAL_WATCHDOG_H

#include <stdint.h>

#include "sc_err.h"

typedef struct sc_watchdog_ops {
    int (*start)(void *ctx, uint32_t timeout_ms);
    int (*kick)(void *ctx);
} sc_watchdog_ops;

typedef struct sc_watchdog_dev {
    const sc_watchdog_ops *ops;
    void *ctx;
} sc_watchdog_dev;

static inline int sc_watchdog_start(const sc_watchdog_dev *dev, uint32_t timeout_ms)
{
    return (dev && dev->ops && dev->ops->start) ? dev->ops->start(dev->ctx, timeout_ms)
                                                : SC_ERR_NOT_SUPPORTED;
}

static inline int sc_watchdog_kick(const sc_watchdog_dev *dev)
{
    return (dev && dev->ops && dev->ops->kick) ? dev->ops->kick(dev->ctx) : SC_ERR_NOT_SUPPORTED;
}

#endif /* SC_HAL_WATCHDOG_H */
