/*
 * sc_hal.h: the set of devices one engine instance talks to. The platform fills it and
 * keeps it alive as long as the engine runs; the core only reads it.
 */
#ifndef SC_HAL_H
#define SC_HAL_H

#include "sc_hal_can.h"
#include "sc_hal_clock.h"
#include "sc_hal_display.h"
#include "sc_hal_log.h"
#include "sc_hal_state.h"
#include "sc_hal_pool.h"
#include "sc_hal_storage.h"
#include "sc_hal_watchdog.h"

typedef struct sc_hal {
    sc_clock_dev clock;       /* mandatory */
    sc_can_dev can;           /* mandatory */
    sc_display_dev display;   /* mandatory */
    sc_storage_dev storage;   /* mandatory */
    sc_log_dev log;           /* ops may be NULL: no log */
    sc_watchdog_dev watchdog; /* ops may be NULL: unguarded */
    sc_state_dev state;       /* ops may be NULL: no state stream (console) */
    sc_pool_dev pool;         /* ops may be NULL: one worker, the loops run serially */
} sc_hal;

#endif /* SC_HAL_H */
