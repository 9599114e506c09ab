/*
 * sc_hs_rig.h: a whole engine on the host simulator: virtual clock, a CAN bus with the
 * engine's node and a peer node (the tracker / test bench), the display recorder, storage and
 * log, wired into an sc_hal and one sc_engine. Integration tests and the host runner use it.
 * The engine's CAN device is the bus node seen through a tap (sc_hs_can_tap.h), so every
 * frame the engine takes carries its time of reception and can be recorded for replay.
 * The platform may replace hal.storage before loading a case (the host runner maps files).
 * The rig is large (the engine and the display recorder hold full-size buffers): place it in
 * static storage or allocate it once before the frames start.
 */
#ifndef SC_HS_RIG_H
#define SC_HS_RIG_H

#include "sc_engine.h"
#include "sc_hs_can.h"
#include "sc_hs_can_tap.h"
#include "sc_hs_clock.h"
#include "sc_hs_display.h"
#include "sc_hs_log.h"
#include "sc_hs_pool.h"
#include "sc_hs_storage.h"

typedef struct sc_hs_rig {
    sc_hs_clock clock;
    sc_clock_dev clock_dev;
    sc_hs_can_bus bus;
    uint32_t engine_node; /* bus node of the engine */
    uint32_t peer_node;   /* bus node of the tracker emulator / bench */
    sc_can_dev peer;      /* the peer's device */
    sc_hs_can_tap tap;    /* between the engine and its bus node: stamps reception times and
                           * reports each received frame (set tap.fn to record) */
    sc_hs_display display;
    sc_hs_storage storage;
    sc_hs_log log;
    sc_hs_pool pool; /* 1 worker; sc_hs_pool_init(&rig->pool, w, &rig->hal.pool) before a case
                        load runs its solvers' ranges as w workers would take them */
    sc_hal hal;
    sc_engine engine;
} sc_hs_rig;

/* Build the rig and initialise the engine with def. Returns the engine's init result. */
int sc_hs_rig_init(sc_hs_rig *rig, const sc_engine_def *def, uint64_t seed, int print_log);

#endif /* SC_HS_RIG_H */
