/* sc_engine.c: the engine object and its frame stages, see sc_engine.h. */
#include "sc_engine.h"

#include <string.h>

#include "sc_assert.h"
#include "sc_err.h"
#include "sc_labels.h"

#define NS_PER_MS 1000000ull

/* Skin patch margin around the mesh box's top face. */
#define SC_ENGINE_SKIN_MARGIN_MM 10.0f

/* Case id reported for a case loaded by a name that is not in the catalogue. */
#define SC_ENGINE_CASE_UNLISTED 254u

sc_engine_def sc_engine_default_def(void)
{
    sc_engine_def d;
    memset(&d, 0, sizeof(d));
    d.sched = sc_sched_default_def();
    d.watchdog_timeout_ms = 500u;
    d.status_period_ms = 100u;
    d.tracker_fault_hold_ms = 1000u;
    d.phys_fault_hold_ms = 1000u;
    d.phys_resets_fatal = 5u;
    d.tracker = sc_tracker_default_def();
    d.tissue = sc_tissue_default_def();
    d.bscan = sc_bscan_default_def();
    d.case_count = 0u;
    return d;
}

static uint64_t now_ns(const sc_engine *e)
{
    return sc_clock_now_ns(&e->hal->clock);
}

/* ---- commands ------------------------------------------------------------------------------ */

static int apply_imaging(sc_engine *e, const sc_imaging_cmd *c)
{
    sc_bscan_def d = e->bscan.def;
    const sc_xform calib = d.scan.image_to_probe;
    if (c->geometry == SC_SCAN_CURVILINEAR && d.scan.kind != SC_SCAN_CURVILINEAR) {
        d.scan = sc_scan_curvilinear_default_def();
    } else if (c->geometry == SC_SCAN_LINEAR && d.scan.kind != SC_SCAN_LINEAR) {
        d.scan = sc_scan_default_def();
    }
    d.scan.image_to_probe = calib;
    d.scan.depth_mm = c->depth_mm;
    d.gain_db = c->gain_db;
    d.dynamic_range_db = c->dyn_range_db;
    /* TGC as a slope: each band gets the slope times its centre depth */
    for (uint32_t b = 0; b < SC_BSCAN_TGC_BANDS; b++) {
        const float centre_cm = 0.1f * c->depth_mm * ((float)b + 0.5f) / (float)SC_BSCAN_TGC_BANDS;
        d.tgc_db[b] = c->tgc_db_per_cm * centre_cm;
    }
    return sc_bscan_set_def(&e->bscan, &d);
}

static void apply_command(sc_engine *e, const sc_cmd *c)
{
    int rc = SC_OK;
    switch (c->kind) {
    case SC_CMD_SELECT_CASE:
        if (c->case_id >= e->def.case_count || !e->def.case_names[c->case_id]) {
            rc = SC_ERR_NOT_FOUND;
        } else {
            rc = sc_engine_load_case(e, e->def.case_names[c->case_id]);
        }
        break;
    case SC_CMD_SET_METHOD:
        e->def.tissue.method = c->method == SC_METHOD_FEM ? SC_TISSUE_FEM : SC_TISSUE_MSDS;
        if (e->case_loaded) {
            rc = sc_tissue_set_method(&e->tissue, e->def.tissue.method);
        }
        break;
    case SC_CMD_SET_IMAGING:
        rc = apply_imaging(e, &c->imaging);
        break;
    case SC_CMD_RESET:
        if (c->reset_target & SC_RESET_TISSUE) {
            if (e->case_loaded) {
                sc_tissue_reset(&e->tissue);
            }
        }
        if (c->reset_target & SC_RESET_FAULTS) {
            sc_health_clear(&e->health, SC_FAULT_PHYS_REPEATED);
            sc_health_clear(&e->health, SC_FAULT_CONFIG);
            e->phys_resets_window = 0;
        }
        break;
    }
    if (rc == SC_OK) {
        e->counters.commands_applied++;
        sc_health_clear(&e->health, SC_FAULT_CONFIG);
        sc_log(&e->hal->log, SC_LOG_INFO, "command_applied", SC_OK, (int64_t)c->kind, 0);
    } else {
        e->counters.commands_refused++;
        sc_health_raise(&e->health, SC_FAULT_CONFIG);
        sc_log(&e->hal->log, SC_LOG_WARN, "command_refused", rc, (int64_t)c->kind, 0);
    }
}

/* ---- stage: CAN receive, commands, pose --------------------------------------------------- */

static void take_bus_errors(sc_engine *e)
{
    const uint32_t be = sc_tracker_take_bus_errors(&e->tracker);
    if (be & SC_CAN_ERRF_BUS_OFF) {
        sc_health_raise(&e->health, SC_FAULT_CAN_BUS_OFF);
        sc_log(&e->hal->log, SC_LOG_ERROR, "can_bus_off", SC_ERR_CAN_BUS_OFF, 0, 0);
    }
    if (be & (SC_CAN_ERRF_PASSIVE | SC_CAN_ERRF_WARNING)) {
        sc_health_raise(&e->health, SC_FAULT_CAN_PASSIVE);
    }
    if (be & SC_CAN_ERRF_RESTARTED) {
        sc_health_clear(&e->health, SC_FAULT_CAN_BUS_OFF);
        sc_health_clear(&e->health, SC_FAULT_CAN_PASSIVE);
        sc_log(&e->hal->log, SC_LOG_INFO, "can_restarted", SC_OK, 0, 0);
    }
    sc_can_state st;
    if (sc_can_get_state(&e->hal->can, &st, NULL) == SC_OK) {
        sc_health_set(&e->health, SC_FAULT_CAN_BUS_OFF, st == SC_CAN_STATE_BUS_OFF);
        sc_health_set(&e->health, SC_FAULT_CAN_PASSIVE,
                      st == SC_CAN_STATE_ERROR_PASSIVE || st == SC_CAN_STATE_ERROR_WARNING);
    }
}

static void update_tracker_faults(sc_engine *e, uint64_t now)
{
    const sc_trk_counters *n = sc_tracker_counters(&e->tracker);
    const uint32_t rejects = sc_tracker_rejected_e2e(&e->tracker) +
                             sc_tracker_rejected_implausible(&e->tracker) +
                             n->outcome[SC_TRK_BAD_LENGTH] + n->outcome[SC_TRK_POSE_STALE] +
                             n->outcome[SC_TRK_CMD_REJECTED];
    if (rejects != e->tracker_rejects_seen) {
        e->tracker_rejects_seen = rejects;
        e->last_tracker_reject_ns = now;
    }
    const int recent = rejects != 0u && now - e->last_tracker_reject_ns <
                                            (uint64_t)e->def.tracker_fault_hold_ms * NS_PER_MS;
    sc_health_set(&e->health, SC_FAULT_TRACKER_DATA, recent);
    sc_health_set(&e->health, SC_FAULT_TRACKER_TIMEOUT, !e->probe_tracked);
}

static void stage_rx(void *user)
{
    sc_engine *e = user;
    const uint64_t now = now_ns(e);
    sc_can_frame f;
    uint32_t n = 0;
    for (; n < SC_CAN_RX_BURST_MAX; n++) {
        if (sc_can_recv(&e->hal->can, &f) != SC_OK) {
            break;
        }
        e->counters.can_rx_frames++;
        (void)sc_tracker_on_frame(&e->tracker, &f, now);
    }
    if (n == SC_CAN_RX_BURST_MAX) {
        e->counters.can_rx_burst_limited++;
    }
    take_bus_errors(e);

    sc_cmd cmd;
    while (sc_tracker_take_command(&e->tracker, &cmd) == SC_OK) {
        apply_command(e, &cmd);
    }

    sc_pose pose;
    int tracked = 0;
    e->probe_tracked = 0;
    if (sc_tracker_poll(&e->tracker, now, &pose, &tracked) == SC_OK && tracked) {
        e->probe_tracked = 1;
        e->probe_tracker = pose;
        if (e->case_loaded) {
            const sc_xform t = sc_xform_from_pose(&pose);
            e->probe_to_volume = sc_xform_compose(&e->slot.c.tracker_to_volume, &t);
            e->probe_volume = sc_pose_from_xform(&e->probe_to_volume);
        }
    }
    update_tracker_faults(e, now);
}

/* ---- stage: physics ------------------------------------------------------------------------ */

static void stage_physics(void *user)
{
    sc_engine *e = user;
    if (!e->case_loaded) {
        return;
    }
    const uint64_t now = now_ns(e);
    const int frozen = sc_health_is_active(&e->health, SC_FAULT_PHYS_REPEATED);
    const sc_pose *probe = (e->probe_tracked && !frozen) ? &e->probe_volume : NULL;
    const int rc = sc_tissue_step(&e->tissue, probe);
    if (rc == SC_ERR_PHYS_UNSTABLE) {
        e->counters.phys_resets++;
        e->last_phys_reset_ns = now;
        const uint64_t window = 10u * (uint64_t)e->def.phys_fault_hold_ms * NS_PER_MS;
        if (e->phys_resets_window == 0u || now - e->phys_window_start_ns > window) {
            e->phys_window_start_ns = now;
            e->phys_resets_window = 0;
        }
        e->phys_resets_window++;
        if (e->phys_resets_window >= e->def.phys_resets_fatal) {
            sc_health_raise(&e->health, SC_FAULT_PHYS_REPEATED);
        }
        sc_log(&e->hal->log, SC_LOG_ERROR, "tissue_reset", rc, (int64_t)e->counters.phys_resets,
               (int64_t)e->tissue.stats.last_fault); /* sc_tissue_guard: why */
    }
    const int unstable = e->counters.phys_resets != 0u &&
                         now - e->last_phys_reset_ns <
                             (uint64_t)e->def.phys_fault_hold_ms * NS_PER_MS;
    sc_health_set(&e->health, SC_FAULT_PHYS_UNSTABLE, unstable);
    if (frozen && !unstable) {
        /* recovery without a person: a hold time without a reset (the tissue ran at rest,
         * without the probe) ends the freeze; the resets stay counted and logged */
        sc_health_clear(&e->health, SC_FAULT_PHYS_REPEATED);
        e->phys_resets_window = 0;
    }
    e->probe_contact = (uint8_t)(probe != NULL && e->tissue.stats.contacts > 0u);
}

/* ---- stage: imaging ------------------------------------------------------------------------ */

static void stage_imaging(void *user)
{
    sc_engine *e = user;
    if (!e->case_loaded) {
        return;
    }
    const int rc = sc_bscan_frame(&e->bscan, &e->tissue.mesh, &e->tissue.nodes, &e->slot.c.volume,
                                  &e->probe_to_volume, e->probe_contact, &e->hal->display,
                                  e->frame_no);
    if (rc != SC_OK) {
        e->counters.imaging_errors++;
    }
    sc_display_link_state ls;
    if (sc_display_get_link_state(&e->hal->display, &ls) == SC_OK) {
        sc_health_set(&e->health, SC_FAULT_DISPLAY_LINK, !ls.up);
    }
}

/* ---- stage: status ------------------------------------------------------------------------- */

static float area_ratio(const sc_engine *e, uint32_t label)
{
    const sc_bscan_status *b = sc_bscan_status_get(&e->bscan);
    if (!e->case_loaded || !b->areas_valid || b->area_ratio[label] < 0.0f) {
        return SC_AREA_RATIO_NOT_AVAILABLE;
    }
    return b->area_ratio[label];
}

static void stage_status(void *user)
{
    sc_engine *e = user;
    const uint64_t now = now_ns(e);
    if (now < e->next_status_ns) {
        return;
    }
    const uint64_t period = (uint64_t)e->def.status_period_ms * NS_PER_MS;
    e->next_status_ns = e->next_status_ns + period > now ? e->next_status_ns + period
                                                         : now + period;
    const uint64_t worst_us = e->sched.frame_stats.worst_ns / 1000u;
    sc_status_msg s = {
        .state = (uint8_t)e->health.state,
        .method = e->def.tissue.method == SC_TISSUE_FEM ? SC_METHOD_FEM : SC_METHOD_MSDS,
        .probe_contact = e->probe_contact,
        .probe_lifted = (uint8_t)!e->probe_tracked,
        .fault_bits = (uint16_t)e->health.active,
        .deadline_misses = (uint32_t)(e->sched.misses > UINT32_MAX ? UINT32_MAX
                                                                   : e->sched.misses),
        .case_id = e->case_loaded ? e->case_id : (uint8_t)SC_STATUS_CASE_NONE,
        .worst_frame_us = (uint32_t)(worst_us > UINT32_MAX ? UINT32_MAX : worst_us),
        .vein_area_ratio = area_ratio(e, SC_LABEL_VEIN),
        .artery_area_ratio = area_ratio(e, SC_LABEL_ARTERY),
    };
    sc_can_frame out[SC_STATUS_FRAMES];
    if (sc_tracker_encode_status(&e->tracker, &s, out) != SC_OK) {
        e->counters.can_tx_failed += SC_STATUS_FRAMES;
        return;
    }
    for (uint32_t i = 0; i < SC_STATUS_FRAMES; i++) {
        if (sc_can_send(&e->hal->can, &out[i]) != SC_OK) {
            e->counters.can_tx_failed++;
        }
    }
}

/* ---- init, case load, frame ---------------------------------------------------------------- */

static int set_filters(sc_engine *e)
{
    /* the protocol's receive ids: commands 0x080..0x083, classic pose 0x100..0x103 (0x103 is
     * unused and rejected by the tracker), FD pose 0x110 */
    const sc_can_filter f[] = {
        {.id = SC_CANID_CMD_CASE, .mask = 0x7FCu, .flags = 0},
        {.id = SC_CANID_POSE_POS, .mask = 0x7FCu, .flags = 0},
        {.id = SC_CANID_POSE_FD, .mask = 0x7FFu, .flags = 0},
    };
    const int rc = sc_can_set_filters(&e->hal->can, f, SC_COUNT_OF(f));
    return rc == SC_ERR_NOT_SUPPORTED ? SC_OK : rc;
}

/* No case runs: the status says none, the probe transform is valid (the imaging stage streams
 * dark frames before the first pose), SC_FAULT_NO_CASE is raised. */
static void set_no_case(sc_engine *e)
{
    e->case_loaded = 0;
    e->case_id = (uint8_t)SC_STATUS_CASE_NONE;
    e->probe_to_volume = sc_xform_identity();
    e->probe_volume = sc_pose_identity();
    e->probe_tracker = sc_pose_identity();
    sc_health_raise(&e->health, SC_FAULT_NO_CASE);
}

int sc_engine_init(sc_engine *e, const sc_engine_def *def, const sc_hal *hal)
{
    if (!e || !def || !hal || !hal->clock.ops || !hal->can.ops || !hal->can.ops->send ||
        !hal->can.ops->recv || !hal->display.ops || !hal->storage.ops ||
        def->case_count > SC_ENGINE_MAX_CASES) {
        return SC_ERR_INVALID_ARG;
    }
    if (def->status_period_ms < 10u || def->status_period_ms > 10000u ||
        def->tracker_fault_hold_ms > 60000u || def->phys_fault_hold_ms > 60000u ||
        def->phys_resets_fatal == 0u) {
        return SC_ERR_RANGE;
    }
    memset(e, 0, offsetof(sc_engine, bscan)); /* the big members are set up by their inits */
    e->hal = hal;
    e->def = *def;
    sc_health_init(&e->health);
    int rc = sc_sched_init(&e->sched, &def->sched, &hal->clock);
    if (rc == SC_OK) {
        rc = sc_tracker_init(&e->tracker, &def->tracker);
    }
    if (rc == SC_OK) {
        rc = sc_bscan_init(&e->bscan, &def->bscan);
    }
    if (rc == SC_OK) {
        rc = sc_sched_add_stage(&e->sched, "rx", stage_rx);
    }
    if (rc == SC_OK) {
        rc = sc_sched_add_stage(&e->sched, "physics", stage_physics);
    }
    if (rc == SC_OK) {
        rc = sc_sched_add_stage(&e->sched, "imaging", stage_imaging);
    }
    if (rc == SC_OK) {
        rc = sc_sched_add_stage(&e->sched, "status", stage_status);
    }
    if (rc == SC_OK) {
        rc = set_filters(e);
    }
    if (rc != SC_OK) {
        return rc;
    }
    if (def->watchdog_timeout_ms) {
        const int wrc = sc_watchdog_start(&hal->watchdog, def->watchdog_timeout_ms);
        if (wrc != SC_OK) {
            sc_health_raise(&e->health, SC_FAULT_WATCHDOG);
            sc_log(&hal->log, SC_LOG_WARN, "watchdog_unavailable", wrc, 0, 0);
        }
    }
    sc_case_slot_init(&e->slot);
    set_no_case(e);
    sc_health_set_ready(&e->health, 1);
    return SC_OK;
}

static uint8_t catalogue_id(const sc_engine *e, const char *name)
{
    for (uint32_t i = 0; i < e->def.case_count; i++) {
        if (e->def.case_names[i] && strcmp(e->def.case_names[i], name) == 0) {
            return (uint8_t)i;
        }
    }
    return (uint8_t)SC_ENGINE_CASE_UNLISTED;
}


int sc_engine_load_case(sc_engine *e, const char *name)
{
    if (!e || !name) {
        return SC_ERR_INVALID_ARG;
    }
    /* open, validate, and only then replace the running case's mapping (sc_case_slot) */
    int rc = sc_case_slot_switch(&e->slot, &e->hal->storage, name);
    if (rc != SC_OK) {
        /* refused before anything of the running case was touched */
        e->counters.case_load_failures++;
        e->counters.last_case_error = rc;
        sc_log(&e->hal->log, SC_LOG_ERROR, "case_refused", rc, 0, 0);
        return rc;
    }
    const sc_case *c = &e->slot.c;

    /* The case is valid: rebuild the tissue and attach imaging. Limits were checked by the
     * loader, so this fails only on a capacity the loader cannot see (then no case runs). */
    sc_material_table mat;
    memset(&mat, 0, sizeof(mat));
    mat.count = c->material_count;
    for (uint32_t i = 0; i < c->material_count; i++) {
        mat.row[i] = (sc_material){.e_pa = c->materials[i].e_pa,
                                   .poisson = c->materials[i].poisson,
                                   .density_kg_m3 = c->materials[i].density_kg_m3};
    }
    sc_tissue_def td = e->def.tissue;
    td.mesh = c->mesh;
    /* the skin surface: over the top of the mesh box and a margin around it, so that its
     * deformation has no edge where the tissue mesh ends (paper section V) */
    for (uint32_t a = 0; a < 2u; a++) {
        td.skin.origin_mm[a] = c->mesh.origin_mm[a] - SC_ENGINE_SKIN_MARGIN_MM;
        td.skin.size_mm[a] = c->mesh.size_mm[a] + 2.0f * SC_ENGINE_SKIN_MARGIN_MM;
    }
    td.skin.z_mm = c->mesh.origin_mm[2];
    rc = sc_tissue_init(&e->tissue, &td, &c->volume, &mat, (uint8_t)SC_LABEL_FAT);
    if (rc == SC_OK) {
        sc_bscan_def bd = e->bscan.def;
        bd.scan.image_to_probe = c->image_to_probe;
        rc = sc_bscan_set_def(&e->bscan, &bd);
    }
    if (rc == SC_OK) {
        rc = sc_bscan_attach_mesh(&e->bscan, &e->tissue.mesh);
    }
    if (rc != SC_OK) {
        /* the previous tissue is gone: no case runs */
        sc_case_slot_close(&e->slot);
        set_no_case(e);
        e->counters.case_load_failures++;
        e->counters.last_case_error = rc;
        sc_log(&e->hal->log, SC_LOG_ERROR, "case_rebuild_failed", rc, 0, 0);
        return rc;
    }
    e->case_loaded = 1;
    e->case_id = catalogue_id(e, name);
    e->probe_contact = 0;
    e->counters.case_loads++;
    sc_health_clear(&e->health, SC_FAULT_NO_CASE);
    sc_log(&e->hal->log, SC_LOG_INFO, "case_loaded", SC_OK, (int64_t)c->case_id,
           (int64_t)e->tissue.mesh.tet_count);
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
    e->frame_no++;
    /* deadline misses: the first of a burst is logged at once, then at most one line per
     * interval (config/sc_config.h) so that an overload cannot flood the log; b counts the
     * misses a line stands for (itself and the unlogged ones before it), and a burst that
     * ends with unlogged misses gets a summary line once the interval is over */
    const int log_due = e->miss_logged_ns == 0u ||
                        r.end_ns - e->miss_logged_ns >= (uint64_t)SC_ENGINE_MISS_LOG_INTERVAL_NS;
    if (r.missed && log_due) {
        sc_log(&e->hal->log, SC_LOG_WARN, "deadline_miss", SC_ERR_TIMEOUT,
               (int64_t)(r.end_ns - r.release_ns), (int64_t)e->misses_unlogged + 1);
        e->miss_logged_ns = r.end_ns;
        e->misses_unlogged = 0u;
    } else if (r.missed) {
        e->misses_unlogged++;
    } else if (log_due && e->misses_unlogged > 0u) {
        sc_log(&e->hal->log, SC_LOG_WARN, "deadline_miss_summary", SC_ERR_TIMEOUT, 0,
               (int64_t)e->misses_unlogged);
        e->miss_logged_ns = r.end_ns;
        e->misses_unlogged = 0u;
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
        .case_loaded = e->case_loaded,
        .case_id = e->case_id,
        .method = e->def.tissue.method,
        .probe_tracked = e->probe_tracked,
        .probe_contact = e->probe_contact,
        .vein_area_ratio = area_ratio(e, SC_LABEL_VEIN),
        .artery_area_ratio = area_ratio(e, SC_LABEL_ARTERY),
    };
}

uint64_t sc_engine_state_hash(const sc_engine *e)
{
    return e->case_loaded ? sc_tissue_state_hash(&e->tissue) : 0u;
}
