/* sc_hs_rig.c: whole-engine host simulator rig, see sc_hs_rig.h. */
#include "sc_hs_rig.h"

#include <string.h>

#include "sc_err.h"

int sc_hs_rig_init(sc_hs_rig *rig, const sc_engine_def *def, uint64_t seed, int print_log)
{
    memset(rig, 0, sizeof(*rig));
    sc_hs_clock_init(&rig->clock, 1000000000u);
    rig->clock_dev = sc_hs_clock_dev(&rig->clock);
    sc_hs_can_bus_init(&rig->bus, &rig->clock_dev, seed);
    int en = sc_hs_can_add_node(&rig->bus);
    int pn = sc_hs_can_add_node(&rig->bus);
    if (en < 0 || pn < 0) {
        return SC_ERR_NO_SPACE;
    }
    rig->engine_node = (uint32_t)en;
    rig->peer_node = (uint32_t)pn;
    rig->peer = sc_hs_can_dev(&rig->bus, rig->peer_node);
    sc_hs_display_init(&rig->display);
    sc_hs_storage_init(&rig->storage);
    sc_hs_log_init(&rig->log, print_log);
    sc_hs_can_tap_init(&rig->tap, sc_hs_can_dev(&rig->bus, rig->engine_node), &rig->clock_dev,
                       NULL, NULL);
    rig->hal = (sc_hal){
        .clock = rig->clock_dev,
        .can = sc_hs_can_tap_dev(&rig->tap),
        .display = sc_hs_display_dev(&rig->display),
        .storage = sc_hs_storage_dev(&rig->storage),
        .log = sc_hs_log_dev(&rig->log),
        .watchdog = {0},
    };
    sc_hs_pool_init(&rig->pool, 1u, &rig->hal.pool);
    return sc_engine_init(&rig->engine, def, &rig->hal);
}
