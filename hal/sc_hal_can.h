/*
 * sc_hal_can.h: the CAN controller contract the core needs.
 *
 * One ops table per device, the device handle first in every call (Zephyr's CAN API shape).
 * Mandatory ops: send, recv. Optional ops may be NULL and then answer SC_ERR_NOT_SUPPORTED.
 * Every op is non-blocking and bounded in time: the frame loop calls them from its deadline.
 * Thread rules: a device is used from one thread (the frame loop). The HAL never allocates on
 * behalf of the core; frames are copied into caller-owned storage.
 */
#ifndef SC_HAL_CAN_H
#define SC_HAL_CAN_H

#include <stddef.h>
#include <stdint.h>

#include "sc_err.h"

#define SC_CAN_MAX_DLEN 64u /* CAN FD payload; classic frames use at most 8 */

enum {
    SC_CAN_FLAG_EXT = 1u << 0, /* 29-bit identifier */
    SC_CAN_FLAG_FD = 1u << 1,  /* CAN FD frame */
    SC_CAN_FLAG_BRS = 1u << 2, /* FD bit-rate switch */
    SC_CAN_FLAG_RTR = 1u << 3, /* remote frame (classic only) */
    SC_CAN_FLAG_ERR = 1u << 4, /* error frame from the controller; id holds SC_CAN_ERRF_* */
};

/* Error-frame classes carried in sc_can_frame.id when SC_CAN_FLAG_ERR is set. */
enum {
    SC_CAN_ERRF_BUS_OFF = 1u << 0,
    SC_CAN_ERRF_PASSIVE = 1u << 1,
    SC_CAN_ERRF_WARNING = 1u << 2,
    SC_CAN_ERRF_CTRL = 1u << 3,     /* controller problem (overrun, ...) */
    SC_CAN_ERRF_PROTOCOL = 1u << 4, /* bit/stuff/form error seen on the bus */
    SC_CAN_ERRF_RESTARTED = 1u << 5,
};

typedef struct sc_can_frame {
    uint32_t id;      /* 11- or 29-bit identifier (or SC_CAN_ERRF_* with SC_CAN_FLAG_ERR) */
    uint8_t len;      /* payload bytes, 0..8 classic, 0..64 FD (valid FD lengths only) */
    uint8_t flags;    /* SC_CAN_FLAG_* */
    uint8_t pad_[2];
    uint64_t ts_ns;   /* receive time stamp on the HAL clock's time base, 0 if unknown */
    uint8_t data[SC_CAN_MAX_DLEN];
} sc_can_frame;

typedef struct sc_can_filter {
    uint32_t id;   /* match when (frame.id & mask) == (id & mask) */
    uint32_t mask;
    uint8_t flags; /* SC_CAN_FLAG_EXT to match extended ids */
} sc_can_filter;

typedef enum sc_can_state {
    SC_CAN_STATE_ERROR_ACTIVE = 0,
    SC_CAN_STATE_ERROR_WARNING,
    SC_CAN_STATE_ERROR_PASSIVE,
    SC_CAN_STATE_BUS_OFF,
    SC_CAN_STATE_STOPPED,
} sc_can_state;

typedef struct sc_can_counters {
    uint16_t tx_err;     /* transmit error counter (TEC), if the controller reports it */
    uint16_t rx_err;     /* receive error counter (REC) */
    uint32_t rx_dropped; /* frames lost in the receive path (queue full, kernel drops) */
    uint32_t tx_dropped; /* frames not sent (queue full, bus-off) */
} sc_can_counters;

typedef struct sc_can_ops {
    /* Queue one frame for transmission. O(1). SC_ERR_WOULD_BLOCK when the transmit queue is
     * full, SC_ERR_CAN_BUS_OFF when the controller is bus-off, SC_ERR_INVALID_ARG for a bad
     * length/flag combination. Mandatory. */
    int (*send)(void *ctx, const sc_can_frame *frame);
    /* Take the oldest received frame (data or error frame). O(1). SC_ERR_WOULD_BLOCK when none
     * is waiting. Mandatory. */
    int (*recv)(void *ctx, sc_can_frame *out);
    /* Replace the acceptance filters. SC_ERR_NO_SPACE above the device's capacity. Optional. */
    int (*set_filters)(void *ctx, const sc_can_filter *filters, size_t count);
    /* Bus state and error counters. Optional. */
    int (*get_state)(void *ctx, sc_can_state *state, sc_can_counters *counters);
} sc_can_ops;

typedef struct sc_can_dev {
    const sc_can_ops *ops;
    void *ctx;
} sc_can_dev;

static inline int sc_can_send(const sc_can_dev *dev, const sc_can_frame *frame)
{
    return dev->ops->send(dev->ctx, frame);
}

static inline int sc_can_recv(const sc_can_dev *dev, sc_can_frame *out)
{
    return dev->ops->recv(dev->ctx, out);
}

static inline int sc_can_set_filters(const sc_can_dev *dev, const sc_can_filter *filters,
                                     size_t count)
{
    return dev->ops->set_filters ? dev->ops->set_filters(dev->ctx, filters, count)
                                 : SC_ERR_NOT_SUPPORTED;
}

static inline int sc_can_get_state(const sc_can_dev *dev, sc_can_state *state,
                                   sc_can_counters *counters)
{
    return dev->ops->get_state ? dev->ops->get_state(dev->ctx, state, counters)
                               : SC_ERR_NOT_SUPPORTED;
}

/* Valid CAN FD payload lengths are 0..8, 12, 16, 20, 24, 32, 48, 64. */
static inline int sc_can_len_valid(uint8_t len, uint8_t flags)
{
    if (!(flags & SC_CAN_FLAG_FD)) {
        return len <= 8u;
    }
    return len <= 8u || len == 12u || len == 16u || len == 20u || len == 24u || len == 32u ||
           len == 48u || len == 64u;
}

#endif /* SC_HAL_CAN_H */
