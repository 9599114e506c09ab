/* sc_engine.c: the engine object, its frame and the control step between frames; see
 * sc_engine.h. */
#include "sc_engine.h"

#include <math.h>
#include <string.h>

#include "sc_assert.h"
#include "sc_err.h"
#include "sc_labels.h"

#define NS_PER_MS 1000000ull

/* Skin patch margin around the mesh box's top face. */
#define SC_ENGINE_SKIN_MARGIN_MM 10.0f

static const char *const k_stage_names[SC_ENGINE_STAGE_COUNT] = {
    "rx", "physics", "imaging", "status", "control", "platform",
};

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
    d.case_check_slice_bytes = 1u << 20;
    d.control_slice_estimate_ns = 2000000u;
    d.control_wait_frames = 30u;
    d.tracker = sc_tracker_default_def();
    d.tissue = sc_tissue_default_def();
    d.bscan = sc_bscan_default_def();
    d.assess = sc_assess_default_def();
#if SC_ENABLE_DOPPLER
    d.doppler = sc_doppler_default_def();
#endif
    d.case_count = 0u;
    d.state_period_ms = 33u;
    d.state_vert_records = 16u;
    return d;
}

static uint64_t now_ns(const sc_engine *e)
{
    return sc_clock_now_ns(&e->hal->clock);
}

static sc_tissue *running_tissue(sc_engine *e)
{
    return &e->tissue[e->active];
}

/* ==== stage rx: CAN -> the probe in the volume frame ===================================== */

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

static void update_tracker_faults(sc_engine *e, uint64_t now, uint8_t tracked)
{
    const sc_trk_counters *n = sc_tracker_counters(&e->tracker);
    /* duplicates (nothing lost, nothing wrong) are counted by the tracker but raise nothing */
    const uint32_t rejects = sc_tracker_rejected_e2e(&e->tracker) +
                             sc_tracker_rejected_implausible(&e->tracker) +
                             sc_tracker_rejected_auth(&e->tracker) +
                             n->outcome[SC_TRK_BAD_LENGTH] + n->outcome[SC_TRK_POSE_STALE] +
                             n->outcome[SC_TRK_CMD_REJECTED];
    if (rejects != e->tracker_rejects_seen) {
        e->tracker_rejects_seen = rejects;
        e->last_tracker_reject_ns = now;
    }
    const int recent = rejects != 0u && now - e->last_tracker_reject_ns <
                                            (uint64_t)e->def.tracker_fault_hold_ms * NS_PER_MS;
    sc_health_set(&e->health, SC_FAULT_TRACKER_DATA, recent);
    sc_health_set(&e->health, SC_FAULT_TRACKER_TIMEOUT, !tracked);
}

static void stage_rx(sc_engine *e, uint64_t now, sc_probe_in *out)
{
    sc_can_frame f;
    uint32_t n = 0;
    for (; n < SC_CAN_RX_BURST_MAX; n++) {
        if (sc_can_recv(&e->hal->can, &f) != SC_OK) {
            break;
        }
        e->counters.can_rx_frames++;
#if SC_ENABLE_NEEDLE
        if (sc_needle_rx_is_needle(&f)) {
            (void)sc_needle_rx_on_frame(&e->needle_rx, &f, now);
            continue;
        }
#endif
        (void)sc_tracker_on_frame(&e->tracker, &f, now);
    }
    if (n == SC_CAN_RX_BURST_MAX) {
        e->counters.can_rx_burst_limited++;
    }
    take_bus_errors(e);
    e->counters.commands_auth_refused = sc_tracker_rejected_auth(&e->tracker);

    /* the last pose is kept while lifted (status, getters); the transform is recomputed */
    out->tracked = 0;
    sc_pose pose;
    int tracked = 0;
    if (sc_tracker_poll(&e->tracker, now, &pose, &tracked) == SC_OK && tracked) {
        out->tracked = 1;
        out->pose_tracker = pose;
    }
    if (e->case_loaded) {
        const sc_xform t = sc_xform_from_pose(&out->pose_tracker);
        out->to_volume = sc_xform_compose(&e->slot.c.tracker_to_volume, &t);
        out->pose_volume = sc_pose_from_xform(&out->to_volume);
    }
#if SC_ENABLE_NEEDLE
    {
        /* the needle in the volume frame, through the same registration as the probe */
        sc_needle_sample ns;
        if (e->case_loaded && sc_needle_rx_poll(&e->needle_rx, now, &ns)) {
            float tip[3], dir[3];
            sc_xform_apply(&e->slot.c.tracker_to_volume, ns.tip_mm, tip);
            sc_xform_rotate(&e->slot.c.tracker_to_volume, ns.dir, dir);
            sc_needle_set(&e->needle, 1, tip, dir, ns.depth_mm);
        } else {
            sc_needle_set(&e->needle, 0, NULL, NULL, 0.0f);
        }
    }
#endif
    update_tracker_faults(e, now, out->tracked);
}

/* ==== stage physics: the probe -> the deformed mesh ====================================== */

static void stage_physics(sc_engine *e, uint64_t now, const sc_probe_in *in, sc_tissue_out *out)
{
    *out = (sc_tissue_out){.force_n = SC_FORCE_NOT_AVAILABLE};
    if (!e->case_loaded) {
        return;
    }
    sc_tissue *t = running_tissue(e);
    const int frozen = sc_health_is_active(&e->health, SC_FAULT_PHYS_REPEATED);
    const sc_pose *probe = (in->tracked && !frozen) ? &in->pose_volume : NULL;
#if SC_ENABLE_NEEDLE
    /* the inserted needle's tip pushes tissue aside: a sphere of 0.6 node spacings (at least
     * 1 mm), so that the mesh's nodes, not the 1.2 mm tip itself, resolve it */
    {
        const float *cm = t->mesh.cell_mm;
        float cell = cm[0] > cm[1] ? cm[0] : cm[1];
        cell = cell > cm[2] ? cell : cm[2];
        const float radius = 0.6f * cell > 1.0f ? 0.6f * cell : 1.0f;
        sc_tissue_set_tip(t, e->needle.present && e->needle.depth_mm > 0.0f && !frozen,
                          e->needle.tip_mm, radius);
    }
#endif
    const int rc = sc_tissue_step(t, probe);
    if (rc == SC_ERR_PHYS_UNSTABLE) {
        out->reset = 1;
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
               (int64_t)t->stats.last_fault); /* sc_tissue_guard: why */
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
    out->contact = (uint8_t)(probe != NULL && t->stats.contacts > 0u);
    out->mesh = &t->mesh;
    out->nodes = &t->nodes;
    if (out->contact) {
        /* the exam's force (assess_frame), here while the step's matrix rows are still in the
         * caches: after the imaging stage its 27 blocks per contact came from memory (64x32x32,
         * two workers, the real loop pressing and sweeping: 0.59-0.65 ms a frame); the same
         * value, as nothing the force reads changes before the frame ends */
        out->force_n = sc_tissue_probe_force_n(t, NULL);
    }
}

/* ==== stage imaging: the deformed mesh -> scan lines and the compression measure ========= */

#if SC_ENABLE_NEEDLE
/* Both per-line consumers of the B-scan's pass: colour Doppler (when on this frame) and the
 * needle, which draws into the displayed samples. */
static void engine_line_hook(void *ctx, const sc_bscan_line_view *v)
{
    sc_engine *e = ctx;
#if SC_ENABLE_DOPPLER
    if (e->doppler_on) {
        sc_doppler_line_hook(&e->doppler, v);
    }
#endif
    sc_needle_line(&e->needle, v);
}
#endif

static void stage_imaging(sc_engine *e, const sc_probe_in *probe, const sc_tissue_out *in,
                          sc_image_out *out)
{
    *out = (sc_image_out){.rc = SC_OK,
                          .vein_area_ratio = SC_AREA_RATIO_NOT_AVAILABLE,
                          .artery_area_ratio = SC_AREA_RATIO_NOT_AVAILABLE};
#if SC_ENABLE_DOPPLER
    /* colour and spectrum come from the B-scan's own pass (a line hook) */
#if SC_PHYS_LUMEN
    if (e->case_loaded) {
        /* one heart for both: the flow follows the cardiac and respiratory phases of the
         * pulsation that drives the lumens (sc_lumen.h) */
        const sc_lumen *lu = &e->tissue[e->active].lumen;
        (void)sc_doppler_set_phase(&e->doppler, lu->heart_phase, lu->resp_phase);
    }
#endif
    sc_doppler_advance(&e->doppler, 1.0f / (float)e->def.sched.rate_hz);
    (void)sc_doppler_frame_begin(&e->doppler, &e->bscan, &e->hal->display, e->frame_no);
    e->doppler_on = (uint8_t)(e->bscan.line_hook == sc_doppler_line_hook);
#endif
#if SC_ENABLE_NEEDLE
    {
        const sc_xform img2vol =
            sc_xform_compose(&probe->to_volume, &e->bscan.def.scan.image_to_probe);
        sc_needle_frame_begin(&e->needle, &img2vol);
        sc_bscan_set_line_hook(&e->bscan, engine_line_hook, e);
    }
#endif
    if (in->mesh != NULL) {
        out->rc = sc_bscan_frame(&e->bscan, in->mesh, in->nodes, &e->slot.c.volume,
                                 &probe->to_volume, in->contact, &e->hal->display, e->frame_no);
        if (out->rc != SC_OK) {
            e->counters.imaging_errors++;
        }
#if SC_ENABLE_NEEDLE
        e->needle_entry = 0u;
        if (sc_needle_frame_end(&e->needle, &e->slot.c.volume)) {
            const sc_needle_status *ns = sc_needle_status_get(&e->needle);
            e->needle_entry = ns->last_puncture;
            sc_log(&e->hal->log, ns->last_puncture == SC_LABEL_ARTERY ? SC_LOG_WARN : SC_LOG_INFO,
                   "needle_puncture", SC_OK, (int64_t)ns->last_puncture,
                   (int64_t)(ns->vein_punctures + ns->artery_punctures));
        }
#endif
        const sc_bscan_status *b = sc_bscan_status_get(&e->bscan);
        if (b->areas_valid) {
            if (b->area_ratio[SC_LABEL_VEIN] >= 0.0f) {
                out->vein_area_ratio = b->area_ratio[SC_LABEL_VEIN];
            }
            if (b->area_ratio[SC_LABEL_ARTERY] >= 0.0f) {
                out->artery_area_ratio = b->area_ratio[SC_LABEL_ARTERY];
            }
        }
    }
    sc_display_link_state ls;
    if (sc_display_get_link_state(&e->hal->display, &ls) == SC_OK) {
        sc_health_set(&e->health, SC_FAULT_DISPLAY_LINK, !ls.up);
    }
}

/* ==== the assessment: what the frame showed -> the exam's record (sc_assess.h) =========== */

static void assess_frame(sc_engine *e, const sc_tissue_out *tissue, const sc_image_out *img)
{
    sc_assess_in in = {.contact = tissue->contact,
                       .area_ratio = {img->vein_area_ratio, img->artery_area_ratio,
                                      SC_AREA_RATIO_NOT_AVAILABLE},
                       .force_n = SC_FORCE_NOT_AVAILABLE};
    if (e->case_loaded && tissue->contact) {
        const sc_bscan_status *b = sc_bscan_status_get(&e->bscan);
        if (b->areas_valid && b->area_ratio[SC_LABEL_THROMBUS] >= 0.0f) {
            in.area_ratio[SC_ASSESS_THROMBUS] = b->area_ratio[SC_LABEL_THROMBUS];
        }
        in.force_n = tissue->force_n; /* stage_physics */
    }
#if SC_ENABLE_NEEDLE
    /* the needle's lumen entry of this frame (an arterial puncture is a fault of the exam) */
    in.puncture = e->case_loaded ? e->needle_entry : 0u;
    e->needle_entry = 0u;
#endif
    sc_assess_update(&e->assess, &in);
}

static void send_assessment(sc_engine *e)
{
    sc_assess_msg m;
    sc_assess_to_msg(sc_assess_get(&e->assess), &m);
    sc_can_frame out[SC_ASSESS_FRAMES];
    if (sc_status_tx_encode_assess(&e->status_tx, &m, out) != SC_OK) {
        e->counters.can_tx_failed += SC_ASSESS_FRAMES;
        return;
    }
    for (uint32_t i = 0; i < SC_ASSESS_FRAMES; i++) {
        if (sc_can_send(&e->hal->can, &out[i]) != SC_OK) {
            e->counters.can_tx_failed++;
        }
    }
}

/* ==== stage status: what the frame did -> CAN ============================================ */

static void stage_status(sc_engine *e, uint64_t now, const sc_probe_in *probe,
                         const sc_tissue_out *tissue, const sc_image_out *in)
{
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
        .probe_contact = tissue->contact,
        .probe_lifted = (uint8_t)!probe->tracked,
        .fault_bits = (uint16_t)e->health.active,
        .deadline_misses = (uint32_t)(e->sched.misses > UINT32_MAX ? UINT32_MAX
                                                                   : e->sched.misses),
        .case_id = e->case_loaded ? e->case_id : (uint8_t)SC_STATUS_CASE_NONE,
        .worst_frame_us = (uint32_t)(worst_us > UINT32_MAX ? UINT32_MAX : worst_us),
        .vein_area_ratio = in->vein_area_ratio,
        .artery_area_ratio = in->artery_area_ratio,
    };
    sc_can_frame out[SC_STATUS_FRAMES];
    if (sc_status_tx_encode(&e->status_tx, &e->tracker, &s, out) != SC_OK) {
        e->counters.can_tx_failed += SC_STATUS_FRAMES;
        return;
    }
    for (uint32_t i = 0; i < SC_STATUS_FRAMES; i++) {
        if (sc_can_send(&e->hal->can, &out[i]) != SC_OK) {
            e->counters.can_tx_failed++;
        }
    }
    send_assessment(e);
#if SC_ENABLE_NEEDLE
    /* NeedleStatus once a needle tool has spoken on the bus (a frame accepted or refused):
     * without one the bus carries what it always did */
    if (e->needle_rx.outcome[SC_NEEDLE_ACCEPTED] != 0u || e->needle_rx.rejected != 0u) {
        const sc_needle_status *ns = sc_needle_status_get(&e->needle);
        const uint32_t rej = e->needle_rx.rejected;
        const sc_needle_status_msg m = {
            .tip_vessel = (ns->present && (ns->tip_label == SC_LABEL_VEIN ||
                                           ns->tip_label == SC_LABEL_ARTERY))
                              ? ns->tip_label
                              : 0u,
            .needle_tracked = ns->present,
            .last_puncture = ns->last_puncture,
            .vein_punctures = (uint8_t)(ns->vein_punctures > 255u ? 255u : ns->vein_punctures),
            .artery_punctures =
                (uint8_t)(ns->artery_punctures > 255u ? 255u : ns->artery_punctures),
            .needle_rejected = (uint16_t)(rej > 65535u ? 65535u : rej),
        };
        sc_can_frame nf;
        if (sc_canproto_encode_needle_status(&m, e->needle_status_counter, &nf) != SC_OK ||
            sc_can_send(&e->hal->can, &nf) != SC_OK) {
            e->counters.can_tx_failed++;
        }
        e->needle_status_counter = (uint8_t)((e->needle_status_counter + 1u) & 0x0Fu);
    }
#endif
}

/* ==== control step: commands and case switches, between frames ========================== */

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

static void count_refusal(sc_engine *e, const char *event, int rc, int64_t a)
{
    e->counters.commands_refused++;
    sc_health_raise(&e->health, SC_FAULT_CONFIG);
    sc_log(&e->hal->log, SC_LOG_WARN, event, rc, a, 0);
}

static uint8_t catalogue_id(const sc_engine *e, const char *name)
{
    for (uint32_t i = 0; i < e->def.case_count; i++) {
        if (strcmp(e->def.case_names[i], name) == 0) {
            return (uint8_t)i;
        }
    }
    return (uint8_t)SC_ENGINE_CASE_UNLISTED;
}

/* Start a switch (no I/O yet: the control step's slices do the work). */
static int request_switch(sc_engine *e, const char *name)
{
    if (!name) {
        return SC_ERR_INVALID_ARG;
    }
    const size_t len = strlen(name);
    if (len == 0u || len >= SC_ENGINE_CASE_NAME_MAX) {
        return len == 0u ? SC_ERR_INVALID_ARG : SC_ERR_RANGE;
    }
    if (e->sw.phase != SC_SWITCH_IDLE) {
        return SC_ERR_STATE;
    }
    memcpy(e->sw.name, name, len + 1u);
    e->sw.case_id = catalogue_id(e, name);
    e->sw.waited = 0;
    e->sw.phase = SC_SWITCH_OPEN;
    return SC_OK;
}

/* CmdVessels: the lumens' drive of the running tissue, kept for the cases loaded later that
 * carry no drive of their own (a case's DRIV section replaces it at the swap).
 * Pulsation off removes the arterial pressure pulse (the heart's clock runs on, so the
 * Doppler's flow keeps its rhythm); on, the pulse pressure is the running case's (its DRIV),
 * else config/sc_materials.h's. */
static int apply_vessels(sc_engine *e, const sc_vessels_cmd *v)
{
#if SC_PHYS_LUMEN
    sc_lumen_drive d = e->vessel_drive_set ? e->vessel_drive : sc_lumen_drive_default();
    const sc_case_drive *cd = e->case_loaded ? &e->slot.c.drive : NULL;
    const float pulse_on = cd != NULL && cd->present && cd->d.pulse_pa > 0.0f
                               ? cd->d.pulse_pa
                               : sc_lumen_drive_default().pulse_pa;
    d.heart_rate_bpm = v->heart_rate_bpm;
    d.resp_rate_bpm = v->resp_rate_bpm;
    d.pulse_pa = v->pulse ? pulse_on : 0.0f;
    d.valsalva = v->valsalva ? 1u : 0u;
    int rc = sc_lumen_drive_validate(&d);
    if (rc == SC_OK && e->case_loaded) {
        rc = sc_tissue_set_drive(running_tissue(e), &d);
    }
    if (rc == SC_OK) {
        e->vessel_drive = d;
        e->vessel_drive_set = 1u;
        sc_log(&e->hal->log, SC_LOG_INFO, "vessels", SC_OK, (int64_t)v->heart_rate_bpm,
               (int64_t)v->resp_rate_bpm);
    }
    return rc;
#else
    (void)e;
    (void)v;
    return SC_ERR_NOT_SUPPORTED;
#endif
}

/* CmdDoppler: the running Doppler settings with the commanded colour switch, scale, steering
 * and gain; sc_doppler_def_validate refuses e.g. a scale below four times the wall filter. */
static int apply_doppler(sc_engine *e, const sc_doppler_cmd *c)
{
#if SC_ENABLE_DOPPLER
    sc_doppler_def d = e->doppler.def;
    d.enabled = c->on ? 1u : 0u;
    d.prf_hz = c->prf_hz;
    d.steer_deg = c->steer_deg;
    d.gain_db = c->gain_db;
    return sc_engine_set_doppler(e, &d);
#else
    (void)e;
    (void)c;
    return SC_ERR_NOT_SUPPORTED;
#endif
}

/* ---- CmdMaterial: the running case rebuilt with other materials ----------------------- */

static int material_valid(const sc_engine *e, const sc_material_cmd *m)
{
    if (!isfinite(m->e_kpa) || !isfinite(m->poisson) || !isfinite(m->damping_s)) {
        return SC_ERR_NOT_FINITE;
    }
    const uint32_t it_max = SC_PHYS_ITERATIONS_MAX < 63u ? SC_PHYS_ITERATIONS_MAX : 63u;
    if (m->label < SC_MATERIAL_LABEL_MIN || m->label > SC_MATERIAL_LABEL_MAX ||
        m->label >= e->slot.c.material_count || !(m->e_kpa >= 0.1f && m->e_kpa <= 6553.4f) ||
        !(m->poisson >= 0.0f && m->poisson <= 0.49f) ||
        !(m->damping_s >= 0.01f && m->damping_s <= 0.5f) || m->cg_iterations < 1u ||
        m->cg_iterations > it_max || m->corotated > 1u) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

/* A rebuild of the running case with `next` (a switch to its own name; build_begin applies
 * the overrides, swap_case takes them over). */
static int material_rebuild(sc_engine *e, const sc_engine_material *next)
{
    if (!e->case_loaded || e->sw.phase != SC_SWITCH_IDLE) {
        return SC_ERR_STATE;
    }
    const int rc = request_switch(e, e->case_name);
    if (rc == SC_OK) {
        e->mat_next = *next;
        e->mat_rebuild = 1u;
    }
    return rc;
}

static int material_request(sc_engine *e, const sc_material_cmd *m)
{
    int rc = !e->case_loaded || e->sw.phase != SC_SWITCH_IDLE ? SC_ERR_STATE : SC_OK;
    if (rc == SC_OK) {
        rc = material_valid(e, m);
    }
    if (rc == SC_OK) {
        sc_engine_material next = e->mat_run;
        next.label_mask = (uint16_t)(next.label_mask | (1u << m->label));
        next.e_pa[m->label] = m->e_kpa * 1000.0f;
        next.poisson[m->label] = m->poisson;
        next.sim_set = 1u;
        next.damping_s = m->damping_s;
        next.cg_iterations = m->cg_iterations;
        next.corotated = m->corotated;
        rc = material_rebuild(e, &next);
    }
    if (rc != SC_OK) {
        e->counters.material_refused++;
    }
    sc_log(&e->hal->log, rc == SC_OK ? SC_LOG_INFO : SC_LOG_WARN, "material", rc,
           (int64_t)m->label, (int64_t)(m->e_kpa * 10.0f));
    return rc;
}

/* CmdReset (tissue) while overrides are in force: the case's own materials, rebuilt. */
static void material_restore(sc_engine *e)
{
    if (e->mat_run.label_mask == 0u && e->mat_run.sim_set == 0u) {
        return;
    }
    const sc_engine_material none = {0};
    const int rc = material_rebuild(e, &none);
    if (rc != SC_OK) {
        e->counters.material_refused++;
    }
    sc_log(&e->hal->log, rc == SC_OK ? SC_LOG_INFO : SC_LOG_WARN, "material_restore", rc, 0, 0);
}

/* build_begin: the overrides of a material rebuild on the case's table and the tissue def. */
static void material_apply_def(const sc_engine *e, sc_material_table *mat, sc_tissue_def *td)
{
    if (!e->mat_rebuild) {
        return;
    }
    const sc_engine_material *o = &e->mat_next;
    for (uint32_t l = 0; l < mat->count && l < 16u; l++) {
        if (o->label_mask & (1u << l)) {
            mat->row[l].e_pa = o->e_pa[l];
            mat->row[l].poisson = o->poisson[l];
        }
    }
    if (o->sim_set) {
        td->fem.rayleigh_beta_s = o->damping_s;
        td->fem.cg_iterations = o->cg_iterations;
        td->fem.corotated = o->corotated;
    }
}

/* swap_case, after the swap: the new tissue's overrides (none after a case switch), the
 * MSDS springs' damping (Algorithm 1's gamma = 0.1 k unless overridden), the running name. */
static void material_swapped(sc_engine *e, uint32_t slot)
{
    if (e->mat_rebuild) {
        e->mat_run = e->mat_next;
        e->counters.material_rebuilds++;
        if (e->mat_run.sim_set) {
            e->tissue[slot].msds.gamma_per_k_s = e->mat_run.damping_s;
        }
        sc_log(&e->hal->log, SC_LOG_INFO, "material_rebuilt", SC_OK,
               (int64_t)e->mat_run.label_mask, (int64_t)e->mat_run.sim_set);
    } else {
        const sc_engine_material none = {0};
        e->mat_run = none;
        const size_t n = strlen(e->sw.name);
        memcpy(e->case_name, e->sw.name, n + 1u);
    }
    e->mat_rebuild = 0u;
}

int sc_engine_set_material(sc_engine *e, const sc_material_cmd *m)
{
    if (e == NULL || m == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const int rc = material_request(e, m);
    if (rc != SC_OK) {
        count_refusal(e, "command_refused", rc, (int64_t)SC_CMD_MATERIAL);
    }
    return rc;
}

const sc_engine_material *sc_engine_get_material(const sc_engine *e)
{
    return &e->mat_run;
}

static void apply_command(sc_engine *e, const sc_cmd *c)
{
    int rc = SC_OK;
    switch (c->kind) {
    case SC_CMD_SELECT_CASE:
        rc = c->case_id < e->def.case_count ? request_switch(e, e->def.case_names[c->case_id])
                                            : SC_ERR_NOT_FOUND;
        break;
    case SC_CMD_SET_METHOD:
        e->def.tissue.method = c->method == SC_METHOD_FEM ? SC_TISSUE_FEM : SC_TISSUE_MSDS;
        if (e->case_loaded) { /* a tissue built later takes it from def.tissue */
            rc = sc_tissue_set_method(running_tissue(e), e->def.tissue.method);
        }
        break;
    case SC_CMD_SET_IMAGING:
        rc = apply_imaging(e, &c->imaging);
        break;
    case SC_CMD_SYNC_FRESHNESS: /* consumed by the tracker, never queued */
        break;
    case SC_CMD_ASSESS:
        if (c->assess_action == SC_ASSESS_ACTION_RESET) {
            sc_assess_reset(&e->assess);
            sc_log(&e->hal->log, SC_LOG_INFO, "assess_reset", SC_OK, 0, 0);
        } else {
            rc = sc_assess_set_call(&e->assess, c->assess_call);
            sc_log(&e->hal->log, SC_LOG_INFO, "assess_call", rc, (int64_t)c->assess_call,
                   (int64_t)sc_assess_get(&e->assess)->score);
        }
        break;
    case SC_CMD_VESSELS:
        rc = apply_vessels(e, &c->vessels);
        break;
    case SC_CMD_DOPPLER:
        rc = apply_doppler(e, &c->doppler);
        break;
    case SC_CMD_MATERIAL:
        rc = material_request(e, &c->material);
        break;
    case SC_CMD_RESET:
        if ((c->reset_target & SC_RESET_TISSUE) && e->case_loaded) {
            sc_tissue_reset(running_tissue(e));
            material_restore(e);
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
        sc_log(&e->hal->log, SC_LOG_INFO, "command_applied", SC_OK, (int64_t)c->kind,
               (int64_t)c->sender);
    } else {
        count_refusal(e, "command_refused", rc, (int64_t)c->kind);
    }
}

/* No case runs: the status says none, the probe transform is valid (the imaging stage streams
 * dark frames before the first pose), SC_FAULT_NO_CASE is raised. */
static void set_no_case(sc_engine *e)
{
    e->case_loaded = 0;
    e->case_id = (uint8_t)SC_STATUS_CASE_NONE;
    e->probe.to_volume = sc_xform_identity();
    e->probe.pose_volume = sc_pose_identity();
    e->probe.pose_tracker = sc_pose_identity();
    sc_health_raise(&e->health, SC_FAULT_NO_CASE);
}

/* The switch was refused: the running case stays (its mapping and tissue were not touched,
 * except by a one-slot build, after which no case runs). */
static void switch_refused(sc_engine *e, int rc)
{
    if (e->sw.data != NULL) {
        sc_storage_close(&e->hal->storage, e->sw.data, e->sw.size);
    }
    e->sw.data = NULL;
    e->sw.phase = SC_SWITCH_IDLE;
    e->counters.case_load_failures++;
    e->counters.last_case_error = rc;
    e->slot.refused++;
    e->slot.last_error = rc;
    if (e->mat_rebuild) {
        e->counters.material_refused++;
        e->mat_rebuild = 0u;
    }
    sc_health_raise(&e->health, SC_FAULT_CONFIG);
    sc_log(&e->hal->log, SC_LOG_ERROR, "case_refused", rc, (int64_t)e->sw.case_id, 0);
}

/* Begin building the next case's tissue into `slot` (the standby slot, or the running one with
 * a single slot). Limits were checked by the loader, so the build fails only on a capacity the
 * loader cannot see. */
static int build_begin(sc_engine *e, uint32_t slot)
{
    const sc_case *c = &e->sw.c;
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
    material_apply_def(e, &mat, &td);
    /* the skin surface: over the top of the mesh box and a margin around it, so that its
     * deformation has no edge where the tissue mesh ends (paper section V) */
    for (uint32_t a = 0; a < 2u; a++) {
        td.skin.origin_mm[a] = c->mesh.origin_mm[a] - SC_ENGINE_SKIN_MARGIN_MM;
        td.skin.size_mm[a] = c->mesh.size_mm[a] + 2.0f * SC_ENGINE_SKIN_MARGIN_MM;
    }
    td.skin.z_mm = c->mesh.origin_mm[2];
    const int rc =
        sc_tissue_build_begin(&e->tissue[slot], &td, &c->volume, &mat, (uint8_t)SC_LABEL_FAT);
    if (rc == SC_OK) {
        sc_tissue_set_pool(&e->tissue[slot], &e->hal->pool);
        sc_bscan_set_pool(&e->bscan, &e->hal->pool); /* its lines in ranges on the same pool */
    }
    return rc;
}

/* The case's truth for the assessment: DVT when a tet of its mesh is thrombus. O(tets). */
static uint8_t case_finding(const sc_mesh *m)
{
    for (uint32_t t = 0; t < m->tet_count; t++) {
        if (m->tet_label[t] == (uint8_t)SC_LABEL_THROMBUS) {
            return SC_ASSESS_CALL_DVT;
        }
    }
    return SC_ASSESS_CALL_NORMAL;
}

/* The imaging depth a case starts with, as a scanner's preset: the configured default depth
 * (the running one if the probe kind was changed by a command), never deeper than the case's
 * usable depth where it states one (issue 15: no black "no data" below the case). */
static float case_imaging_depth_mm(const sc_engine *e, const sc_case *c, const sc_scan_def *scan)
{
    float depth =
        scan->kind == e->def.bscan.scan.kind ? e->def.bscan.scan.depth_mm : scan->depth_mm;
    if (c->usable_depth_mm > 0.0f && depth > c->usable_depth_mm) {
        depth = c->usable_depth_mm;
    }
    return depth;
}

/* Between two frames: the new case becomes the running one. */
static int swap_case(sc_engine *e, uint32_t slot)
{
    const sc_bscan_def running_def = e->bscan.def;
    sc_bscan_def bd = running_def;
    bd.scan.image_to_probe = e->sw.c.image_to_probe;
    /* the case says whether its volume holds the acoustics or the engine adds them */
    bd.acoustics = (e->sw.c.imaging_flags & SC_CASE_IMAGING_ENGINE_ACOUSTICS) != 0u ? 1u : 0u;
    /* and whether the engine forms the speckle (an MCU build without SC_BSCAN_PSF shows the
     * volume's mean echogenicity) */
    bd.psf = SC_BSCAN_PSF && (e->sw.c.imaging_flags & SC_CASE_IMAGING_ENGINE_SPECKLE) != 0u ? 1u
                                                                                           : 0u;
    bd.scan.depth_mm = case_imaging_depth_mm(e, &e->sw.c, &bd.scan);
    /* a method command during the build applies to the new tissue too */
    int rc = sc_tissue_set_method(&e->tissue[slot], e->def.tissue.method);
#if SC_PHYS_LUMEN
    if (rc == SC_OK) {
        /* the pulsation's clock runs at the frame rate */
        rc = sc_tissue_set_frame_s(&e->tissue[slot], 1.0f / (float)e->def.sched.rate_hz);
    }
    if (rc == SC_OK && e->sw.c.drive.present) {
        /* the case's own drive (its DRIV section: heart rate, pulse, waveform, breathing);
         * a later CmdVessels overrides it, and a case without one keeps that command's */
        rc = sc_tissue_set_drive(&e->tissue[slot], &e->sw.c.drive.d);
        if (rc == SC_OK) {
            e->vessel_drive = e->sw.c.drive.d;
            e->vessel_drive_set = 1u;
            sc_log(&e->hal->log, SC_LOG_INFO, "case_drive", SC_OK,
                   (int64_t)e->sw.c.drive.d.heart_rate_bpm, (int64_t)e->sw.c.drive.d.resp_rate_bpm);
        }
    } else if (rc == SC_OK && e->vessel_drive_set) {
        /* CmdVessels' setting outlives the case */
        rc = sc_tissue_set_drive(&e->tissue[slot], &e->vessel_drive);
    }
#endif
    if (rc == SC_OK) {
        rc = sc_bscan_set_def(&e->bscan, &bd);
    }
    if (rc == SC_OK) {
        rc = sc_bscan_attach_mesh(&e->bscan, &e->tissue[slot].mesh);
    }
#if SC_ENABLE_DOPPLER
    if (rc == SC_OK) {
        /* the flow model of the new case: a bounded strided pass over its label map */
        rc = sc_doppler_attach_volume(&e->doppler, &e->sw.c.volume);
    }
#endif
    if (rc != SC_OK) {
        /* imaging cannot show the new mesh: keep the running case if it is intact */
        if (e->case_loaded && slot != e->active) {
            (void)sc_bscan_set_def(&e->bscan, &running_def);
            (void)sc_bscan_attach_mesh(&e->bscan, &running_tissue(e)->mesh);
#if SC_ENABLE_DOPPLER
            (void)sc_doppler_attach_volume(&e->doppler, &e->slot.c.volume);
#endif
        } else {
            sc_case_slot_close(&e->slot);
            set_no_case(e);
        }
        return rc;
    }
    sc_case_slot_close(&e->slot);
    e->slot.dev = &e->hal->storage;
    e->slot.data = e->sw.data;
    e->slot.size = e->sw.size;
    e->slot.c = e->sw.c;
    e->slot.loaded = 1;
    e->slot.last_error = SC_OK;
    e->sw.data = NULL;
    e->active = (uint8_t)slot;
    e->case_loaded = 1;
    e->case_id = e->sw.case_id;
    e->counters.case_loads++;
    material_swapped(e, slot);
    (void)sc_assess_begin_case(&e->assess, case_finding(&e->tissue[slot].mesh));
    sc_health_clear(&e->health, SC_FAULT_NO_CASE);
    sc_log(&e->hal->log, SC_LOG_INFO, "case_loaded", SC_OK, (int64_t)e->sw.c.case_id,
           (int64_t)e->tissue[slot].mesh.tet_count);
    return SC_OK;
}

/* One slice of the switch: the work of its current phase. */
static void switch_slice(sc_engine *e)
{
    sc_case_switch *sw = &e->sw;
    const uint32_t standby = SC_ENGINE_TISSUE_SLOTS > 1u ? 1u - e->active : 0u;
    int rc = SC_OK;
    switch (sw->phase) {
    case SC_SWITCH_OPEN:
        rc = sc_storage_open(&e->hal->storage, sw->name, &sw->data, &sw->size);
        if (rc != SC_OK) {
            sw->data = NULL;
        } else {
            rc = sc_case_check_begin(&sw->check, sw->data, sw->size);
        }
        if (rc == SC_OK) {
            sw->phase = SC_SWITCH_VALIDATE;
        }
        break;
    case SC_SWITCH_VALIDATE: {
        rc = sc_case_check_step(&sw->check, e->def.case_check_slice_bytes);
        if (rc == 1) {
            rc = sc_case_check_finish(&sw->check, &sw->c);
            if (rc == SC_OK) {
                sw->phase = SC_SWITCH_BUILD;
            }
        }
        if (rc == SC_OK && sw->phase == SC_SWITCH_BUILD) {
            rc = build_begin(e, standby);
        }
        rc = rc > 0 ? SC_OK : rc;
        break;
    }
    case SC_SWITCH_BUILD:
        if (SC_ENGINE_TISSUE_SLOTS == 1u && e->case_loaded) {
            /* in place: the running case ends here, no case runs until the swap */
            sc_case_slot_close(&e->slot);
            set_no_case(e);
        }
        rc = sc_tissue_build_step(&e->tissue[standby]);
        if (rc == 1) {
            sw->phase = SC_SWITCH_SWAP;
            rc = SC_OK;
        }
        break;
    case SC_SWITCH_SWAP:
        rc = swap_case(e, standby);
        sw->phase = SC_SWITCH_IDLE;
        break;
    case SC_SWITCH_IDLE:
        break;
    }
    if (rc != SC_OK) {
        switch_refused(e, rc);
    }
}

static sc_engine_slice slice_kind(const sc_engine *e)
{
    const uint32_t standby = SC_ENGINE_TISSUE_SLOTS > 1u ? 1u - e->active : 0u;
    switch (e->sw.phase) {
    case SC_SWITCH_OPEN:
        return SC_ENGINE_SLICE_OPEN;
    case SC_SWITCH_VALIDATE:
        return SC_ENGINE_SLICE_VALIDATE;
    case SC_SWITCH_BUILD:
        return (sc_engine_slice)(SC_ENGINE_SLICE_BUILD + e->tissue[standby].build_phase);
    case SC_SWITCH_SWAP:
    case SC_SWITCH_IDLE:
        break;
    }
    return SC_ENGINE_SLICE_SWAP;
}

/* Run one slice now; its cost is recorded. */
static void run_slice(sc_engine *e)
{
    const sc_engine_slice kind = slice_kind(e);
    const uint64_t bytes_before = e->sw.check.bytes_done;
    const uint64_t t0 = now_ns(e);
    switch_slice(e);
    const uint64_t dt = now_ns(e) - t0;
    e->counters.control_slices[kind]++;
    if (dt > e->counters.control_worst_ns[kind]) {
        e->counters.control_worst_ns[kind] = dt;
    }
    const uint64_t bytes = e->sw.check.bytes_done - bytes_before; /* <= the slice budget */
    if (kind == SC_ENGINE_SLICE_VALIDATE && bytes > e->counters.case_check_bytes_worst) {
        e->counters.case_check_bytes_worst = bytes;
    }
    e->sw.waited = 0;
}

static void control_step(sc_engine *e)
{
    sc_cmd cmd;
    while (sc_tracker_take_command(&e->tracker, &cmd) == SC_OK) {
        apply_command(e, &cmd);
    }
    if (e->sw.phase == SC_SWITCH_IDLE) {
        return;
    }
    const sc_engine_slice kind = slice_kind(e);
    const uint64_t need = e->counters.control_slices[kind] > 0u
                              ? e->counters.control_worst_ns[kind]
                              : (uint64_t)e->def.control_slice_estimate_ns;
    if (sc_sched_slack_ns(&e->sched) > need) {
        run_slice(e);
    } else if (++e->sw.waited > e->def.control_wait_frames) {
        e->counters.control_forced++;
        run_slice(e);
    } else {
        e->counters.control_deferred++;
    }
}

/* ==== init, case selection, frame ========================================================= */

static int set_filters(sc_engine *e)
{
    /* exactly the protocol's receive ids, so that foreign traffic (a flood at full bus load
     * included) stays in the controller: commands 0x080..0x087 and 0x090, their cryptographic
     * PDUs 0x088..0x08F and 0x098, classic pose 0x100..0x102, FD pose 0x110 */
    const sc_can_filter f[] = {
        {.id = SC_CANID_CMD_CASE, .mask = 0x7F0u, .flags = 0}, /* 0x080..0x08F */
        {.id = SC_CANID_CMD_MATERIAL, .mask = 0x7FFu, .flags = 0}, /* 0x090 CmdMaterial */
        {.id = SC_CANID_AUTH_MATERIAL, .mask = 0x7FFu, .flags = 0}, /* 0x098 its MAC */
        {.id = SC_CANID_POSE_POS, .mask = 0x7FEu, .flags = 0},  /* 0x100..0x101 */
        {.id = SC_CANID_POSE_AUX, .mask = 0x7FFu, .flags = 0},  /* 0x102 */
        {.id = SC_CANID_POSE_FD, .mask = 0x7FFu, .flags = 0},
#if SC_ENABLE_NEEDLE
        {.id = SC_CANID_NEEDLE_POS, .mask = 0x7FEu, .flags = 0}, /* 0x120..0x121 */
        {.id = SC_CANID_NEEDLE_AUX, .mask = 0x7FFu, .flags = 0}, /* 0x122 */
#endif
    };
    const int rc = sc_can_set_filters(&e->hal->can, f, SC_COUNT_OF(f));
    return rc == SC_ERR_NOT_SUPPORTED ? SC_OK : rc;
}

static int def_valid(const sc_engine_def *def)
{
    if (def->case_count > SC_ENGINE_MAX_CASES) {
        return SC_ERR_INVALID_ARG;
    }
    for (uint32_t i = 0; i < def->case_count; i++) {
        if (!def->case_names[i] || def->case_names[i][0] == '\0' ||
            strlen(def->case_names[i]) >= SC_ENGINE_CASE_NAME_MAX) {
            return SC_ERR_INVALID_ARG;
        }
    }
    if (def->status_period_ms < 10u || def->status_period_ms > 10000u ||
        def->tracker_fault_hold_ms > 60000u || def->phys_fault_hold_ms > 60000u ||
        def->phys_resets_fatal == 0u || def->case_check_slice_bytes < 4096u ||
        def->control_wait_frames == 0u) {
        return SC_ERR_RANGE;
    }
    if ((def->state_period_ms != 0u && def->state_period_ms < 10u) ||
        def->state_period_ms > 10000u || def->state_vert_records > 64u) {
        return SC_ERR_RANGE;
    }
    return SC_OK;
}

int sc_engine_init(sc_engine *e, const sc_engine_def *def, const sc_hal *hal)
{
    if (!e || !def || !hal || !hal->clock.ops || !hal->can.ops || !hal->can.ops->send ||
        !hal->can.ops->recv || !hal->display.ops || !hal->storage.ops) {
        return SC_ERR_INVALID_ARG;
    }
    int rc = def_valid(def);
    if (rc != SC_OK) {
        return rc;
    }
    memset(e, 0, offsetof(sc_engine, bscan)); /* the big members are set up by their inits */
    e->hal = hal;
    e->def = *def;
    sc_health_init(&e->health);
    rc = sc_sched_init(&e->sched, &def->sched, &hal->clock);
    for (uint32_t s = 0; s < SC_ENGINE_STAGE_COUNT && rc == SC_OK; s++) {
        const int idx = sc_sched_add_stage(&e->sched, k_stage_names[s]);
        rc = idx == (int)s ? SC_OK : (idx < 0 ? idx : SC_ERR_STATE);
    }
    if (rc == SC_OK) {
        rc = sc_tracker_init(&e->tracker, &def->tracker);
    }
    sc_status_tx_init(&e->status_tx);
#if SC_STATE_STREAM
    sc_state_tx_init(&e->state_tx, def->state_period_ms, def->state_vert_records);
#endif
    if (rc == SC_OK) {
        rc = sc_bscan_init(&e->bscan, &def->bscan);
    }
#if SC_ENABLE_DOPPLER
    if (rc == SC_OK) {
        rc = sc_doppler_init(&e->doppler, &def->doppler);
    }
#endif
#if SC_ENABLE_NEEDLE
    if (rc == SC_OK) {
        const sc_needle_rx_def nrd = sc_needle_rx_default_def();
        rc = sc_needle_rx_init(&e->needle_rx, &nrd);
    }
    if (rc == SC_OK) {
        const sc_needle_def nd = sc_needle_default_def();
        rc = sc_needle_init(&e->needle, &nd);
    }
#endif
    if (rc == SC_OK) {
        rc = sc_assess_init(&e->assess, &def->assess);
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
    e->tissue_out = (sc_tissue_out){0};
    e->image = (sc_image_out){.rc = SC_OK,
                              .vein_area_ratio = SC_AREA_RATIO_NOT_AVAILABLE,
                              .artery_area_ratio = SC_AREA_RATIO_NOT_AVAILABLE};
    sc_health_set_ready(&e->health, 1);
    return SC_OK;
}

int sc_engine_select_case(sc_engine *e, const char *name)
{
    if (!e) {
        return SC_ERR_INVALID_ARG;
    }
    const int rc = request_switch(e, name);
    if (rc != SC_OK) {
        count_refusal(e, "case_select_refused", rc, 0);
    }
    return rc;
}

int sc_engine_load_case(sc_engine *e, const char *name)
{
    if (!e) {
        return SC_ERR_INVALID_ARG;
    }
    int rc = request_switch(e, name);
    if (rc != SC_OK) {
        return rc;
    }
    const uint64_t failures = e->counters.case_load_failures;
    while (e->sw.phase != SC_SWITCH_IDLE) {
        run_slice(e);
    }
    return e->counters.case_load_failures != failures ? e->counters.last_case_error : SC_OK;
}

int sc_engine_set_hook(sc_engine *e, sc_engine_hook_fn fn, void *user)
{
    if (!e) {
        return SC_ERR_INVALID_ARG;
    }
    e->hook = fn;
    e->hook_user = user;
    return SC_OK;
}

/* Deadline misses: the first of a burst is logged at once, then at most one line per interval
 * (config/sc_config.h) so that an overload cannot flood the log; b counts the misses a line
 * stands for (itself and the unlogged ones before it), and a burst that ends with unlogged
 * misses gets a summary line once the interval is over. */
static void log_misses(sc_engine *e, const sc_frame_result *r)
{
    const int log_due = e->miss_logged_ns == 0u ||
                        r->end_ns - e->miss_logged_ns >= (uint64_t)SC_ENGINE_MISS_LOG_INTERVAL_NS;
    if (r->missed && log_due) {
        sc_log(&e->hal->log, SC_LOG_WARN, "deadline_miss", SC_ERR_TIMEOUT,
               (int64_t)(r->end_ns - r->release_ns), (int64_t)e->misses_unlogged + 1);
        e->miss_logged_ns = r->end_ns;
        e->misses_unlogged = 0u;
    } else if (r->missed) {
        e->misses_unlogged++;
    } else if (log_due && e->misses_unlogged > 0u) {
        sc_log(&e->hal->log, SC_LOG_WARN, "deadline_miss_summary", SC_ERR_TIMEOUT, 0,
               (int64_t)e->misses_unlogged);
        e->miss_logged_ns = r->end_ns;
        e->misses_unlogged = 0u;
    }
}

#if SC_STATE_STREAM
/* The console state stream, off the deadline's critical work: a few bounded records at most
 * every state_period_ms, handed to the optional state device (sc_state.h). */
static void state_stream(sc_engine *e, uint64_t now)
{
    if (e->hal->state.ops == NULL) {
        return;
    }
    sc_engine_status st;
    sc_engine_get_status(e, &st);
    const sc_bscan_def *b = &e->bscan.def;
    sc_state_in in = {
        .now_ns = now,
        .frame_no = e->frame_no,
        .health_state = (uint8_t)st.state,
        .case_loaded = st.case_loaded,
        .case_id = st.case_id,
        .method = (uint8_t)st.method,
        .tracked = st.probe_tracked,
        .contact = st.probe_contact,
        .switching = st.switching,
        .faults = st.faults,
        .frames = st.frames,
        .misses = st.misses,
        .worst_frame_ns = st.worst_frame_ns,
        .p99_frame_ns = st.p99_frame_ns,
        .vein_area_ratio = st.vein_area_ratio,
        .artery_area_ratio = st.artery_area_ratio,
        .probe_volume = e->probe.pose_volume,
        .gain_db = b->gain_db,
        .dynamic_range_db = b->dynamic_range_db,
        .depth_mm = b->scan.depth_mm,
        .geometry_id = b->scan.kind,
        .commands_applied = e->counters.commands_applied,
        .commands_refused = e->counters.commands_refused,
        .commands_auth_refused = e->counters.commands_auth_refused,
        .case_loads = e->counters.case_loads,
        .case_load_failures = e->counters.case_load_failures,
        .last_case_error = e->counters.last_case_error,
        .assess = sc_assess_get(&e->assess),
        .catalogue = e->def.case_names,
        .catalogue_count = e->def.case_count,
    };
    for (uint32_t i = 0; i < 8u && i < SC_BSCAN_TGC_BANDS; i++) {
        in.tgc_db[i] = b->tgc_db[i];
    }
    in.material_rebuilds = e->counters.material_rebuilds;
    in.material_refused = e->counters.material_refused;
    if (e->case_loaded) {
        const sc_tissue *rt = &e->tissue[e->active];
        in.mat = &rt->mat;
        in.mat_override_mask = e->mat_run.label_mask;
        in.mat_sim_override = e->mat_run.sim_set;
        in.cg_iterations = (uint8_t)(rt->fem.def.cg_iterations > 255u ? 255u
                                                                       : rt->fem.def.cg_iterations);
        in.corotated = rt->fem.def.corotated;
        in.damping_s = rt->msds.gamma_per_k_s;
    }
    if (e->case_loaded && e->tissue_out.mesh != NULL && e->tissue_out.nodes != NULL) {
        in.c = &e->slot.c;
        in.mesh = e->tissue_out.mesh;
        in.x = e->tissue_out.nodes->x;
        in.y = e->tissue_out.nodes->y;
        in.z = e->tissue_out.nodes->z;
    }
    (void)sc_state_emit(&e->state_tx, &e->hal->state, &in);
}

const sc_state_tx *sc_engine_get_state_tx(const sc_engine *e)
{
    return &e->state_tx;
}
#endif

void sc_engine_step(sc_engine *e, sc_frame_result *out)
{
    SC_ASSERT(e && e->hal);
    sc_sched *s = &e->sched;
    sc_sched_begin_frame(s);

    stage_rx(e, now_ns(e), &e->probe);
    sc_sched_stage_done(s, SC_ENGINE_STAGE_RX);

    stage_physics(e, now_ns(e), &e->probe, &e->tissue_out);
    sc_sched_stage_done(s, SC_ENGINE_STAGE_PHYSICS);

    stage_imaging(e, &e->probe, &e->tissue_out, &e->image);
    assess_frame(e, &e->tissue_out, &e->image);
    sc_sched_stage_done(s, SC_ENGINE_STAGE_IMAGING);

    stage_status(e, now_ns(e), &e->probe, &e->tissue_out, &e->image);
#if SC_STATE_STREAM
    state_stream(e, now_ns(e));
#endif
    sc_sched_stage_done(s, SC_ENGINE_STAGE_STATUS);

    control_step(e);
    sc_sched_stage_done(s, SC_ENGINE_STAGE_CONTROL);

    if (e->hook) {
        e->hook(e->hook_user);
        sc_sched_stage_done(s, SC_ENGINE_STAGE_PLATFORM);
    }

    sc_frame_result r;
    sc_sched_end_frame(s, &r);
    e->frame_no++;
    log_misses(e, &r);
    sc_health_set(&e->health, SC_FAULT_DEADLINE,
                  sc_sched_recent_misses(s, SC_HEALTH_MISS_WINDOW) >= SC_HEALTH_MISS_DEGRADED);
    if (!sc_health_is_active(&e->health, SC_FAULT_WATCHDOG) &&
        sc_watchdog_kick(&e->hal->watchdog) == SC_OK) {
        e->counters.watchdog_kicks++;
    }
    if (out) {
        *out = r;
    }
}

/* ==== read-only views ====================================================================== */

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
        .switching = (uint8_t)(e->sw.phase != SC_SWITCH_IDLE),
        .method = e->def.tissue.method,
        .probe_tracked = e->probe.tracked,
        .probe_contact = e->tissue_out.contact,
        .vein_area_ratio = e->case_loaded ? e->image.vein_area_ratio : SC_AREA_RATIO_NOT_AVAILABLE,
        .artery_area_ratio =
            e->case_loaded ? e->image.artery_area_ratio : SC_AREA_RATIO_NOT_AVAILABLE,
    };
}

uint64_t sc_engine_state_hash(const sc_engine *e)
{
    return e->case_loaded ? sc_tissue_state_hash(&e->tissue[e->active]) : 0u;
}

const sc_engine_counters *sc_engine_get_counters(const sc_engine *e)
{
    return &e->counters;
}

const sc_sched *sc_engine_get_sched(const sc_engine *e)
{
    return &e->sched;
}

const sc_case *sc_engine_get_case(const sc_engine *e)
{
    return e->case_loaded ? &e->slot.c : NULL;
}

const sc_tissue *sc_engine_get_tissue(const sc_engine *e)
{
    return e->case_loaded ? &e->tissue[e->active] : NULL;
}

const sc_tracker *sc_engine_get_tracker(const sc_engine *e)
{
    return &e->tracker;
}

const sc_bscan_status *sc_engine_get_bscan_status(const sc_engine *e)
{
    return sc_bscan_status_get(&e->bscan);
}

uint64_t sc_engine_next_release_ns(const sc_engine *e)
{
    return e->sched.started ? e->sched.next_release_ns : now_ns(e);
}

const sc_probe_in *sc_engine_get_probe(const sc_engine *e)
{
    return &e->probe;
}

const sc_assess_report *sc_engine_assessment(const sc_engine *e)
{
    return sc_assess_get(&e->assess);
}

#if SC_ENABLE_DOPPLER
/* ==== colour and spectral Doppler settings (issue 18) ==================================== */

int sc_engine_set_doppler(sc_engine *e, const sc_doppler_def *def)
{
    if (e == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    return sc_doppler_set_def(&e->doppler, def);
}

int sc_engine_set_flow_phase(sc_engine *e, float cardiac_phase, float resp_phase)
{
    if (e == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    return sc_doppler_set_phase(&e->doppler, cardiac_phase, resp_phase);
}

const sc_doppler_def *sc_engine_get_doppler_def(const sc_engine *e)
{
    return &e->doppler.def;
}

const sc_doppler_status *sc_engine_get_doppler_status(const sc_engine *e)
{
    return sc_doppler_status_get(&e->doppler);
}
#endif

#if SC_ENABLE_NEEDLE
const sc_needle_status *sc_engine_get_needle_status(const sc_engine *e)
{
    return sc_needle_status_get(&e->needle);
}

const sc_needle_rx *sc_engine_get_needle_rx(const sc_engine *e)
{
    return &e->needle_rx;
}
#endif
