/* sc_engine.c: the engine object and its frame stages, see sc_engine.h. */
#include "sc_engine.h"

#include "sc_assert.h"
#include "sc_err.h"

sc_engine_def sc_engine_default_def(void)
{
    return (sc_engine_def){.sched = sc_sched_default_def(), .watchdog_timeout_ms = 500u};
}

static void handle_error_frame(sc_engine *e, const sc_can_frame *f)
{
    e->counters.can_rx_error_frames++;
    if (f->id & SC_CAN_ERRF_BUS_OFF) {
        sc_health_raise(&e->health, SC_FAULT_CAN_BUS_OFF);
        sc_log(&e->hal->log, SC_LOG_ERROR, "can_bus_off", SC_ERR_CAN_BUS_OFF, 0, 0);
    }
    if (f->id & (SC_CAN_ERRF_PASSIVE | SC_CAN_ERRF_WARNING)) {
        sc_health_raise(&e->health, SC_FAULT_CAN_PASSIVE);
    }
    if (f->id & SC_CAN_ERRF_RESTARTED) {
        sc_health_clear(&e->health, SC_FAULT_CAN_BUS_OFF);
        sc_health_clear(&e->health, SC_FAULT_CAN_PASSIVE);
        sc_log(&e->hal->log, SC_LOG_INFO, "can_restarted", SC_OK, 0, 0);
    }
}

/* Stage 1: drain the CAN receive queue, bounded by SC_CAN_RX_BURST_MAX frames. */
static void stage_can_rx(void *user)
{
    sc_engine *e = user;
    sc_can_frame f;
    uint32_t n = 0;
    for (; n < SC_CAN_RX_BURST_MAX; n++) {
        if (sc_can_recv(&e->hal->can, &f) != SC_OK) {
            break;
        }
        if (f.flags & SC_CAN_FLAG_ERR) {
            handle_error_frame(e, &f);
            continue;
        }
        e->counters.can_rx_frames++;
    }
    if (n == SC_CAN_RX_BURST_MAX) {
        e->counters.can_rx_burst_limited++;
    }
    sc_can_state st;
    if (sc_can_get_state(&e->hal->can, &st, 0) == SC_OK) {
        e->can_state = st;
        sc_health_set(&e->health, SC_FAULT_CAN_BUS_OFF, st == SC_CAN_STATE_BUS_OFF);
        sc_health_set(&e->health, SC_FAULT_CAN_PASSIVE,
                      st == SC_CAN_STATE_ERROR_PASSIVE || st == SC_CAN_STATE_ERROR_WARNING);
    }
}

int sc_engine_init(sc_engine *e, const sc_engine_def *def, const sc_hal *hal)
{
    if (!e || !def || !hal || !hal->clock.ops || !hal->can.ops || !hal->can.ops->send ||
        !hal->can.ops->recv || !hal->display.ops || !hal->storage.ops) {
        return SC_ERR_INVALID_ARG;
    }
    *e = (sc_engine){0};
    e->hal = hal;
    e->def = *def;
    sc_health_init(&e->health);
    int rc = sc_sched_init(&e->sched, &def->sched, &hal->clock);
    if (rc != SC_OK) {
        return rc;
    }
    rc = sc_sched_add_stage(&e->sched, "can_rx", stage_can_rx);
    if (rc != SC_OK) {
        return rc;
    }
    if (def->watchdog_timeout_ms) {
        rc = sc_watchdog_start(&hal->watchdog, def->watchdog_timeout_ms);
        if (rc != SC_OK) {
            sc_health_raise(&e->health, SC_FAULT_WATCHDOG);
            sc_log(&hal->log, SC_LOG_WARN, "watchdog_unavailable", rc, 0, 0);
        }
    }
    sc_health_set_ready(&e->health, 1);
    return SC_OK;
}

int sc_engine_add_stage(sc_engine *e, const char *name, sc_stage_fn fn)
{
    return sc_sched_add_stage(&e->sched, name, fn);
}

void sc_engine_step(sc_engine *e, sc_frame_result *out)
{
    SC_ASSERT(e && e->hal);
    sc_frame_result r;
    sc_sched_run_frame(&e->sched, e, &r);
    if (r.missed) {
        sc_log(&e->hal->log, SC_LOG_WARN, "deadline_miss", SC_ERR_TIMEOUT,
               (int64_t)(r.end_ns - r.release_ns), (int64_t)r.periods_skipped);
    }
    sc_health_set(&e->health, SC_FAULT_DEADLINE,
                  sc_sched_recent_misses(&e->sched, SC_HEALTH_MISS_WINDOW) >=
                      SC_HEALTH_MISS_DEGRADED);
    if (!sc_health_is_active(&e->health, SC_FAULT_WATCHDOG) &&
        sc_watchdog_kick(&e->hal->watchdog) == SC_OK) {
        e->counters.watchdog_kicks++;
    }
    if (out) {
        *out = r;
    }
}

void sc_engine_get_status(const sc_engine *e, sc_engine_status *out)
{
    *out = (sc_engine_status){
        .state = e->health.state,
        .faults = e->health.active,
        .frames = e->sched.frames,
        .misses = e->sched.misses,
        .worst_frame_ns = e->sched.frame_stats.worst_ns,
        .p99_frame_ns = sc_stats_percentile_ns(&e->sched.frame_stats, 990u),
    };
}
