/*
 * sc_hal_state.h: the state stream for the instructor console, off the real-time path.
 *
 * At the end of a frame (rate-limited, sc_engine_def.state_period_ms) the core fills a few
 * fixed, self-describing records (core/sc_state.h, docs/state-stream.md) into one bounded
 * buffer of its own and hands each to send(). The platform copies or transmits the bytes
 * during the call (UDP datagram on the appliance, a file or socket on the host simulator)
 * and returns at once: it never blocks, never retries; a record it cannot take is dropped
 * and counted by the core (SC_ERR_WOULD_BLOCK / SC_ERR_IO). Records carry a sequence number,
 * so a receiver sees what it lost; nothing depends on every record arriving.
 *
 * Optional device: a NULL ops pointer in sc_state_dev means "no state stream" and the core
 * fills nothing. The buffer passed to send() is owned by the core and valid during the call.
 *
 * Return values of send: SC_OK; SC_ERR_INVALID_ARG (NULL, len 0 or above
 * SC_STATE_RECORD_MAX); SC_ERR_WOULD_BLOCK / SC_ERR_IO (dropped, counted).
 */
#ifndef SC_HAL_STATE_H
#define SC_HAL_STATE_H

#include <stdint.h>

#include "sc_err.h"

typedef struct sc_state_ops {
    int (*send)(void *ctx, const uint8_t *rec, uint16_t len); /* mandatory when present */
} sc_state_ops;

typedef struct sc_state_dev {
    const sc_state_ops *ops;
    void *ctx;
} sc_state_dev;

/* SC_ERR_NOT_SUPPORTED when the device is absent. */
static inline int sc_state_send(const sc_state_dev *dev, const uint8_t *rec, uint16_t len)
{
    if (dev == 0 || dev->ops == 0 || dev->ops->send == 0) {
        return SC_ERR_NOT_SUPPORTED;
    }
    return dev->ops->send(dev->ctx, rec, len);
}

#endif /* SC_HAL_STATE_H */
