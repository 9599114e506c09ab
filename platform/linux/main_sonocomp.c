/*
 * main_sonocomp.c: `sonocomp`, the engine binary of the Linux appliance.
 *
 * Reads the runtime configuration (config/sonocomp.conf syntax; every bad line refused with its
 * line number and reason), sets the process up for real time (mlockall, SCHED_FIFO, CPU pinning,
 * each with a warning and a fallback when refused), opens the devices (SocketCAN, the display
 * target, case storage, watchdog), loads the case, and runs the frame loop at the configured
 * rate until SIGINT/SIGTERM (or --frames / --seconds). Once a second: a live status line on a
 * terminal, a structured status record otherwise. At exit: a final statistics report (frame
 * times, wake-up latency, misses, per-stage times, display link and CAN counters) on stdout.
 *
 * Exit status: 0 clean stop; 1 runtime error (a device or the engine could not start);
 * 2 command-line usage error; 3 configuration refused.
 */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sc_can_replay.h"
#include "sc_can_rxmb.h"
#include "sc_cmdsign.h"
#include "sc_engine.h"
#include "sc_err.h"
#include "sc_cpu.h"
#include "sc_kms_display.h"
#include "sc_log_linux.h"
#include "sc_frame_trace.h"
#include "sc_png_sink.h"
#include "sc_rt.h"
#include "sc_pool_linux.h"
#include "sc_rtcfg.h"
#include "sc_socketcan.h"
#include "sc_storage_linux.h"
#include "sc_udp_display.h"
#include "sc_udp_state.h"
#include "sc_udpcan.h"

#ifndef SONOCOMP_VERSION
#define SONOCOMP_VERSION "0.1.0"
#endif

enum { EXIT_OK = 0, EXIT_RUNTIME = 1, EXIT_USAGE = 2, EXIT_CONFIG = 3 };

#define CONFIG_FILE_MAX (256u * 1024u)

/* The engine object: static storage, locked and pre-faulted with the rest of the process. */
static sc_engine g_engine;
static sc_log_linux g_log;
static sc_cpu_prefetch g_prefetch; /* how the mat-vec's prefetch was chosen (sc_cpu.h) */

/* ---- null devices: can.interface = none, display.target = none ------------------------- */

static int null_can_send(void *ctx, const sc_can_frame *f)
{
    (void)ctx;
    (void)f;
    return 0;
}

static int null_can_recv(void *ctx, sc_can_frame *out)
{
    (void)ctx;
    (void)out;
    return SC_ERR_WOULD_BLOCK;
}

static const sc_can_ops k_null_can = {null_can_send, null_can_recv, NULL, NULL};

static int null_begin(void *ctx, const sc_display_frame_info *info)
{
    (void)ctx;
    (void)info;
    return 0;
}

static int null_line(void *ctx, uint32_t f, uint16_t l, const uint8_t *s, uint16_t n)
{
    (void)ctx;
    (void)f;
    (void)l;
    (void)s;
    (void)n;
    return 0;
}

static int null_end(void *ctx, const sc_display_end_info *end)
{
    (void)ctx;
    (void)end;
    return 0;
}

static const sc_display_ops k_null_display = {null_begin, null_line, null_end, NULL, NULL, NULL};

/* ---- command line ----------------------------------------------------------------------- */

typedef struct cli {
    const char *config_path;
    const char *sets[64];
    uint32_t set_n;
    int check_config;
    uint64_t frames;
    double seconds;
    const char *case_dir;
    uint32_t inject_loss_permille; /* test option: display link lines lost on purpose */
    const char *can_replay_path;   /* --can-replay: a candump -l log instead of SocketCAN */
    const char *state_target;      /* --state-udp: the console state stream's UDP target */
    uint16_t can_udp_port;         /* --can-udp: CAN over UDP instead of SocketCAN */
    uint32_t workers;              /* --workers: solver workers, 0: one per CPU (default 1) */
    const char *hist_path;         /* --hist: frame and wake-up histograms as CSV at the end */
    const char *trace_path;        /* --trace: every frame's times as CSV at the end */
} cli;

static void usage(FILE *f)
{
    fprintf(
        f, "usage: sonocomp [options]\n"
           "The sonocomp real-time engine: tracker on CAN in, B-scan lines to the display.\n\n"
           "  -c, --config FILE     runtime configuration (default: built-in defaults;\n"
           "                        see config/sonocomp.conf)\n"
           "  -s, --set KEY=VALUE   override one key after the file (repeatable)\n"
           "      --check-config    validate the configuration, print it, exit\n"
           "      --help-config     list every key with its default and range\n"
           "      --case-dir DIR    directory relative case paths are resolved in\n"
           "  -n, --frames N        stop after N frames\n"
           "  -t, --seconds S       stop after S seconds\n"
           "      --inject-loss P   (tests) lose P permille of the display link lines on\n"
           "                        purpose, counted, as a lossy network would\n"
           "      --can-replay FILE play a candump -l log (sc-tracker-emu --log) in real\n"
           "                        time as the CAN bus, for hosts without SocketCAN;\n"
           "                        can.interface is then ignored; the log's end is a lift\n"
           "      --can-udp PORT    CAN frames over UDP on 127.0.0.1:PORT (sc_udpcan.h), for\n"
           "                        hosts without SocketCAN; can.interface is then ignored\n"
           "      --state-udp H:P   the console state stream (docs/state-stream.md) to UDP H:P\n"
           "                        (sc-gateway --state-port P)\n"
           "      --hist FILE       at the end, write the frame-time and wake-up lateness\n"
           "                        histograms (CSV: bin upper bound us, counts)\n"
           "      --trace FILE      at the end, write every frame's times (CSV: frame,\n"
           "                        wake-up lateness, frame, missed, each stage, in us;\n"
           "                        kept in memory during the run, up to an hour at 60 Hz\n"
           "                        or the run's --frames / --seconds)\n"
           "      --workers N       solver worker threads, one per core from rt.cpu\n"
           "                        (0: one per online CPU; default 1: no thread);\n"
           "                        results are bit-identical for every N\n"
           "  -h, --help            this help\n"
           "  -V, --version         version\n\n"
           "Stops cleanly on SIGINT or SIGTERM and prints its final statistics on stdout.\n"
           "Exit status: 0 clean stop, 1 runtime error, 2 usage error, 3 configuration refused.\n");
}

static void help_config(void)
{
    printf("Runtime configuration keys (key = value; # comments):\n\n");
    for (uint32_t i = 0; i < sc_rtcfg_key_count(); i++) {
        sc_rtcfg_key_info k;
        sc_rtcfg_key_describe(i, &k);
        printf("%-24s default %s\n%-24s %s\n%-24s %s\n\n", k.name, k.default_text, "", k.range_text,
               "", k.help);
    }
}

static void print_config(FILE *f, const sc_rtcfg *c)
{
    fprintf(f, "can.interface = %s\n", c->can_interface);
    switch ((sc_rtcfg_target)c->display_target) {
    case SC_RTCFG_TARGET_UDP:
        fprintf(f, "display.target = udp:%s:%u\n", c->display_host, (unsigned)c->display_port);
        break;
    case SC_RTCFG_TARGET_PNG:
    case SC_RTCFG_TARGET_DRM:
    case SC_RTCFG_TARGET_FBDEV:
        fprintf(f, "display.target = %s%s%s\n", sc_rtcfg_target_name(c->display_target),
                c->display_path[0] ? ":" : "", c->display_path);
        break;
    case SC_RTCFG_TARGET_NONE:
        fprintf(f, "display.target = none\n");
        break;
    }
    fprintf(f, "frame_rate_hz = %u\n", (unsigned)c->frame_rate_hz);
    fprintf(f, "case = %s\n", c->case_path);
    fprintf(f, "physics.method = %s\n", sc_rtcfg_method_name(c->physics_method));
    fprintf(f, "physics.iterations = %u\n", (unsigned)c->physics_iterations);
    fprintf(f, "physics.dt_s = %g\n", (double)c->physics_dt_s);
    fprintf(f, "physics.cg_iterations = %u\n", (unsigned)c->physics_cg_iterations);
    fprintf(f, "image.geometry = %s\n", sc_rtcfg_geometry_name(c->image_geometry));
    fprintf(f, "image.depth_mm = %g\n", (double)c->image_depth_mm);
    fprintf(f, "image.width_mm = %g\n", (double)c->image_width_mm);
    fprintf(f, "image.sector_deg = %g\n", (double)c->image_sector_deg);
    fprintf(f, "image.lines = %u\n", (unsigned)c->image_lines);
    fprintf(f, "image.samples = %u\n", (unsigned)c->image_samples);
    fprintf(f, "image.gain_db = %g\n", (double)c->image_gain_db);
    fprintf(f, "image.tgc_db =");
    for (uint32_t i = 0; i < SC_BSCAN_TGC_BANDS; i++) {
        fprintf(f, " %g", (double)c->image_tgc_db[i]);
    }
    fprintf(f, "\nimage.dynamic_range_db = %g\n", (double)c->image_dynamic_range_db);
    fprintf(f, "rt.sched_fifo = %s\n", c->rt_sched_fifo ? "true" : "false");
    fprintf(f, "rt.priority = %u\n", (unsigned)c->rt_priority);
    fprintf(f, "rt.cpu = %d\n", (int)c->rt_cpu);
    fprintf(f, "rt.mlock = %s\n", c->rt_mlock ? "true" : "false");
    fprintf(f, "rt.hugepages = %s\n", c->rt_hugepages ? "true" : "false");
    fprintf(f, "watchdog.device = %s\n", c->watchdog_device);
    fprintf(f, "watchdog.timeout_ms = %u\n", (unsigned)c->watchdog_timeout_ms);
    fprintf(f, "tracker.timeout_ms = %u\n", (unsigned)c->tracker_timeout_ms);
    /* the key itself is never printed */
    fprintf(f, "can.auth_key = %s\n",
            strcmp(c->can_auth_key, "bench") == 0 || strncmp(c->can_auth_key, "file:", 5) == 0
                ? c->can_auth_key
                : "(32 hex digits, not shown)");
    fprintf(f, "can.auth_window = %u\n", (unsigned)c->can_auth_window);
    fprintf(f, "can.auth_floor_s = %d\n", (int)c->can_auth_floor_s);
    static const char *const levels[] = {"debug", "info", "warn", "error"};
    static const char *const tri[] = {"auto", "on", "off"};
    fprintf(f, "log.level = %s\n", c->log_level < 4u ? levels[c->log_level] : "?");
    fprintf(f, "status.line = %s\n", c->status_line < 3u ? tri[c->status_line] : "?");
}

/* Read the configuration file and apply it; print every refused line. 0 or EXIT_CONFIG. */
static int load_config(const char *path, sc_rtcfg *cfg)
{
    FILE *f = sc_fopen_regular(path); /* a FIFO or device is refused, never waited on */
    if (!f) {
        fprintf(stderr, "sonocomp: %s: %s\n", path,
                errno == EINVAL ? "not a regular file" : strerror(errno));
        return EXIT_CONFIG;
    }
    static char text[CONFIG_FILE_MAX + 1u];
    size_t n = fread(text, 1, sizeof text, f);
    const int read_err = ferror(f);
    fclose(f);
    if (read_err) {
        fprintf(stderr, "sonocomp: %s: read error\n", path);
        return EXIT_CONFIG;
    }
    if (n > CONFIG_FILE_MAX) {
        fprintf(stderr, "sonocomp: %s: larger than %u bytes\n", path, CONFIG_FILE_MAX);
        return EXIT_CONFIG;
    }
    sc_rtcfg_error errs[32];
    uint32_t stored = 0;
    uint32_t bad = sc_rtcfg_parse(cfg, text, n, errs, 32u, &stored);
    for (uint32_t i = 0; i < stored; i++) {
        fprintf(stderr, "sonocomp: %s:%u: %s%s%s (%s)\n", path, (unsigned)errs[i].line, errs[i].key,
                errs[i].key[0] ? ": " : "", errs[i].reason, sc_err_name(errs[i].err));
    }
    if (bad > stored) {
        fprintf(stderr, "sonocomp: %s: %u more refused lines\n", path, (unsigned)(bad - stored));
    }
    return bad ? EXIT_CONFIG : 0;
}

static int apply_sets(const cli *a, sc_rtcfg *cfg)
{
    int rc = 0;
    for (uint32_t i = 0; i < a->set_n; i++) {
        char key[128];
        const char *eq = strchr(a->sets[i], '=');
        if (!eq || eq == a->sets[i] || (size_t)(eq - a->sets[i]) >= sizeof key) {
            fprintf(stderr, "sonocomp: --set %s: expected KEY=VALUE\n", a->sets[i]);
            rc = EXIT_CONFIG;
            continue;
        }
        memcpy(key, a->sets[i], (size_t)(eq - a->sets[i]));
        key[eq - a->sets[i]] = '\0';
        sc_rtcfg_error e;
        if (sc_rtcfg_set(cfg, key, eq + 1, &e) != 0) {
            fprintf(stderr, "sonocomp: --set %s: %s (%s)\n", a->sets[i], e.reason,
                    sc_err_name(e.err));
            rc = EXIT_CONFIG;
        }
    }
    return rc;
}

/* ---- engine definition from the configuration ------------------------------------------- */

/* The case catalogue of CmdSelectCase: the configured case is index 0, then every other
 * *.scase file of the case folder in name order, up to SC_ENGINE_MAX_CASES. */
static void catalogue(const sc_rtcfg *c, const char *case_dir, sc_engine_def *d)
{
    static char listed[SC_ENGINE_MAX_CASES][SC_STORAGE_LINUX_NAME_MAX];
    uint32_t n = 0;
    const int rc = sc_storage_linux_list(case_dir, ".scase", listed, SC_ENGINE_MAX_CASES, &n);
    if (rc != 0 && rc != SC_ERR_NO_SPACE) {
        sc_log_linux_msg(&g_log, SC_LOG_WARN, "case_folder_unreadable", "dir=%s err=%s",
                         case_dir ? case_dir : ".", sc_err_name(rc));
    } else if (rc == SC_ERR_NO_SPACE) {
        sc_log_linux_msg(&g_log, SC_LOG_WARN, "case_catalogue_full", "dir=%s listed=%u",
                         case_dir ? case_dir : ".", (unsigned)n);
    }
    d->case_names[0] = c->case_path;
    d->case_count = 1u;
    for (uint32_t i = 0; i < n && d->case_count < SC_ENGINE_MAX_CASES; i++) {
        if (strcmp(listed[i], c->case_path) != 0) {
            d->case_names[d->case_count++] = listed[i];
        }
    }
}

/* The command key, freshness window and floor of can.auth_*: 0, or EXIT_CONFIG with the
 * reason logged (an unreadable or malformed key file). */
static int auth_def_from(const sc_rtcfg *c, sc_secoc_def *out)
{
    *out = sc_secoc_default_def();
    out->window = c->can_auth_window;
    const char *k = c->can_auth_key;
    if (strcmp(k, "bench") == 0) {
        sc_log_linux_msg(&g_log, SC_LOG_WARN, "auth_bench_key",
                         "action=\"commands authenticated with the documented bench key: set "
                         "can.auth_key on an appliance\"");
    } else if (strncmp(k, "file:", 5) == 0) {
        FILE *f = sc_fopen_regular(k + 5);
        char text[80] = {0};
        const size_t n = f ? fread(text, 1, sizeof text - 1u, f) : 0u;
        if (f) {
            fclose(f);
        }
        size_t a = 0, b = n;
        while (a < b && (text[a] == ' ' || text[a] == '\t' || text[a] == '\n' || text[a] == '\r')) {
            a++;
        }
        while (b > a && (text[b - 1] == ' ' || text[b - 1] == '\t' || text[b - 1] == '\n' ||
                         text[b - 1] == '\r')) {
            b--;
        }
        text[b] = '\0';
        if (!f || sc_cmdsign_parse_key(text + a, out->key) != 0) {
            sc_log_linux_msg(&g_log, SC_LOG_ERROR, "auth_key_unreadable",
                             "file=%s why=\"%s\"", k + 5,
                             !f ? strerror(errno) : "not 32 hex digits");
            return EXIT_CONFIG;
        }
    } else if (sc_cmdsign_parse_key(k, out->key) != 0) {
        return EXIT_CONFIG; /* unreachable: the configuration checked it */
    }
    if (c->can_auth_floor_s >= 0) {
        const uint64_t now_us = sc_cmdsign_fv_now();
        const uint64_t back_us = (uint64_t)c->can_auth_floor_s * 1000000u;
        out->fv_floor = now_us > back_us ? now_us - back_us : 0u;
    }
    return 0;
}

static sc_engine_def engine_def_from(const sc_rtcfg *c, const char *case_dir)
{
    sc_engine_def d = sc_engine_default_def();
    d.sched.rate_hz = c->frame_rate_hz;
    d.watchdog_timeout_ms = strcmp(c->watchdog_device, "none") == 0 ? 0u : c->watchdog_timeout_ms;
    d.tracker.pose_timeout_ms = c->tracker_timeout_ms;
    d.tissue.method = c->physics_method == SC_RTCFG_METHOD_FEM ? SC_TISSUE_FEM : SC_TISSUE_MSDS;
    d.tissue.msds.iterations = c->physics_iterations;
    d.tissue.msds.dt_s = c->physics_dt_s;
    d.tissue.fem.cg_iterations = c->physics_cg_iterations;
    const sc_xform calib = d.bscan.scan.image_to_probe;
    if (c->image_geometry == SC_RTCFG_GEOMETRY_CURVILINEAR) {
        d.bscan.scan = sc_scan_curvilinear_default_def();
        d.bscan.scan.sector_deg = c->image_sector_deg;
    } else {
        d.bscan.scan = sc_scan_default_def();
        d.bscan.scan.width_mm = c->image_width_mm;
    }
    d.bscan.scan.image_to_probe = calib;
    d.bscan.scan.lines_n = c->image_lines;
    d.bscan.scan.samples_n = c->image_samples;
    d.bscan.scan.depth_mm = c->image_depth_mm;
    d.bscan.gain_db = c->image_gain_db;
    for (uint32_t i = 0; i < SC_BSCAN_TGC_BANDS; i++) {
        d.bscan.tgc_db[i] = c->image_tgc_db[i];
    }
    d.bscan.dynamic_range_db = c->image_dynamic_range_db;
    catalogue(c, case_dir, &d);
    return d;
}

/* ---- status and final report ------------------------------------------------------------ */

static double ms(uint64_t ns)
{
    return (double)ns / 1e6;
}

static const char *method_name(sc_tissue_method m)
{
    return m == SC_TISSUE_FEM ? "fem" : "msds";
}

static void status_tick(const sc_engine *e, double fps, const sc_rtcfg *cfg, int terminal)
{
    sc_engine_status st;
    sc_engine_get_status(e, &st);
    char comp[16] = "--";
    if (st.vein_area_ratio >= 0.0f) {
        double pct = 100.0 * (1.0 - (double)st.vein_area_ratio);
        snprintf(comp, sizeof comp, "%.0f%%", pct < 0.0 ? 0.0 : pct);
    }
    const sc_case *running = sc_engine_get_case(e);
    const char *case_name = running ? running->name : "none";
    (void)cfg;
    if (terminal) {
        char line[480];
        snprintf(line, sizeof line,
                 "%-8s %5.1f fps  worst %6.2f ms  p99 %6.2f ms  misses %llu  tracker %-6s  "
                 "case %s  %s  vein compression %s",
                 sc_health_state_name(st.state), fps, ms(st.worst_frame_ns), ms(st.p99_frame_ns),
                 (unsigned long long)st.misses,
                 st.probe_tracked ? (st.probe_contact ? "touch" : "ok") : "lifted", case_name,
                 method_name(st.method), comp);
        sc_log_linux_status(&g_log, line);
    } else {
        sc_log_linux_msg(&g_log, SC_LOG_INFO, "status",
                         "state=%s fps=%.1f worst_ms=%.3f p99_ms=%.3f misses=%llu tracker=%s "
                         "contact=%d case=%s method=%s vein_compression=%s faults=0x%x",
                         sc_health_state_name(st.state), fps, ms(st.worst_frame_ns),
                         ms(st.p99_frame_ns), (unsigned long long)st.misses,
                         st.probe_tracked ? "ok" : "lifted", st.probe_contact,
                         case_name, method_name(st.method), comp,
                         (unsigned)st.faults);
    }
}

static void print_stats_row(const char *name, const sc_stats *s)
{
    printf("  %-16s %9llu %9.3f %9.3f %9.3f %9.3f\n", name, (unsigned long long)s->count,
           ms(sc_stats_mean_ns(s)), ms(sc_stats_percentile_ns(s, 500u)),
           ms(sc_stats_percentile_ns(s, 990u)), ms(s->worst_ns));
}

/* The frame-time and wake-up lateness histograms (sc_stats.h bins) as CSV: bins with a count. */
static int write_hist(const char *path, const sc_engine *e)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        return -1;
    }
    const sc_sched *s = sc_engine_get_sched(e);
    fprintf(f, "bin_upper_us,frame_count,wakeup_late_count\n");
    for (uint32_t b = 0; b < SC_STATS_BINS; b++) {
        const uint32_t fc = s->frame_stats.hist[b], lc = s->lateness_stats.hist[b];
        if (fc || lc) {
            fprintf(f, "%llu,%u,%u\n", (unsigned long long)sc_stats_bin_upper_us(b),
                    (unsigned)fc, (unsigned)lc);
        }
    }
    return fclose(f);
}

/* With workers: per frame, the loop thread's time outside the pool's jobs (the frame's serial
 * work: what a second core does not shorten), from the pool's own count of the time the caller
 * spent in its jobs. */
static sc_stats g_alone;
/* With workers: the workers' share of each frame's ranges (sc_pool_linux_ranges; their even
 * share is (W - 1) / W), and the frames by it: the workers ran at least half their even share
 * (a quarter of the ranges with two), or less (held: the host had their CPUs). "Two cores" is
 * the first kind's frame time; the second kind's count and misses say how often the host took a
 * core away. On the shared VM of docs/performance.md no frame was held: in its slow phases both
 * cores run slow, the workers' share stays near a half. */
static sc_stats g_present;
static uint64_t g_held_frames, g_held_misses, g_present_misses;
static uint64_t g_share_frames; /* the frames that ran a pool job: the share's count */
static double g_share_sum, g_share_min = 1.0;

static void final_report(const sc_engine *e, double wall_s, const char *stop_reason,
                         const sc_display_dev *disp, const sc_rt_report *rt,
                         const sc_udp_display *udp)
{
    const sc_sched *s = sc_engine_get_sched(e);
    const double period_ms = (double)s->period_ns / 1e6;
    const unsigned rate_hz = (unsigned)(1e9 / (double)s->period_ns + 0.5);
    printf("sonocomp final statistics\n");
    printf("  stopped by %s after %.1f s; %llu frames at %u Hz (period %.3f ms), %.2f fps\n",
           stop_reason, wall_s, (unsigned long long)s->frames, rate_hz,
           period_ms, wall_s > 0.0 ? (double)s->frames / wall_s : 0.0);
    printf("  deadline misses %llu (%.3f%%), release times skipped %llu\n",
           (unsigned long long)s->misses,
           s->frames ? 100.0 * (double)s->misses / (double)s->frames : 0.0,
           (unsigned long long)s->periods_skipped);
    printf("  real time: mlockall %s, SCHED_FIFO %s, pinned %s, huge pages %s\n",
           rt->locked ? "yes" : "no", rt->fifo ? "yes" : "no", rt->pinned ? "yes" : "no",
           rt->huge ? "yes" : "no");
    char pf_line[160];
    sc_cpu_prefetch_describe(&g_prefetch, pf_line, sizeof pf_line);
    printf("  kernels %s, %s\n", sc_simd_name(sc_simd_selected()), pf_line);
    const sc_tissue *tis = sc_engine_get_tissue(e);
    if (tis != NULL) {
        printf("  soft tissue: %s, mesh %ux%ux%u, %u CG iterations per frame\n",
               tis->method == SC_TISSUE_FEM ? "fem" : "msds", (unsigned)tis->mesh.nx,
               (unsigned)tis->mesh.ny, (unsigned)tis->mesh.nz, (unsigned)tis->fem.def.cg_iterations);
    }
    printf("  %-16s %9s %9s %9s %9s %9s   (ms)\n", "", "count", "mean", "p50", "p99", "worst");
    print_stats_row("frame", &s->frame_stats);
    print_stats_row("wake-up latency", &s->lateness_stats);
    printf("  p99.9: frame %.3f ms, wake-up latency %.3f ms\n",
           ms(sc_stats_percentile_ns(&s->frame_stats, 999u)),
           ms(sc_stats_percentile_ns(&s->lateness_stats, 999u)));
    for (uint32_t i = 0; i < s->stage_count; i++) {
        char name[40];
        snprintf(name, sizeof name, "stage %s", s->stages[i].name ? s->stages[i].name : "?");
        print_stats_row(name, &s->stages[i].stats);
    }
    if (g_alone.count != 0u) {
        print_stats_row("outside the pool", &g_alone);
        const uint64_t n = g_share_frames;
        printf("  workers' share of the ranges: mean %.3f, lowest %.3f; frames with the workers "
               "held by the host (under half their share) %llu, misses %llu\n",
               n ? g_share_sum / (double)n : 0.0, n ? g_share_min : 0.0,
               (unsigned long long)g_held_frames, (unsigned long long)g_held_misses);
        if (g_held_frames != 0u) {
            print_stats_row("frame, not held", &g_present);
            printf("  misses in the frames not held %llu\n", (unsigned long long)g_present_misses);
        }
    }
    sc_display_link_state ls;
    if (sc_display_get_link_state(disp, &ls) == 0) {
        printf("  display link: %s, %u lines sent, %u dropped\n", ls.up ? "up" : "down",
               (unsigned)ls.lines_sent, (unsigned)ls.lines_dropped);
    }
    if (udp) {
        printf("  display link lines_sent=%llu lines_dropped=%llu lines_injected=%llu "
               "send_errors=%llu\n",
               (unsigned long long)udp->lines_sent, (unsigned long long)udp->lines_dropped,
               (unsigned long long)udp->lines_injected, (unsigned long long)udp->send_errors);
    }
    const sc_engine_counters *c = sc_engine_get_counters(e);
    printf("  CAN rx frames %llu (burst-limited frames %llu), tx failed %llu\n",
           (unsigned long long)c->can_rx_frames, (unsigned long long)c->can_rx_burst_limited,
           (unsigned long long)c->can_tx_failed);
    printf("  commands applied %llu, refused %llu; case loads %llu, failures %llu; "
           "physics resets %llu; imaging errors %llu; watchdog kicks %llu\n",
           (unsigned long long)c->commands_applied, (unsigned long long)c->commands_refused,
           (unsigned long long)c->case_loads, (unsigned long long)c->case_load_failures,
           (unsigned long long)c->phys_resets, (unsigned long long)c->imaging_errors,
           (unsigned long long)c->watchdog_kicks);
    const sc_tracker *t = sc_engine_get_tracker(e);
    const sc_trk_counters *tc = sc_tracker_counters(t);
    printf("  command authentication: %u authenticated, %llu refused (bad MAC %u, stale %u, "
           "not synced %u, unknown sender %u, orphan MAC %u, MAC missing %u), %u duplicates\n",
           (unsigned)sc_tracker_authenticated(t), (unsigned long long)c->commands_auth_refused,
           (unsigned)tc->outcome[SC_TRK_AUTH_BAD_MAC], (unsigned)tc->outcome[SC_TRK_AUTH_STALE],
           (unsigned)tc->outcome[SC_TRK_AUTH_NOT_SYNCED],
           (unsigned)tc->outcome[SC_TRK_AUTH_UNKNOWN_SENDER],
           (unsigned)tc->outcome[SC_TRK_AUTH_ORPHAN], (unsigned)tc->auth_missing,
           (unsigned)tc->outcome[SC_TRK_DUPLICATE]);
    printf("  log records dropped %llu\n", (unsigned long long)sc_log_linux_dropped(&g_log));
    fflush(stdout);
    sc_log_linux_msg(&g_log, SC_LOG_INFO, "final_stats",
                     "stop=%s frames=%llu misses=%llu skipped=%llu frame_mean_ms=%.3f "
                     "frame_p99_ms=%.3f frame_worst_ms=%.3f wake_p99_ms=%.3f wake_worst_ms=%.3f",
                     stop_reason, (unsigned long long)s->frames, (unsigned long long)s->misses,
                     (unsigned long long)s->periods_skipped, ms(sc_stats_mean_ns(&s->frame_stats)),
                     ms(sc_stats_percentile_ns(&s->frame_stats, 990u)), ms(s->frame_stats.worst_ns),
                     ms(sc_stats_percentile_ns(&s->lateness_stats, 990u)),
                     ms(s->lateness_stats.worst_ns));
}

/* ---- main ------------------------------------------------------------------------------- */

/* The command line into *a (nothing else is touched: tests/fuzz/fuzz_cli_sonocomp.c calls it).
 * Returns -1 to go on, or the exit status: EXIT_OK after --help, --help-config, --version;
 * EXIT_USAGE for a bad option or value. */
static int parse_cli(int argc, char **argv, cli *a)
{
    memset(a, 0, sizeof *a);
    a->workers = 1u;
    optind = 0; /* glibc: a full re-initialisation, so that it can be called again */
    enum { OPT_CHECK = 1000, OPT_HELP_CONFIG, OPT_CASE_DIR, OPT_INJECT, OPT_CAN_REPLAY,
           OPT_STATE_UDP, OPT_CAN_UDP, OPT_WORKERS, OPT_HIST, OPT_TRACE };
    static const struct option lo[] = {{"config", required_argument, NULL, 'c'},
                                       {"set", required_argument, NULL, 's'},
                                       {"check-config", no_argument, NULL, OPT_CHECK},
                                       {"help-config", no_argument, NULL, OPT_HELP_CONFIG},
                                       {"case-dir", required_argument, NULL, OPT_CASE_DIR},
                                       {"inject-loss", required_argument, NULL, OPT_INJECT},
                                       {"can-replay", required_argument, NULL, OPT_CAN_REPLAY},
                                       {"state-udp", required_argument, NULL, OPT_STATE_UDP},
                                       {"can-udp", required_argument, NULL, OPT_CAN_UDP},
                                       {"workers", required_argument, NULL, OPT_WORKERS},
                                       {"hist", required_argument, NULL, OPT_HIST},
                                       {"trace", required_argument, NULL, OPT_TRACE},
                                       {"frames", required_argument, NULL, 'n'},
                                       {"seconds", required_argument, NULL, 't'},
                                       {"help", no_argument, NULL, 'h'},
                                       {"version", no_argument, NULL, 'V'},
                                       {NULL, 0, NULL, 0}};
    int opt;
    while ((opt = getopt_long(argc, argv, "c:s:n:t:hV", lo, NULL)) != -1) {
        char *end = NULL;
        switch (opt) {
        case 'c':
            a->config_path = optarg;
            break;
        case 's':
            if (a->set_n == sizeof a->sets / sizeof a->sets[0]) {
                fprintf(stderr, "sonocomp: too many --set options\n");
                return EXIT_USAGE;
            }
            a->sets[a->set_n++] = optarg;
            break;
        case OPT_CHECK:
            a->check_config = 1;
            break;
        case OPT_HELP_CONFIG:
            help_config();
            return EXIT_OK;
        case OPT_CASE_DIR:
            a->case_dir = optarg;
            break;
        case OPT_INJECT: {
            errno = 0;
            unsigned long v = strtoul(optarg, &end, 10);
            if (errno || !end || *end || optarg[0] == '-' || v > 1000u) {
                fprintf(stderr, "sonocomp: --inject-loss %s: expected 0..1000\n", optarg);
                return EXIT_USAGE;
            }
            a->inject_loss_permille = (uint32_t)v;
            break;
        }
        case OPT_CAN_REPLAY:
            a->can_replay_path = optarg;
            break;
        case OPT_STATE_UDP: {
            char host[256];
            uint16_t port;
            if (sc_udp_parse_target(optarg, host, sizeof host, &port) != 0) {
                fprintf(stderr, "sonocomp: --state-udp %s: expected HOST:PORT or PORT\n", optarg);
                return EXIT_USAGE;
            }
            a->state_target = optarg;
            break;
        }
        case OPT_CAN_UDP: {
            errno = 0;
            const unsigned long v = strtoul(optarg, &end, 10);
            if (errno || !end || *end || optarg[0] == '-' || v == 0u || v > 65535u) {
                fprintf(stderr, "sonocomp: --can-udp %s: expected a port 1..65535\n", optarg);
                return EXIT_USAGE;
            }
            a->can_udp_port = (uint16_t)v;
            break;
        }
        case OPT_HIST:
            a->hist_path = optarg;
            break;
        case OPT_TRACE:
            a->trace_path = optarg;
            break;
        case OPT_WORKERS: {
            errno = 0;
            unsigned long v = strtoul(optarg, &end, 10);
            if (errno || !end || *end || optarg[0] == '-' || v > SC_POOL_LINUX_MAX_WORKERS) {
                fprintf(stderr, "sonocomp: --workers %s: expected 0..%u\n", optarg,
                        (unsigned)SC_POOL_LINUX_MAX_WORKERS);
                return EXIT_USAGE;
            }
            a->workers = (uint32_t)v;
            break;
        }
        case 'n':
            errno = 0;
            a->frames = strtoull(optarg, &end, 10);
            if (errno || !end || *end || optarg[0] == '-' || a->frames == 0u) {
                fprintf(stderr, "sonocomp: --frames %s: expected a positive count\n", optarg);
                return EXIT_USAGE;
            }
            break;
        case 't':
            errno = 0;
            a->seconds = strtod(optarg, &end);
            if (errno || !end || *end || !(a->seconds > 0.0) || !isfinite(a->seconds)) {
                fprintf(stderr, "sonocomp: --seconds %s: expected positive seconds\n", optarg);
                return EXIT_USAGE;
            }
            break;
        case 'h':
            usage(stdout);
            return EXIT_OK;
        case 'V':
            printf("sonocomp %s (display link v%u)\n", SONOCOMP_VERSION, SC_DLINK_VERSION);
            return EXIT_OK;
        default:
            usage(stderr);
            return EXIT_USAGE;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "sonocomp: unexpected argument '%s' (see --help)\n", argv[optind]);
        return EXIT_USAGE;
    }
    return -1;
}

int main(int argc, char **argv)
{
    cli a;
    const int parsed = parse_cli(argc, argv, &a);
    if (parsed >= 0) {
        return parsed;
    }

    /* configuration: defaults, the file, then --set */
    static sc_rtcfg cfg;
    sc_rtcfg_default(&cfg);
    if (a.config_path) {
        int rc = load_config(a.config_path, &cfg);
        if (rc) {
            return rc;
        }
    }
    if (apply_sets(&a, &cfg)) {
        return EXIT_CONFIG;
    }
    if (a.check_config) {
        print_config(stdout, &cfg);
        return EXIT_OK;
    }

    /* logging and real-time set-up */
    if (sc_log_linux_start(&g_log, 2, (sc_log_level)cfg.log_level) != 0) {
        fprintf(stderr, "sonocomp: cannot start the log writer\n");
        return EXIT_RUNTIME;
    }
    const int terminal =
        cfg.status_line == SC_RTCFG_ON || (cfg.status_line == SC_RTCFG_AUTO && isatty(2));
    const int status_records = cfg.status_line != SC_RTCFG_OFF;
    sc_log_linux_set_status_mode(&g_log, terminal);
    /* the kernel variant for this CPU (core/physics/sc_simd.h; SONOCOMP_SIMD overrides) */
    if (sc_cpu_select_simd() != SC_OK) {
        sc_log_linux_msg(&g_log, SC_LOG_WARN, "simd", "SONOCOMP_SIMD=%s refused: not on this CPU",
                         getenv("SONOCOMP_SIMD"));
    }
    /* the mat-vec's prefetch for this CPU, measured (sc_cpu.h; SONOCOMP_PREFETCH overrides) */
    if (sc_cpu_select_prefetch(1, &g_prefetch) != SC_OK) {
        sc_log_linux_msg(&g_log, SC_LOG_WARN, "prefetch",
                         "SONOCOMP_PREFETCH=%s refused or no memory to measure: by the mesh",
                         getenv("SONOCOMP_PREFETCH") ? getenv("SONOCOMP_PREFETCH") : "");
    }
    sc_log_linux_msg(&g_log, SC_LOG_INFO, "start",
                     "version=%s config=%s rate_hz=%u kernels=%s prefetch=%s", SONOCOMP_VERSION,
                     a.config_path ? a.config_path : "(defaults)", (unsigned)cfg.frame_rate_hz,
                     sc_simd_name(sc_simd_selected()),
                     sc_simd_prefetch_name(sc_simd_selected_prefetch()));
    if (sc_rt_install_signals() != 0) {
        sc_log_linux_msg(&g_log, SC_LOG_WARN, "signals", "reason=\"cannot install handlers\"");
    }
    int hp = 1;
    if (cfg.rt_hugepages) {
        /* before mlockall faults the engine's pages in (sc_rt.h) */
        hp = sc_rt_advise_hugepages(&g_engine, sizeof g_engine);
        if (hp == SC_ERR_IO) {
            sc_log_linux_msg(&g_log, SC_LOG_WARN, "rt_hugepages_refused",
                             "errno=%s action=\"running on 4 KiB pages\"", strerror(errno));
        }
    }
    sc_rt_def rtd = sc_rt_default_def();
    rtd.mlock = (int)cfg.rt_mlock;
    rtd.sched_fifo = (int)cfg.rt_sched_fifo;
    rtd.priority = (int)cfg.rt_priority;
    rtd.cpu = cfg.rt_cpu;
    sc_rt_report rtr;
    sc_rt_apply(&rtd, &rtr);
    rtr.huge = hp == 0;
    if (rtd.mlock && !rtr.locked) {
        sc_log_linux_msg(&g_log, SC_LOG_WARN, "rt_mlock_refused",
                         "errno=%s action=\"running with pageable memory\"",
                         strerror(rtr.lock_errno));
    }
    if (rtd.sched_fifo && !rtr.fifo) {
        sc_log_linux_msg(&g_log, SC_LOG_WARN, "rt_fifo_refused",
                         "priority=%d errno=\"%s\" action=\"normal priority\" hint=\"needs "
                         "CAP_SYS_NICE or RLIMIT_RTPRIO\"",
                         rtd.priority, strerror(rtr.fifo_errno));
    }
    if (rtd.cpu >= 0 && !rtr.pinned) {
        sc_log_linux_msg(&g_log, SC_LOG_WARN, "rt_pin_refused", "cpu=%d errno=\"%s\"", rtd.cpu,
                         strerror(rtr.pin_errno));
    }
    sc_rt_prefault(&g_engine, sizeof g_engine);

    int exit_code = EXIT_OK;
    /* devices */
    static sc_hal hal;
    memset(&hal, 0, sizeof hal);
    hal.clock = sc_rt_clock_dev();
    hal.log = sc_log_linux_dev(&g_log);
    static sc_pool_linux pool;
    int pool_started = 0;
    if (a.workers != 1u) {
        const int prc = sc_pool_linux_start(&pool, a.workers, cfg.rt_cpu, 200u, &hal.pool);
        if (prc != 0) {
            sc_log_linux_msg(&g_log, SC_LOG_WARN, "pool_refused",
                             "workers=%u errno=\"%s\" action=\"serial solvers\"",
                             (unsigned)a.workers, strerror(-prc));
        } else {
            pool_started = 1;
            sc_log_linux_msg(&g_log, SC_LOG_INFO, "pool_started", "workers=%u first_cpu=%d",
                             (unsigned)pool.workers, (int)cfg.rt_cpu);
        }
    }

    static sc_socketcan can;
    static sc_can_replay replay;
    static sc_udpcan can_udp;
    static sc_can_rxmb_port can_udp_mb; /* a controller's mailboxes in front of the socket */
    static sc_can_rxmb_port can_mb;     /* the same in front of the SocketCAN socket */
    int can_open = 0, replay_open = 0;
    if (a.can_udp_port && !a.can_replay_path) {
        if (sc_udpcan_open_rx(&can_udp, a.can_udp_port) != 0) {
            fprintf(stderr, "sonocomp: --can-udp %u: %s\n", (unsigned)a.can_udp_port,
                    strerror(can_udp.last_errno));
            sc_log_linux_stop(&g_log);
            return EXIT_RUNTIME;
        }
        /* the socket is one FIFO: drained whole at each receive into the mailboxes, so that
         * commands go first and the newest poses win (sc_can_rxmb.h) */
        const sc_can_rxmb_def mbd = sc_can_rxmb_default_def();
        (void)sc_can_rxmb_port_init(&can_udp_mb, &mbd, sc_udpcan_dev(&can_udp), 4096u);
        hal.can = sc_can_rxmb_port_dev(&can_udp_mb);
        sc_log_linux_msg(&g_log, SC_LOG_INFO, "can_udp", "port=%u can_interface_ignored=%s",
                         (unsigned)a.can_udp_port, cfg.can_interface);
    } else if (a.can_replay_path) {
        errno = 0;
        int rc = sc_can_replay_open(&replay, a.can_replay_path, NULL, NULL);
        if (rc != 0) {
            const int err = errno;
            fprintf(stderr, "sonocomp: --can-replay %s: %s\n", a.can_replay_path,
                    rc == SC_ERR_NOT_FOUND && err ? strerror(err)
                    : rc == SC_ERR_PARSE          ? "no valid candump -l frame in the log"
                                                  : sc_err_str(rc));
            sc_log_linux_msg(&g_log, SC_LOG_ERROR, "can_replay_failed", "file=\"%s\" err=%s",
                             a.can_replay_path, sc_err_name(rc));
            sc_log_linux_stop(&g_log);
            return EXIT_RUNTIME;
        }
        replay_open = 1;
        hal.can = sc_can_replay_dev(&replay);
        sc_log_linux_msg(&g_log, SC_LOG_INFO, "can_replay",
                         "file=\"%s\" frames=%zu duration_s=%.3f lines=%u rejected=%u "
                         "can_interface_ignored=%s",
                         a.can_replay_path, replay.count, (double)replay.duration_ns / 1e9,
                         (unsigned)replay.lines, (unsigned)replay.rejected, cfg.can_interface);
        if (replay.rejected > 0u) {
            sc_log_linux_msg(&g_log, SC_LOG_WARN, "can_replay_rejected",
                             "file=\"%s\" rejected=%u last_line=%u reason=%s", a.can_replay_path,
                             (unsigned)replay.rejected, (unsigned)replay.last_reject_line,
                             sc_candump_reject_name(replay.last_reject));
        }
    } else if (strcmp(cfg.can_interface, "none") == 0) {
        hal.can.ops = &k_null_can;
        sc_log_linux_msg(&g_log, SC_LOG_WARN, "can_none", "action=\"no tracker: probe lifted\"");
    } else {
        int rc = sc_socketcan_open(&can, sc_socketcan_sys_posix(), NULL, cfg.can_interface);
        if (rc != 0) {
            sc_log_linux_msg(&g_log, SC_LOG_ERROR, "can_open_failed",
                             "interface=%s err=%s hint=\"ip link set %s up; or can.interface = "
                             "none\"",
                             cfg.can_interface, sc_err_name(rc), cfg.can_interface);
            sc_log_linux_stop(&g_log);
            return EXIT_RUNTIME;
        }
        can_open = 1;
        /* the kernel's socket queue is one FIFO too: drained (bounded) at each receive into
         * the mailboxes, so that after a stall a command does not wait behind the queued
         * tracker frames and the newest poses win (sc_can_rxmb.h); the kernel's receive
         * stamps and acceptance filters stay */
        const sc_can_rxmb_def mbd = sc_can_rxmb_default_def();
        (void)sc_can_rxmb_port_init(&can_mb, &mbd, sc_socketcan_dev(&can), 4096u);
        hal.can = sc_can_rxmb_port_dev(&can_mb);
    }

    static sc_udp_display udp;
    sc_png_sink *png = NULL;
    sc_kms_display *kms = NULL;
    int udp_open = 0;
    switch ((sc_rtcfg_target)cfg.display_target) {
    case SC_RTCFG_TARGET_UDP: {
        sc_udp_display_def ud = sc_udp_display_default_def();
        ud.host = cfg.display_host;
        ud.port = (uint16_t)cfg.display_port;
        ud.inject_drop_permille = a.inject_loss_permille;
        int rc = sc_udp_display_open(&udp, &ud);
        if (rc != 0) {
            sc_log_linux_msg(&g_log, SC_LOG_ERROR, "display_open_failed", "target=udp:%s:%u err=%s",
                             cfg.display_host, (unsigned)cfg.display_port, sc_err_name(rc));
            exit_code = EXIT_RUNTIME;
        } else {
            udp_open = 1;
            hal.display = sc_udp_display_dev(&udp);
        }
        break;
    }
    case SC_RTCFG_TARGET_PNG: {
        const sc_png_sink_def pd = {.dir = cfg.display_path};
        int rc = sc_png_sink_open(&png, &pd);
        if (rc != 0) {
            sc_log_linux_msg(&g_log, SC_LOG_ERROR, "display_open_failed", "target=png:%s err=%s",
                             cfg.display_path, sc_err_name(rc));
            exit_code = EXIT_RUNTIME;
        } else {
            hal.display = sc_png_sink_dev(png);
        }
        break;
    }
    case SC_RTCFG_TARGET_DRM:
    case SC_RTCFG_TARGET_FBDEV: {
        const char *why = NULL;
        const char *path = cfg.display_path[0] ? cfg.display_path : NULL;
        int rc = cfg.display_target == SC_RTCFG_TARGET_DRM ? sc_kms_open_drm(&kms, path, &why)
                                                           : sc_kms_open_fbdev(&kms, path, &why);
        if (rc != 0 && cfg.display_target == SC_RTCFG_TARGET_DRM && !path) {
            sc_log_linux_msg(&g_log, SC_LOG_WARN, "drm_unavailable",
                             "reason=\"%s\" action=\"trying fbdev\"", why ? why : "?");
            rc = sc_kms_open_fbdev(&kms, NULL, &why);
        }
        if (rc != 0) {
            sc_log_linux_msg(
                &g_log, SC_LOG_ERROR, "display_open_failed", "target=%s err=%s why=\"%s\"",
                sc_rtcfg_target_name(cfg.display_target), sc_err_name(rc), why ? why : "?");
            exit_code = EXIT_RUNTIME;
        } else {
            hal.display = sc_kms_display_dev(kms);
        }
        break;
    }
    case SC_RTCFG_TARGET_NONE:
        hal.display.ops = &k_null_display;
        break;
    }

    /* the console state stream (optional, off the deadline: one datagram per record) */
    static sc_udp_state state_udp;
    if (a.state_target) {
        char host[256];
        uint16_t port = 0;
        (void)sc_udp_parse_target(a.state_target, host, sizeof host, &port);
        if (sc_udp_state_open(&state_udp, host, port) != 0) {
            sc_log_linux_msg(&g_log, SC_LOG_ERROR, "state_open_failed", "target=udp:%s:%u",
                             host, (unsigned)port);
            exit_code = EXIT_RUNTIME;
        } else {
            hal.state = sc_udp_state_dev(&state_udp);
        }
    }

    static sc_storage_linux storage;
    sc_storage_linux_init(&storage, a.case_dir);
    hal.storage = sc_storage_linux_dev(&storage);

    static sc_soft_watchdog soft_wdg;
    static sc_dev_watchdog dev_wdg;
    int dev_wdg_open = 0, soft_wdg_used = 0;
    if (strcmp(cfg.watchdog_device, "soft") == 0) {
        sc_soft_watchdog_init(&soft_wdg, 1);
        hal.watchdog = sc_soft_watchdog_dev(&soft_wdg);
        soft_wdg_used = 1;
    } else if (strcmp(cfg.watchdog_device, "none") != 0) {
        int rc = sc_dev_watchdog_open(&dev_wdg, cfg.watchdog_device);
        if (rc == 0) {
            hal.watchdog = sc_dev_watchdog_dev(&dev_wdg);
            dev_wdg_open = 1;
        } else {
            sc_log_linux_msg(&g_log, SC_LOG_WARN, "watchdog_unavailable",
                             "device=%s errno=\"%s\" action=\"software watchdog\"",
                             cfg.watchdog_device, strerror(dev_wdg.last_errno));
            sc_soft_watchdog_init(&soft_wdg, 1);
            hal.watchdog = sc_soft_watchdog_dev(&soft_wdg);
            soft_wdg_used = 1;
        }
    }

    sc_engine *e = &g_engine;
    int engine_ok = 0;
    static sc_engine_def def;
    if (exit_code == EXIT_OK) {
        def = engine_def_from(&cfg, a.case_dir);
        exit_code = auth_def_from(&cfg, &def.tracker.secoc);
    }
    if (exit_code == EXIT_OK) {
        int rc = sc_engine_init(e, &def, &hal);
        if (rc != 0) {
            sc_log_linux_msg(&g_log, SC_LOG_ERROR, "engine_init_failed", "err=%s (%s)",
                             sc_err_name(rc), sc_err_str(rc));
            exit_code = EXIT_RUNTIME;
        } else {
            engine_ok = 1;
            rc = sc_engine_load_case(e, cfg.case_path);
            if (rc != 0) {
                sc_log_linux_msg(&g_log, SC_LOG_ERROR, "case_load_failed",
                                 "case=%s err=%s (%s) action=\"running without a case until a "
                                 "select-case command\"",
                                 cfg.case_path, sc_err_name(rc), sc_err_str(rc));
            } else {
                sc_log_linux_msg(&g_log, SC_LOG_INFO, "case_loaded", "case=%s", cfg.case_path);
            }
        }
    }

    static sc_frame_trace trace;
    int trace_open = 0;
    if (engine_ok && a.trace_path) {
        /* room for the run's frames when its length is given (5 % over for a slow start) */
        const uint64_t want =
            a.frames
                ? a.frames
                : (a.seconds > 0.0 ? (uint64_t)(a.seconds * (double)cfg.frame_rate_hz * 1.05) + 64u
                                   : 0u);
        if (sc_frame_trace_open(&trace, a.trace_path, want, sc_engine_get_sched(e)) != 0) {
            fprintf(stderr, "sonocomp: --trace %s: %s\n", a.trace_path, strerror(errno));
            exit_code = EXIT_RUNTIME;
            engine_ok = 0;
        } else {
            trace_open = 1;
        }
    }

    const char *stop_reason = "error";
    double wall_s = 0.0;
    if (engine_ok) {
        sc_stats_reset(&g_alone);
        sc_stats_reset(&g_present);
        const uint64_t t0 = sc_rt_now_ns();
        uint64_t next_status = t0 + 1000000000u;
        uint64_t frames_at_status = 0;
        uint64_t t_status = t0;
        double fps = 0.0;
        sc_frame_result fr;
        for (;;) {
            if (sc_rt_stop_requested()) {
                stop_reason = sc_rt_stop_signal() == 15 ? "SIGTERM" : "SIGINT";
                break;
            }
            const uint64_t in_jobs0 = pool.job_ns;
            uint64_t by_workers0 = 0, by_workers1 = 0;
            const uint64_t by_caller0 =
                pool_started ? sc_pool_linux_ranges(&pool, &by_workers0) : 0u;
            const uint64_t misses0 = sc_engine_get_sched(e)->misses;
            sc_engine_step(e, &fr);
            const uint64_t now = sc_rt_now_ns();
            if (trace_open) {
                sc_frame_trace_add(&trace, &fr, sc_engine_get_sched(e));
            }
            if (pool_started && fr.end_ns > fr.start_ns) {
                const uint64_t busy = fr.end_ns - fr.start_ns, in_jobs = pool.job_ns - in_jobs0;
                sc_stats_add(&g_alone, busy > in_jobs ? busy - in_jobs : 0u);
                const uint64_t by_caller = sc_pool_linux_ranges(&pool, &by_workers1) - by_caller0;
                const uint64_t by_workers = by_workers1 - by_workers0;
                const uint64_t missed = sc_engine_get_sched(e)->misses - misses0;
                const uint64_t ranges = by_caller + by_workers;
                int held = 0; /* (a frame with no job says nothing of the workers) */
                if (ranges != 0u) {
                    const double share = (double)by_workers / (double)ranges;
                    g_share_frames++;
                    g_share_sum += share;
                    g_share_min = share < g_share_min ? share : g_share_min;
                    /* the workers' even share is (W - 1) / W of the ranges: held under half */
                    held = by_workers * 2u * pool.workers < ranges * (pool.workers - 1u);
                }
                if (held) {
                    g_held_frames++;
                    g_held_misses += missed;
                } else {
                    sc_stats_add(&g_present, busy);
                    g_present_misses += missed;
                }
            }
            if (now >= next_status) {
                const uint64_t frames_now = sc_engine_get_sched(e)->frames;
                fps = (double)(frames_now - frames_at_status) * 1e9 / (double)(now - t_status);
                frames_at_status = frames_now;
                t_status = now;
                next_status += 1000000000u;
                if (next_status <= now) {
                    next_status = now + 1000000000u;
                }
                if (status_records) {
                    status_tick(e, fps, &cfg, terminal);
                }
            }
            if (a.frames && sc_engine_get_sched(e)->frames >= a.frames) {
                stop_reason = "frame limit";
                break;
            }
            if (a.seconds > 0.0 && (double)(now - t0) / 1e9 >= a.seconds) {
                stop_reason = "time limit";
                break;
            }
        }
        wall_s = (double)(sc_rt_now_ns() - t0) / 1e9;
        sc_log_linux_status_done(&g_log);
        final_report(e, wall_s, stop_reason, &hal.display, &rtr, udp_open ? &udp : NULL);
        if (a.can_udp_port && !a.can_replay_path) {
            const sc_can_rxmb_counters *mc = &can_udp_mb.mb.c;
            printf("  can over udp    %llu datagrams (%llu malformed); mailboxes: %llu commands, "
                   "%llu stream frames taken, %llu stream frames overwritten by newer ones, "
                   "%llu commands refused (full)\n",
                   (unsigned long long)can_udp.received, (unsigned long long)can_udp.rejected,
                   (unsigned long long)mc->prio_taken, (unsigned long long)mc->stream_taken,
                   (unsigned long long)mc->stream_overwritten,
                   (unsigned long long)mc->prio_dropped);
        }
        if (can_open) {
            const sc_can_rxmb_counters *mc = &can_mb.mb.c;
            printf("  socketcan       %s: %llu frames, %llu error frames (%u unconvertible, %u "
                   "dropped by the kernel); mailboxes: %llu commands, %llu stream frames taken, "
                   "%llu stream frames overwritten by newer ones, %llu commands refused (full), "
                   "%llu drains stopped at %u frames\n",
                   cfg.can_interface, (unsigned long long)can.rx_frames,
                   (unsigned long long)can.rx_error_frames, (unsigned)can.rx_unconvertible,
                   (unsigned)can.counters.rx_dropped, (unsigned long long)mc->prio_taken,
                   (unsigned long long)mc->stream_taken, (unsigned long long)mc->stream_overwritten,
                   (unsigned long long)mc->prio_dropped, (unsigned long long)can_mb.drain_limited,
                   (unsigned)can_mb.drain_max);
        }
        if (a.hist_path && write_hist(a.hist_path, e) != 0) {
            fprintf(stderr, "sonocomp: --hist %s: %s\n", a.hist_path, strerror(errno));
        }
    }
    if (trace_open) {
        const uint32_t kept = trace.n;
        const uint64_t dropped = trace.dropped;
        if (sc_frame_trace_close(&trace) != 0) {
            fprintf(stderr, "sonocomp: --trace %s: %s\n", a.trace_path, strerror(errno));
            exit_code = exit_code == EXIT_OK ? EXIT_RUNTIME : exit_code;
        } else {
            printf("  frame trace     %u frames written to %s, %llu past its capacity not kept\n",
                   (unsigned)kept, a.trace_path, (unsigned long long)dropped);
        }
    }

    /* clean shutdown: a stopped engine must not be reset by its watchdog */
    if (pool_started) {
        sc_pool_linux_stop(&pool);
    }
    if (soft_wdg_used) {
        sc_soft_watchdog_stop(&soft_wdg);
    }
    if (dev_wdg_open) {
        sc_dev_watchdog_close(&dev_wdg, 1);
    }
    if (png) {
        sc_png_sink_stats ps;
        sc_png_sink_get_stats(png, &ps);
        sc_png_sink_close(png);
        sc_log_linux_msg(&g_log, SC_LOG_INFO, "png_sink",
                         "frames=%llu written=%llu busy=%llu "
                         "errors=%llu",
                         (unsigned long long)ps.frames, (unsigned long long)ps.frames_written,
                         (unsigned long long)ps.frames_busy, (unsigned long long)ps.write_errors);
    }
    if (kms) {
        sc_kms_close(kms);
    }
    if (udp_open) {
        sc_udp_display_close(&udp);
    }
    if (can_open) {
        sc_socketcan_close(&can);
    }
    if (replay_open) {
        sc_log_linux_msg(&g_log, SC_LOG_INFO, "can_replay_done",
                         "frames=%zu delivered=%llu sent_discarded=%llu rejected_lines=%u "
                         "end_reached=%s",
                         replay.count, (unsigned long long)replay.received,
                         (unsigned long long)replay.sent, (unsigned)replay.rejected,
                         sc_can_replay_done(&replay) ? "yes" : "no");
        if (engine_ok) {
            printf("  CAN replay %s: %zu frames over %.3f s, %llu delivered%s, %u malformed "
                   "lines refused, %llu sent frames discarded\n",
                   a.can_replay_path, replay.count, (double)replay.duration_ns / 1e9,
                   (unsigned long long)replay.received,
                   sc_can_replay_done(&replay) ? " (end of log reached)" : "",
                   (unsigned)replay.rejected, (unsigned long long)replay.sent);
            fflush(stdout);
        }
        sc_can_replay_close(&replay);
    }
    sc_log_linux_msg(&g_log, SC_LOG_INFO, "stop", "reason=\"%s\" exit=%d", stop_reason, exit_code);
    sc_log_linux_stop(&g_log);
    return exit_code;
}
