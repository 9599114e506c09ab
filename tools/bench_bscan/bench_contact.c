/* bench_contact.c: the engine's contact case for bench_bscan (issue 15 item 5).
 *
 * A whole engine on the host simulator (sc_hs_rig) loads a built case, the tracker emulator
 * plays the press script (as sc-hostsim does, 8 mm by default) and the frames run until the
 * deepest point of the press (the middle of the hold at the bottom, t = 2.0 s). There, with the
 * deformed mesh from the real physics under the probe:
 *  - imaging alone: sc_bscan_frame on the engine's own B-scan object (the engine's settings:
 *    256x512, walker, the case's acoustics flag), min / median of N frames, with the lines the
 *    walker handed to the region path;
 *  - the same frame through the region path and the oracle's agreement count;
 *  - the whole frame (rx + physics + imaging + status + control): sc_engine_step during the hold
 *    at the bottom (t 1.55 .. 2.0 s), min / median thread CPU time, split at the imaging stage's
 *    display calls (its frame_begin .. the end of its frame_end: the imaging stage; the rest:
 *    rx, physics, status, control, state stream); then the same frames again with the display
 *    a buffer instead of the host simulator's, which hashes every frame.
 * Thread CPU time throughout: the machine is shared. With workers > 1 (bench_contact_set_workers,
 * `bench_bscan contact DIR CASE N METHOD WORKERS`) the engine's HAL gets a pool of that many
 * threads (platform/linux/sc_pool_linux.h, not pinned) before the case loads, so the physics and
 * the B-scan's lines run on it; with the argument given (1 too) every time is wall clock (a
 * worker's CPU is not the frame thread's): read them on a quiet machine.
 */
#define _POSIX_C_SOURCE 200809L
#include "bench_contact.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sc_engine.h"
#include "sc_err.h"
#include "sc_hs_rig.h"
#include "sc_pool_linux.h"
#include "sc_storage_linux.h"
#include "sc_trkemu.h"

static sc_hs_rig g_rig; /* large: static */
static sc_emu g_emu;

static uint32_t g_workers = 1u;
static int g_wall; /* the workers argument given: wall clock, whatever the count */
static sc_pool_linux g_pool;

void bench_contact_set_workers(uint32_t workers)
{
    g_wall = 1;
    g_workers = workers < 1u ? 1u : (workers > SC_POOL_LINUX_MAX_WORKERS ? SC_POOL_LINUX_MAX_WORKERS
                                                                          : workers);
}

/* thread CPU ms, or wall ms when the workers argument was given (1 too, to compare) */
static double cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(g_wall ? CLOCK_MONOTONIC : CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int cmp_d(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The imaging is timed into a display that keeps the lines (a memcpy, as a display controller's
 * buffer), not the host simulator's recorder, which hashes every frame. */
static uint8_t g_keep[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
static uint16_t g_keep_samples;
static int kd_begin(void *ctx, const sc_display_frame_info *info)
{
    (void)ctx;
    g_keep_samples = info->samples;
    return SC_OK;
}
static int kd_line(void *ctx, uint32_t frame_no, uint16_t line, const uint8_t *s, uint16_t n)
{
    (void)ctx;
    (void)frame_no;
    memcpy(&g_keep[(size_t)line * g_keep_samples], s, n);
    return SC_OK;
}
static int kd_end(void *ctx, const sc_display_end_info *end)
{
    (void)ctx;
    (void)end;
    return SC_OK;
}
static const sc_display_ops g_kd_ops = {kd_begin, kd_line, kd_end, NULL, NULL, NULL};
static const sc_display_dev g_kd = {&g_kd_ops, NULL};

/* The whole frame split: a display that forwards every call to the engine's own display (or
 * to the keeping one above) and takes the thread CPU time at the imaging stage's frame_begin
 * and after its frame_end, so that a whole frame's time splits into the B-scan stage (with
 * its sink) and the rest (rx, physics, status, control, the state stream). Two clock reads per
 * frame, none per line. */
typedef struct stamp_disp {
    const sc_display_dev *inner;
    double t_begin, t_end;
} stamp_disp;
static stamp_disp g_sd;
static sc_display_ops g_sd_ops;
static int sd_begin(void *ctx, const sc_display_frame_info *info)
{
    stamp_disp *s = ctx;
    s->t_begin = cpu_ms();
    return sc_display_frame_begin(s->inner, info);
}
static int sd_line(void *ctx, uint32_t frame_no, uint16_t line, const uint8_t *v, uint16_t n)
{
    const stamp_disp *s = ctx;
    return sc_display_line(s->inner, frame_no, line, v, n);
}
static int sd_end(void *ctx, const sc_display_end_info *end)
{
    stamp_disp *s = ctx;
    const int rc = sc_display_frame_end(s->inner, end);
    s->t_end = cpu_ms();
    return rc;
}
static int sd_link(void *ctx, sc_display_link_state *st)
{
    const stamp_disp *s = ctx;
    return s->inner->ops->link_state(s->inner->ctx, st);
}
static int sd_colour(void *ctx, uint32_t frame_no, uint16_t line, uint16_t first, const int8_t *v,
                     uint16_t n)
{
    const stamp_disp *s = ctx;
    return s->inner->ops->colour_line(s->inner->ctx, frame_no, line, first, v, n);
}
static int sd_doppler(void *ctx, const sc_display_doppler_info *info)
{
    const stamp_disp *s = ctx;
    return s->inner->ops->doppler(s->inner->ctx, info);
}
/* the same optional operations as inner (the engine asks whether they are there) */
static sc_display_dev stamp_over(const sc_display_dev *inner)
{
    g_sd.inner = inner;
    g_sd_ops.frame_begin = sd_begin;
    g_sd_ops.line = sd_line;
    g_sd_ops.frame_end = sd_end;
    g_sd_ops.link_state = inner->ops->link_state != NULL ? sd_link : NULL;
    g_sd_ops.colour_line = inner->ops->colour_line != NULL ? sd_colour : NULL;
    g_sd_ops.doppler = inner->ops->doppler != NULL ? sd_doppler : NULL;
    const sc_display_dev d = {&g_sd_ops, &g_sd};
    return d;
}

static int send_peer(void *ctx, const sc_can_frame *f)
{
    const sc_can_dev *dev = ctx;
    return sc_can_send(dev, f);
}

int bench_contact_setup(const char *cases_dir, const char *case_name, int method, float depth_mm,
                        double stop_s)
{
    sc_engine_def def = sc_engine_default_def();
    def.watchdog_timeout_ms = 0;
    if (method >= 0) {
        def.tissue.method = (sc_tissue_method)method;
    }
    int rc = sc_hs_rig_init(&g_rig, &def, 1u, 0);
    if (rc != SC_OK) {
        fprintf(stderr, "bench_contact: engine init: %s\n", sc_err_str(rc));
        return rc;
    }
    if (g_workers > 1u) {
        static int started;
        static sc_pool_dev dev;
        if (!started && sc_pool_linux_start(&g_pool, g_workers, -1, 200u, &dev) != 0) {
            fprintf(stderr, "bench_contact: cannot start %u workers\n", (unsigned)g_workers);
            return SC_ERR_STATE;
        }
        started = 1;
        g_rig.hal.pool = dev; /* every setup: sc_hs_rig_init gives the rig its one-worker pool */
    }
    if (g_wall) {
        printf("pool: %u worker(s) (times are wall clock)\n", (unsigned)g_workers);
    }
    static sc_storage_linux storage;
    sc_storage_linux_init(&storage, cases_dir);
    g_rig.hal.storage = sc_storage_linux_dev(&storage);
    char name[512];
    snprintf(name, sizeof name, "%s.scase", case_name);
    rc = sc_engine_load_case(&g_rig.engine, name);
    if (rc != SC_OK) {
        fprintf(stderr, "bench_contact: case %s/%s: %s (build the cases target first)\n", cases_dir,
                name, sc_err_str(rc));
        return rc;
    }
    const sc_case *cs = sc_engine_get_case(&g_rig.engine);
    sc_emu_def ed = sc_emu_default_def();
    ed.script = SC_EMU_PRESS;
    /* over the top centre of the mesh box, as sc-hostsim */
    const float p_vol[3] = {cs->mesh.origin_mm[0] + 0.5f * cs->mesh.size_mm[0],
                            cs->mesh.origin_mm[1] + 0.5f * cs->mesh.size_mm[1],
                            cs->mesh.origin_mm[2]};
    const sc_xform v2t = sc_xform_inverse(&cs->tracker_to_volume);
    sc_xform_apply(&v2t, p_vol, ed.point_mm);
    ed.depth_mm = depth_mm;
    ed.duration_s = 10.0;
    rc = sc_emu_init(&g_emu, &ed);
    if (rc != SC_OK) {
        return rc;
    }
    const uint64_t t0 = g_rig.clock.now_ns;
    for (;;) {
        const uint64_t release = sc_engine_next_release_ns(&g_rig.engine);
        if ((double)(release - t0) * 1e-9 > stop_s) {
            break;
        }
        (void)sc_emu_feed(&g_emu, release - t0, send_peer, &g_rig.peer);
        sc_engine_step(&g_rig.engine, NULL);
    }
    return SC_OK;
}

const sc_engine *bench_contact_engine(void)
{
    return &g_rig.engine;
}

sc_engine *bench_contact_engine_mut(void)
{
    return &g_rig.engine;
}

const sc_display_dev *bench_contact_display(void)
{
    return &g_rig.hal.display;
}

/* 1: the B-scan's rest reference above the face forgotten before each timed frame, as under a
 * moving probe (a held one, the same pose bit for bit, reuses it: sc_bscan_margin_memo) */
static int g_forget_margin;

/* The engine's imaging of this frame, n times: min and median ms. */
static void time_imaging(uint32_t mapper, int n, double *mn, double *med, uint32_t *fallbacks,
                         int rigid)
{
    sc_engine *e = &g_rig.engine;
    const sc_tissue *t = sc_engine_get_tissue(e);
    const sc_case *cs = sc_engine_get_case(e);
    const sc_probe_in *p = sc_engine_get_probe(e);
    sc_bscan_def d = e->bscan.def;
    const sc_bscan_def keep = d;
    d.mapper = mapper;
    (void)sc_bscan_set_def(&e->bscan, &d);
    static double tm[1000];
    n = n > 1000 ? 1000 : (n < 1 ? 1 : n);
    const uint32_t fb0 = e->bscan.status.line_fallbacks;
    for (int i = 0; i < n; i++) {
        if (g_forget_margin) {
            e->bscan.margin_memo.valid = 0u;
        }
        const double a = cpu_ms();
        (void)sc_bscan_frame(&e->bscan, rigid ? NULL : &t->mesh, rigid ? NULL : &t->nodes,
                             &cs->volume, &p->to_volume, 1, &g_kd, 100000u + (uint32_t)i);
        tm[i] = cpu_ms() - a;
    }
    *fallbacks = (e->bscan.status.line_fallbacks - fb0) / (uint32_t)n;
    qsort(tm, (size_t)n, sizeof tm[0], cmp_d);
    *mn = tm[0];
    *med = tm[n / 2];
    (void)sc_bscan_set_def(&e->bscan, &keep);
}

/* Whole engine frames of the hold (t 1.55 .. 2.0 s after a setup to 1.55 s): per frame the
 * thread CPU ms of sc_engine_step (tf), of its imaging stage (ti, from the display's
 * frame_begin to the end of its frame_end) and of the rest (tr = tf - ti); each sorted.
 * keep_display: the lines go to the buffer of the imaging rows instead of the engine's
 * display (the host simulator's, which hashes every frame). */
static void hold_frames(double *tf, double *ti, double *tr, int *nf_out, int keep_display)
{
    const sc_display_dev saved = g_rig.hal.display;
    g_rig.hal.display = stamp_over(keep_display ? &g_kd : &saved);
    int nf = 0;
    const uint64_t t0 = g_rig.clock.now_ns - (uint64_t)(1.55e9);
    for (;;) {
        const uint64_t release = sc_engine_next_release_ns(&g_rig.engine);
        if ((double)(release - t0) * 1e-9 > 2.0 || nf >= 200) {
            break;
        }
        (void)sc_emu_feed(&g_emu, release - t0, send_peer, &g_rig.peer);
        g_sd.t_begin = g_sd.t_end = 0.0;
        const double a = cpu_ms();
        sc_engine_step(&g_rig.engine, NULL);
        tf[nf] = cpu_ms() - a;
        ti[nf] = g_sd.t_end > g_sd.t_begin ? g_sd.t_end - g_sd.t_begin : 0.0;
        tr[nf] = tf[nf] - ti[nf];
        nf++;
    }
    g_rig.hal.display = saved;
    qsort(tf, (size_t)nf, sizeof tf[0], cmp_d);
    qsort(ti, (size_t)nf, sizeof ti[0], cmp_d);
    qsort(tr, (size_t)nf, sizeof tr[0], cmp_d);
    *nf_out = nf;
}

int bench_contact_run(const char *cases_dir, const char *case_name, int method, int frames)
{
    const float depth_mm = 8.0f;
    /* the press: down from 0.5 s to 1.5 s, held at the bottom until 2.5 s */
    int rc = bench_contact_setup(cases_dir, case_name, method, depth_mm, 1.55);
    if (rc != SC_OK) {
        return 1;
    }
    /* whole frames during the hold, split at the imaging stage's display calls */
    static double tf[200], ti[200], tr[200];
    int nf = 0;
    hold_frames(tf, ti, tr, &nf, 0);
    const sc_engine *e = &g_rig.engine;
    const sc_tissue *t = sc_engine_get_tissue(e);
    sc_engine_status st;
    sc_engine_get_status(e, &st);
    printf("engine contact case: %s, press script %.0f mm, deepest point (t = 2.0 s), mesh "
           "%ux%ux%u (%u tets), %s, %ux%u, acoustics %s, contact %u, vein ratio %.2f\n",
           case_name, (double)depth_mm, t->mesh.nx, t->mesh.ny, t->mesh.nz, t->mesh.tet_count,
           t->method == SC_TISSUE_FEM ? "FEM" : "MSDS", e->bscan.def.scan.lines_n,
           e->bscan.def.scan.samples_n, e->bscan.def.acoustics ? "on" : "off", st.probe_contact,
           (double)st.vein_area_ratio);
    double mn, med;
    uint32_t fb;
    const uint32_t rel0 = e->bscan.status.walk_relocations;
    time_imaging(SC_BSCAN_MAP_WALK, frames, &mn, &med, &fb, 0);
    printf("  imaging, walker (engine default): min %.3f, median %.3f ms per frame; lines to the "
           "region path %u of %u, fold relocations %u per frame; target <= 1.5 ms\n",
           mn, med, fb, e->bscan.def.scan.lines_n,
           (e->bscan.status.walk_relocations - rel0) / (uint32_t)(frames > 0 ? frames : 1));
    {
        sc_bscan_def d = e->bscan.def;
        const uint32_t keep = d.acoustics;
        d.acoustics = 1u - keep;
        (void)sc_bscan_set_def(&g_rig.engine.bscan, &d);
        double mn2, med2;
        time_imaging(SC_BSCAN_MAP_WALK, frames, &mn2, &med2, &fb, 0);
        d.acoustics = keep;
        (void)sc_bscan_set_def(&g_rig.engine.bscan, &d);
        printf("  imaging, walker, acoustics %s: min %.3f, median %.3f ms per frame\n",
               keep ? "off" : "on", mn2, med2);
    }
    {
        /* the acoustics on and the margin labelled every frame: what a moving probe costs */
        sc_bscan_def d = e->bscan.def;
        const uint32_t keep = d.acoustics;
        d.acoustics = 1u;
        (void)sc_bscan_set_def(&g_rig.engine.bscan, &d);
        double mn2, med2;
        g_forget_margin = 1;
        time_imaging(SC_BSCAN_MAP_WALK, frames, &mn2, &med2, &fb, 0);
        g_forget_margin = 0;
        d.acoustics = keep;
        (void)sc_bscan_set_def(&g_rig.engine.bscan, &d);
        printf("  imaging, walker, acoustics on, the rest reference above the face labelled every "
               "frame (a moving probe; a held one reuses it): min %.3f, median %.3f ms per frame\n",
               mn2, med2);
    }
    {
        /* the B-mode alone: the engine's line hook (colour Doppler, the needle) off */
        sc_bscan *bs = &g_rig.engine.bscan;
        const sc_bscan_line_hook_fn hook = bs->line_hook;
        void *hook_ctx = bs->line_hook_ctx;
        sc_bscan_set_line_hook(bs, NULL, NULL);
        double mn2, med2;
        time_imaging(SC_BSCAN_MAP_WALK, frames, &mn2, &med2, &fb, 0);
        sc_bscan_set_line_hook(bs, hook, hook_ctx);
        printf("  imaging, walker, line hook (colour Doppler) %s: min %.3f, median %.3f ms per "
               "frame\n",
               hook != NULL ? "off" : "(none)", mn2, med2);
    }
    time_imaging(SC_BSCAN_MAP_REGIONS, frames / 4 + 1, &mn, &med, &fb, 0);
    printf("  imaging, region path (R = %u): min %.3f, median %.3f ms per frame\n",
           e->bscan.def.regions_n, mn, med);
    time_imaging(SC_BSCAN_MAP_WALK, frames, &mn, &med, &fb, 1);
    printf("  the same pose without the mesh (every pixel rigid: sampling, display, areas): min "
           "%.3f, median %.3f ms\n",
           mn, med);
    printf("  whole frame (rx + physics + imaging + status + control), %d frames of the hold: "
           "min %.3f, median %.3f ms; target <= 4 ms\n",
           nf, tf[0], tf[nf / 2]);
    printf("    of which the imaging stage (frame_begin .. frame_end, the host simulator's display "
           "hashing the frame): min %.3f, median %.3f ms; the rest (rx, physics, status, "
           "control, state stream): min %.3f, median %.3f ms\n",
           ti[0], ti[nf / 2], tr[0], tr[nf / 2]);
    /* again from the start of the hold, the display a buffer (as the imaging rows above and a
     * display controller): the host simulator's per-frame hash is the simulator's cost */
    rc = bench_contact_setup(cases_dir, case_name, method, depth_mm, 1.55);
    if (rc != SC_OK) {
        return 1;
    }
    hold_frames(tf, ti, tr, &nf, 1);
    printf("  whole frame, the display a buffer: min %.3f, median %.3f ms; imaging stage min "
           "%.3f, median %.3f ms; the rest min %.3f, median %.3f ms\n",
           tf[0], tf[nf / 2], ti[0], ti[nf / 2], tr[0], tr[nf / 2]);
    return 0;
}

__attribute__((noinline)) void bench_contact_walker_frames(int frames)
{
    sc_engine *e = &g_rig.engine;
    const sc_tissue *t = sc_engine_get_tissue(e);
    const sc_case *cs = sc_engine_get_case(e);
    const sc_probe_in *p = sc_engine_get_probe(e);
    for (int i = 0; i < frames; i++) {
        (void)sc_bscan_frame(&e->bscan, &t->mesh, &t->nodes, &cs->volume, &p->to_volume, 1, &g_kd,
                             100000u + (uint32_t)i);
    }
}

int bench_contact_walker(const char *cases_dir, const char *case_name, int frames, int acoustics)
{
    if (bench_contact_setup(cases_dir, case_name, -1, 8.0f, 2.0) != SC_OK) {
        return 1;
    }
    if (acoustics >= 0) { /* the acoustics as asked, else the engine's setting for the case */
        sc_bscan_def d = g_rig.engine.bscan.def;
        d.acoustics = (uint32_t)(acoustics != 0);
        (void)sc_bscan_set_def(&g_rig.engine.bscan, &d);
    }
    const sc_engine *e = &g_rig.engine;
    const uint32_t rel0 = e->bscan.status.walk_relocations;
    bench_contact_walker_frames(frames);
    /* FNV-1a of the last frame's bytes: a change of the imaging code must keep it */
    uint32_t h = 2166136261u;
    const size_t nb = (size_t)e->bscan.def.scan.lines_n * e->bscan.def.scan.samples_n;
    for (size_t i = 0; i < nb; i++) {
        h = (h ^ g_keep[i]) * 16777619u;
    }
    /* and of the label areas (the compression measure): their float bits */
    uint32_t ha = 2166136261u;
    for (uint32_t i = 0; i < SC_LABEL_COUNT; i++) {
        uint32_t w[2];
        memcpy(&w[0], &e->bscan.status.area_now_mm2[i], 4);
        memcpy(&w[1], &e->bscan.status.area_rest_mm2[i], 4);
        for (uint32_t q = 0; q < 2u; q++) {
            ha = (ha ^ w[q]) * 16777619u;
        }
    }
    printf("contact-walker: %s, %d walker frames at the deepest point (mapper %u, acoustics %u), "
           "fold relocations %u per frame, image hash %08x, areas hash %08x\n",
           case_name, frames, e->bscan.def.mapper, e->bscan.def.acoustics,
           (e->bscan.status.walk_relocations - rel0) / (uint32_t)(frames > 0 ? frames : 1), h, ha);
    return 0;
}

__attribute__((noinline)) void bench_contact_hold_frames(int frames)
{
    const uint64_t t0 = g_rig.clock.now_ns - (uint64_t)(1.55e9);
    for (int i = 0; i < frames; i++) {
        const uint64_t release = sc_engine_next_release_ns(&g_rig.engine);
        (void)sc_emu_feed(&g_emu, release - t0, send_peer, &g_rig.peer);
        sc_engine_step(&g_rig.engine, NULL);
    }
}

int bench_contact_hold(const char *cases_dir, const char *case_name, int frames)
{
    if (bench_contact_setup(cases_dir, case_name, -1, 8.0f, 1.55) != SC_OK) {
        return 1;
    }
    frames = frames > 50 ? 50 : frames; /* the hold at the bottom lasts to t = 2.45 s */
    bench_contact_hold_frames(frames);
    sc_engine_status st;
    sc_engine_get_status(&g_rig.engine, &st);
    /* the host simulator's display: every complete frame's image hash so far (folded) and the
     * colour Doppler lines' hash: a change of the imaging code must keep them */
    const sc_hs_display *hd = &g_rig.display;
    uint64_t hi = 0;
    for (uint32_t i = 0; i < hd->hash_count; i++) {
        hi = (hi ^ hd->hashes[i]) * 0x100000001b3ull;
    }
    printf("contact-hold: %s, %d whole frames of the hold, contact %u, vein ratio %.4f, state hash "
           "%016llx, images hash %016llx (%u frames), colour hash %016llx (%llu lines)\n",
           case_name, frames, st.probe_contact, (double)st.vein_area_ratio,
           (unsigned long long)sc_engine_state_hash(&g_rig.engine), (unsigned long long)hi,
           hd->hash_count, (unsigned long long)hd->colour_hash,
           (unsigned long long)hd->colour_lines);
    return 0;
}
