/*
 * sc_hs_can.h: an in-process CAN bus for the host simulator.
 *
 * Several nodes share one bus; each node is an sc_can_dev with a bounded receive queue
 * (SC_HS_CAN_QUEUE frames; a full queue drops and counts, as a controller FIFO overrun does)
 * and acceptance filters. A frame sent by one node is delivered to every other node whose
 * filters accept it. Fault injection on the bus, deterministic from a seed: drop, corrupt (one
 * payload bit flipped, as if it got past the controller's CRC: the E2E layer must catch it),
 * duplicate, delay (by a fixed virtual time), reorder (held back and delivered after the next
 * frame), and bus-off (sends fail, receivers get a bus-off error frame). Every injected fault
 * is counted so tests can check that the engine counted each one.
 * Time stamps and delays use the virtual clock. Storage is fixed; nothing allocates.
 */
#ifndef SC_HS_CAN_H
#define SC_HS_CAN_H

#include <stdint.h>

#include "sc_hal_can.h"
#include "sc_hal_clock.h"

#ifndef SC_HS_CAN_MAX_NODES
#define SC_HS_CAN_MAX_NODES 8u
#endif
#ifndef SC_HS_CAN_QUEUE
#define SC_HS_CAN_QUEUE 256u
#endif
#ifndef SC_HS_CAN_MAX_FILTERS
#define SC_HS_CAN_MAX_FILTERS 16u
#endif

typedef struct sc_hs_can_faults {
    uint32_t drop_ppm;      /* probability per frame, parts per million */
    uint32_t corrupt_ppm;
    uint32_t duplicate_ppm;
    uint32_t reorder_ppm;
    uint64_t delay_ns;      /* added to every delivery */
} sc_hs_can_faults;

typedef struct sc_hs_can_injected {
    uint64_t sent;          /* frames offered to the bus */
    uint64_t dropped;
    uint64_t corrupted;
    uint64_t duplicated;
    uint64_t reordered;
    uint64_t error_frames;  /* error frames generated (bus-off) */
} sc_hs_can_injected;

struct sc_hs_can_bus;

typedef struct sc_hs_can_slot {
    sc_can_frame frame;
    uint64_t deliver_at_ns;
} sc_hs_can_slot;

typedef struct sc_hs_can_node {
    struct sc_hs_can_bus *bus;
    uint32_t index;
    uint32_t head, count;   /* ring of received frames */
    sc_hs_can_slot queue[SC_HS_CAN_QUEUE];
    sc_can_filter filters[SC_HS_CAN_MAX_FILTERS];
    uint32_t filter_count;  /* 0: accept all */
    uint64_t rx_frames, tx_frames;
    uint64_t rx_filtered;   /* frames its acceptance filters kept out */
    uint32_t rx_overruns;
    uint32_t tx_refused;
} sc_hs_can_node;

typedef struct sc_hs_can_bus {
    const sc_clock_dev *clock;
    sc_hs_can_node nodes[SC_HS_CAN_MAX_NODES];
    uint32_t node_count;
    sc_hs_can_faults faults;
    sc_hs_can_injected injected;                         /* all traffic */
    sc_hs_can_injected by_sender[SC_HS_CAN_MAX_NODES];   /* per sending node */
    uint64_t rng;
    uint8_t bus_off;
    uint8_t held_valid;     /* a frame held back for reordering */
    uint32_t held_from;
    sc_can_frame held;
} sc_hs_can_bus;

void sc_hs_can_bus_init(sc_hs_can_bus *bus, const sc_clock_dev *clock, uint64_t seed);
/* Add a node; returns its index or a negative sc_err (SC_ERR_NO_SPACE). */
int sc_hs_can_add_node(sc_hs_can_bus *bus);
sc_can_dev sc_hs_can_dev(sc_hs_can_bus *bus, uint32_t node);
void sc_hs_can_set_faults(sc_hs_can_bus *bus, const sc_hs_can_faults *faults);
/* Enter or leave bus-off. Entering sends a bus-off error frame to every node. */
void sc_hs_can_set_bus_off(sc_hs_can_bus *bus, int bus_off);
/* Put a frame straight into one node's receive queue, bypassing faults and filters, with the
 * given time stamp; it is delivered at once. For replaying a recording. SC_ERR_NO_SPACE when
 * the queue is full (counted as an overrun). */
int sc_hs_can_inject(sc_hs_can_bus *bus, uint32_t node, const sc_can_frame *frame);
/* Deliver a frame held back for reordering (call at the end of a test's traffic). */
void sc_hs_can_flush(sc_hs_can_bus *bus);

#endif /* SC_HS_CAN_H */
