/*
 * sc_can_rxmb.h: a CAN controller's receive mailboxes in front of the engine, for the transports
 * whose own queue is one long FIFO (CAN over UDP, SocketCAN: the socket's buffer holds seconds
 * of tracker frames, and a command behind them waits for all of them).
 *
 * The platform drains its transport into the mailboxes every frame (sc_can_rxmb_put, nothing is
 * left in the socket), then the engine takes from them (sc_can_rxmb_take) as from a controller:
 *  - priority mailbox: the command block by CAN id (0x080..0x09F: commands, the freshness sync
 *    and their cryptographic PDUs) and controller error frames, a FIFO of SC_CAN_RXMB_PRIO_MAX,
 *    always taken first; a full one refuses the newest frame (counted: prio_dropped) and never
 *    overwrites a command;
 *  - stream ring: everything else (the probe's and the needle's pose frames at 100 Hz, unknown
 *    ids), a FIFO of def.stream_cap frames that overwrites its oldest frame when full (counted:
 *    stream_overwritten), so that the newest tracker poses win and a slow reader never lags
 *    behind by more than stream_cap frames. Overwritten pose frames reach the engine's E2E
 *    receiver as a counter gap, which it counts as it counts frames lost on a bus.
 * Nothing is lost uncounted: put = taken + prio_dropped + stream_overwritten + depth.
 * Order is kept within each class; a command may overtake pose frames that came before it
 * (the engine applies commands between frames, after the frame's poses, either way).
 *
 * Pure C, no OS call, no heap: fixed storage inside the object; one thread.
 */
#ifndef SC_CAN_RXMB_H
#define SC_CAN_RXMB_H

#include <stdint.h>

#include "sc_hal_can.h"

#ifndef SC_CAN_RXMB_PRIO_MAX
#define SC_CAN_RXMB_PRIO_MAX 64u
#endif
#ifndef SC_CAN_RXMB_STREAM_MAX
#define SC_CAN_RXMB_STREAM_MAX 256u
#endif

#define SC_CAN_RXMB_PRIO_ID_LO 0x080u /* the command block (docs/can-protocol.md) */
#define SC_CAN_RXMB_PRIO_ID_HI 0x09Fu

typedef struct sc_can_rxmb_def {
    uint32_t stream_cap; /* stream ring frames, 1..SC_CAN_RXMB_STREAM_MAX */
} sc_can_rxmb_def;

typedef struct sc_can_rxmb_counters {
    uint64_t put; /* frames offered */
    uint64_t prio_taken, stream_taken;
    uint64_t prio_dropped;                     /* priority mailbox full: the newest refused */
    uint64_t stream_overwritten;               /* the oldest stream frame replaced by a newer one */
    uint32_t prio_depth_max, stream_depth_max; /* deepest the mailboxes were after a put */
} sc_can_rxmb_counters;

typedef struct sc_can_rxmb {
    sc_can_rxmb_def def;
    uint32_t prio_head, prio_count;
    uint32_t stream_head, stream_count;
    sc_can_rxmb_counters c;
    sc_can_frame prio[SC_CAN_RXMB_PRIO_MAX];
    sc_can_frame stream[SC_CAN_RXMB_STREAM_MAX];
} sc_can_rxmb;

/* stream_cap 64 (SC_CAN_RX_BURST_MAX, what the engine takes in one frame). */
sc_can_rxmb_def sc_can_rxmb_default_def(void);
/* 0, or SC_ERR_RANGE for a stream_cap outside 1..SC_CAN_RXMB_STREAM_MAX. O(1). */
int sc_can_rxmb_init(sc_can_rxmb *mb, const sc_can_rxmb_def *def);
/* 1 for a frame of the priority mailbox (the command block's standard ids, error frames). */
int sc_can_rxmb_is_priority(const sc_can_frame *f);
/* Store one frame. 0; SC_ERR_NO_SPACE when the priority mailbox is full (the frame counted in
 * prio_dropped); a full stream ring overwrites its oldest frame and answers 0 (counted). O(1). */
int sc_can_rxmb_put(sc_can_rxmb *mb, const sc_can_frame *f);
/* Take the oldest priority frame, else the oldest stream frame. SC_ERR_WOULD_BLOCK when both
 * are empty. O(1). */
int sc_can_rxmb_take(sc_can_rxmb *mb, sc_can_frame *out);
/* Frames waiting (both mailboxes). */
uint32_t sc_can_rxmb_depth(const sc_can_rxmb *mb);

/* Move every frame waiting in src (its recv, until SC_ERR_WOULD_BLOCK) into mb, at most max;
 * stamp each with ts_ns when ts_ns is not 0. Returns the frames moved. O(max). */
uint32_t sc_can_rxmb_drain(sc_can_rxmb *mb, const sc_can_dev *src, uint32_t max, uint64_t ts_ns);

/* A device with the mailboxes in front of a transport's receive side: each recv drains src
 * (at most drain_max frames) and takes from the mailboxes; send, set_filters and get_state go
 * to src (get_state adds the mailboxes' losses to rx_dropped). The engine's device when the
 * transport is CAN over UDP (sonocomp --can-udp) or SocketCAN (sonocomp, the kernel's socket
 * queue being one FIFO too): frames keep the transport's receive stamps. */
typedef struct sc_can_rxmb_port {
    sc_can_rxmb mb;
    sc_can_dev src;
    uint32_t drain_max;
    uint64_t drain_limited; /* recv calls that stopped draining at drain_max */
} sc_can_rxmb_port;

/* 0, or SC_ERR_RANGE (def), SC_ERR_INVALID_ARG (no src, drain_max 0). */
int sc_can_rxmb_port_init(sc_can_rxmb_port *p, const sc_can_rxmb_def *def, sc_can_dev src,
                          uint32_t drain_max);
sc_can_dev sc_can_rxmb_port_dev(sc_can_rxmb_port *p);

#endif /* SC_CAN_RXMB_H */
