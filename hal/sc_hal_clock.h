/*
 * sc_hal_clock.h: the monotonic clock and absolute sleep.
 *
 * now_ns: monotonic nanoseconds since an arbitrary epoch, never decreasing. O(1).
 * sleep_until_ns: return at or after the absolute time t_ns on the same base; returns at once
 * when t_ns is in the past. On Linux: clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME). On the
 * host simulator the clock is virtual: sleep_until_ns moves it forward, and nothing else does
 * unless a test says so, so deadline logic is testable without wall time.
 * Both are mandatory.
 */
#ifndef SC_HAL_CLOCK_H
#define SC_HAL_CLOCK_H

#include <stdint.h>

typedef struct sc_clock_ops {
    uint64_t (*now_ns)(void *ctx);
    int (*sleep_until_ns)(void *ctx, uint64_t t_ns);
} sc_clock_ops;

typedef struct sc_clock_dev {
    const sc_clock_ops *ops;
    void *ctx;
} sc_clock_dev;

static inline uint64_t sc_clock_now_ns(const sc_clock_dev *dev)
{
    return dev->ops->now_ns(dev->ctx);
}

static inline int sc_clock_sleep_until_ns(const sc_clock_dev *dev, uint64_t t_ns)
{
    return dev->ops->sleep_until_ns(dev->ctx, t_ns);
}

#endif /* SC_HAL_CLOCK_H */
