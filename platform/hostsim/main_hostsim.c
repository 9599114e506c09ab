/*
 * main_hostsim.c: sc-hostsim, the engine's main job on the host simulator.
 *
 * The real core runs on the simulated HAL (virtual clock, in-process CAN bus, display
 * recorder) with a case file mapped read-only, while the tracker emulator's generator drives
 * a scripted probe over the simulated bus (or a candump -l log is replayed). Every received
 * CAN frame can be recorded as a candump -l log; replaying that log reproduces the session's
 * frames bit for bit. Output: scan-converted PNG frames, a per-frame CSV and a summary.
 * A session bundle (--record-bundle FILE.scb, docs/session-bundle.md) holds the case's
 * identity, the method and configuration, the received CAN log, the engine's events, every
 * frame's image hash and the assessment's score in one checksummed file; --replay FILE.scb
 * replays it with nothing else given, refuses it when its case is missing or different, and
 * checks every image hash; --list-bundles DIR prints the bundles of a folder as JSON.
 * Virtual time makes the run deterministic; the host CPU time of each frame is measured
 * separately (wall clock around each frame) and reported.
 *
 * Exit codes: 0 success, 1 the run failed (case refused, output not writable), 2 bad usage.
 */
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "sc_bundle.h"
#include "sc_candump.h"
#include "sc_cmdsign.h"
#include <dirent.h>
#include "sc_engine.h"
#include "sc_err.h"
#include "sc_cpu.h"
#include "sc_hs_faults.h"
#include "sc_hs_live.h"
#include "sc_hs_rig.h"
#include "sc_labels.h"
#include "sc_png_write.h"
#include "sc_scan_overlay.h"
#include "sc_scanconv.h"
#include "sc_stats.h"
#include "sc_storage_linux.h"
#include "sc_trkemu.h"

#ifndef SC_DEFAULT_CASES_DIR
#define SC_DEFAULT_CASES_DIR "cases"
#endif
#define SC_HOSTSIM_VERSION "0.1.0"

typedef struct options {
    const char *case_name;
    const char *cases_dir;
    const char *out_dir;
    const char *script;
    const char *csv_path;
    const char *replay_path;
    const char *record_path;
    const char *frame_raw_path;
    double seconds;
    uint32_t every;
    uint32_t png_width, png_height;
    int method; /* -1 keep default */
    uint32_t cg_iterations; /* --cg-iterations; 0: the build's default */
    int fd;
    uint64_t seed;
    sc_hs_fault_plan faults;
    uint64_t rx_cost_ns;
    float point_mm[3];
    int point_set;
    float depth_mm;
    int quiet;
    const char *bundle_path;  /* --record-bundle */
    const char *list_dir;     /* --list-bundles */
    uint8_t call;             /* --call: SC_ASSESS_CALL_*, NONE: no call */
    double call_t_s;          /* its time; < 0: 0.5 s before the end */
    int case_set, seconds_set, faults_set;
    sc_hs_live_def live; /* --live, --can-udp, --state-udp, --dlink-udp, --state-out */
} options;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: sc-hostsim [options]\n"
            "Runs the engine on the host simulator with a scripted probe and writes B-scans.\n"
            "  --case NAME|PATH     case (default neck-ijv; NAME is looked up in --cases-dir)\n"
            "  --cases-dir DIR      folder of the built cases (default " SC_DEFAULT_CASES_DIR ")\n"
            "  --out DIR            output folder (default out/demo)\n"
            "  --script NAME        press|sweep|rock|lift (default press)\n"
            "  --csv FILE           timed poses instead of a script (t_s,x,y,z,qw,qx,qy,qz[,force])\n"
            "  --seconds S          simulated time (default 6)\n"
            "  --method msds|fem    soft-tissue solver (default msds)\n"
            "  --cg-iterations N    CG iterations per frame of the implicit step, 1..%u\n"
            "                       (default %u; not recorded in a bundle)\n"
            "  --point X,Y,Z        probe contact point, volume frame mm (default: over the vein)\n"
            "  --depth MM           press depth (default 8)\n"
            "  --fd                 CAN FD pose frames\n"
            "  --faults LIST        faults, comma separated (platform/hostsim/sc_hs_faults.h):\n"
            "                       drop|corrupt|dup|reorder=PPM, delay=NS, random=START:END\n"
            "                       (the random ones only then); busoff|silence|flood|linkdown=\n"
            "                       START:DURATION (seconds); bitrate=BPS (flood, 500000)\n"
            "  --rx-cost-us US      virtual time each CAN frame the engine takes costs (default 0)\n"
            "  --seed N             fault injection seed (default 1)\n"
            "  --record FILE        write every frame the engine received as a candump -l log\n"
            "  --record-bundle FILE write the session as a bundle (case, method, CAN log, events,\n"
            "                       image hashes, score; docs/session-bundle.md), e.g. x.scb\n"
            "  --replay FILE        replay a candump -l log instead of the emulator, or a bundle:\n"
            "                       its case, method and length, every image hash checked\n"
            "  --list-bundles DIR   print the bundles (*.scb) of DIR as JSON and exit\n"
            "  --call normal|dvt[@T_S]  the trainee's call (CmdAssessment, signed with the bench\n"
            "                       key) at T_S (default 0.5 s before the end)\n"
            "  --every N            write every N-th frame as PNG (default 6; 0: none)\n"
            "  --png-size WxH       PNG canvas (default 480x640); a PNG is the image's box in it\n"
            "  --frame-raw FILE     also write the deepest-compression frame as a raw frame file\n"
            "  --quiet              no per-second progress\n"
            "  --live               release frames at wall-clock time (the engine keeps the\n"
            "                       virtual clock) for the console gateway (tools/gateway)\n"
            "  --can-udp PORT       CAN frames in over UDP on 127.0.0.1:PORT (sc_udpcan.h:\n"
            "                       sc-tracker-emu --udp, the gateway's commands) instead of\n"
            "                       the built-in emulator script\n"
            "  --state-udp H:P      the console state stream to UDP H:P (docs/state-stream.md)\n"
            "  --state-out FILE     the state stream's records into FILE (u16 length + record)\n"
            "  --dlink-udp H:P      scan lines over the UDP display link to H:P as well\n"
            "  --help, --version\n",
            (unsigned)SC_PHYS_ITERATIONS_MAX, (unsigned)SC_PHYS_CG_ITERATIONS_DEFAULT);
}

static int parse_u64(const char *s, uint64_t max, uint64_t *out)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || end == s || *end || v > max || s[0] == '-') {
        return -1;
    }
    *out = v;
    return 0;
}

static int parse_double(const char *s, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v) || v < lo || v > hi) {
        return -1;
    }
    *out = v;
    return 0;
}

/* The command line into *o (nothing else is touched: tests/fuzz/fuzz_cli_hostsim.c calls it).
 * 0 to go on, -1 after --help or --version (exit 0), 2 for a usage error. */
static int parse_args(int argc, char **argv, options *o)
{
    *o = (options){.case_name = "neck-ijv",
                   .cases_dir = SC_DEFAULT_CASES_DIR,
                   .out_dir = "out/demo",
                   .script = "press",
                   .seconds = 6.0,
                   .every = 6,
                   .png_width = 480,
                   .png_height = 640,
                   .method = -1,
                   .seed = 1,
                   .depth_mm = 8.0f};
    (void)sc_hs_fault_plan_parse("", &o->faults, NULL, 0);
    enum { O_CASE = 256, O_CASES_DIR, O_OUT, O_SCRIPT, O_CSV, O_SECONDS, O_METHOD, O_POINT,
           O_DEPTH, O_FD, O_FAULTS, O_SEED, O_RECORD, O_REPLAY, O_EVERY, O_PNG, O_RAW, O_QUIET,
           O_HELP, O_VERSION, O_RX_COST, O_BUNDLE, O_LIST, O_CALL,
           O_LIVE, O_CAN_UDP, O_STATE_UDP, O_STATE_OUT, O_DLINK_UDP, O_CG };
    static const struct option opts[] = {
        {"case", required_argument, 0, O_CASE},     {"cases-dir", required_argument, 0, O_CASES_DIR},
        {"out", required_argument, 0, O_OUT},       {"script", required_argument, 0, O_SCRIPT},
        {"csv", required_argument, 0, O_CSV},       {"seconds", required_argument, 0, O_SECONDS},
        {"method", required_argument, 0, O_METHOD}, {"point", required_argument, 0, O_POINT},
        {"depth", required_argument, 0, O_DEPTH},   {"fd", no_argument, 0, O_FD},
        {"faults", required_argument, 0, O_FAULTS}, {"seed", required_argument, 0, O_SEED},
        {"record", required_argument, 0, O_RECORD}, {"replay", required_argument, 0, O_REPLAY},
        {"every", required_argument, 0, O_EVERY},   {"png-size", required_argument, 0, O_PNG},
        {"frame-raw", required_argument, 0, O_RAW}, {"quiet", no_argument, 0, O_QUIET},
        {"help", no_argument, 0, O_HELP},           {"version", no_argument, 0, O_VERSION},
        {"rx-cost-us", required_argument, 0, O_RX_COST},
        {"record-bundle", required_argument, 0, O_BUNDLE},
        {"list-bundles", required_argument, 0, O_LIST},
        {"call", required_argument, 0, O_CALL},
        {"live", no_argument, 0, O_LIVE},           {"can-udp", required_argument, 0, O_CAN_UDP},
        {"state-udp", required_argument, 0, O_STATE_UDP},
        {"state-out", required_argument, 0, O_STATE_OUT},
        {"dlink-udp", required_argument, 0, O_DLINK_UDP},
        {"cg-iterations", required_argument, 0, O_CG},
        {0, 0, 0, 0}};
    int c;
    opterr = 0;
    optind = 0; /* glibc: a full re-initialisation, so that it can be called again */
    while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        uint64_t u;
        double d;
        switch (c) {
        case O_CASE: o->case_name = optarg; o->case_set = 1; break;
        case O_CASES_DIR: o->cases_dir = optarg; break;
        case O_OUT: o->out_dir = optarg; break;
        case O_SCRIPT: o->script = optarg; break;
        case O_CSV: o->csv_path = optarg; break;
        case O_SECONDS:
            if (parse_double(optarg, 0.01, 3600.0, &o->seconds)) {
                fprintf(stderr, "sc-hostsim: --seconds wants 0.01..3600, got '%s'\n", optarg);
                return 2;
            }
            o->seconds_set = 1;
            break;
        case O_METHOD:
            if (strcmp(optarg, "msds") == 0) {
                o->method = SC_TISSUE_MSDS;
            } else if (strcmp(optarg, "fem") == 0) {
                o->method = SC_TISSUE_FEM;
            } else {
                fprintf(stderr, "sc-hostsim: --method wants msds or fem, got '%s'\n", optarg);
                return 2;
            }
            break;
        case O_CG:
            if (parse_u64(optarg, SC_PHYS_ITERATIONS_MAX, &u) || u == 0u) {
                fprintf(stderr, "sc-hostsim: --cg-iterations wants 1..%u, got '%s'\n",
                        (unsigned)SC_PHYS_ITERATIONS_MAX, optarg);
                return 2;
            }
            o->cg_iterations = (uint32_t)u;
            break;
        case O_POINT:
            if (sscanf(optarg, "%f,%f,%f", &o->point_mm[0], &o->point_mm[1], &o->point_mm[2]) != 3 ||
                !isfinite(o->point_mm[0]) || !isfinite(o->point_mm[1]) || !isfinite(o->point_mm[2])) {
                fprintf(stderr, "sc-hostsim: --point wants X,Y,Z in mm, got '%s'\n", optarg);
                return 2;
            }
            o->point_set = 1;
            break;
        case O_DEPTH:
            if (parse_double(optarg, 0.0, 50.0, &d)) {
                fprintf(stderr, "sc-hostsim: --depth wants 0..50 mm, got '%s'\n", optarg);
                return 2;
            }
            o->depth_mm = (float)d;
            break;
        case O_FD: o->fd = 1; break;
        case O_FAULTS: {
            char why[160];
            if (sc_hs_fault_plan_parse(optarg, &o->faults, why, sizeof why)) {
                fprintf(stderr, "sc-hostsim: --faults '%s': %s\n", optarg, why);
                return 2;
            }
            o->faults_set = 1;
            break;
        }
        case O_RX_COST:
            if (parse_u64(optarg, 10000u, &u)) {
                fprintf(stderr, "sc-hostsim: --rx-cost-us wants 0..10000, got '%s'\n", optarg);
                return 2;
            }
            o->rx_cost_ns = u * 1000u;
            break;
        case O_SEED:
            if (parse_u64(optarg, UINT64_MAX, &o->seed)) {
                fprintf(stderr, "sc-hostsim: --seed wants an unsigned integer, got '%s'\n", optarg);
                return 2;
            }
            break;
        case O_RECORD: o->record_path = optarg; break;
        case O_REPLAY: o->replay_path = optarg; break;
        case O_EVERY:
            if (parse_u64(optarg, 100000u, &u)) {
                fprintf(stderr, "sc-hostsim: --every wants 0..100000, got '%s'\n", optarg);
                return 2;
            }
            o->every = (uint32_t)u;
            break;
        case O_PNG:
            if (sscanf(optarg, "%ux%u", &o->png_width, &o->png_height) != 2 || o->png_width < 16 ||
                o->png_height < 16 || o->png_width > 4096 || o->png_height > 4096) {
                fprintf(stderr, "sc-hostsim: --png-size wants WxH, 16..4096, got '%s'\n", optarg);
                return 2;
            }
            break;
        case O_RAW: o->frame_raw_path = optarg; break;
        case O_BUNDLE: o->bundle_path = optarg; break;
        case O_LIST: o->list_dir = optarg; break;
        case O_CALL: {
            char buf[64];
            if (strlen(optarg) >= sizeof buf) {
                fprintf(stderr, "sc-hostsim: --call wants normal|dvt[@T_S], got '%s'\n", optarg);
                return 2;
            }
            strcpy(buf, optarg);
            char *at = strchr(buf, '@');
            o->call_t_s = -1.0;
            if (at) {
                *at = '\0';
                if (parse_double(at + 1, 0.0, 3600.0, &o->call_t_s)) {
                    fprintf(stderr, "sc-hostsim: --call time wants 0..3600 s, got '%s'\n", at + 1);
                    return 2;
                }
            }
            if (strcmp(buf, "normal") == 0) {
                o->call = SC_ASSESS_CALL_NORMAL;
            } else if (strcmp(buf, "dvt") == 0) {
                o->call = SC_ASSESS_CALL_DVT;
            } else {
                fprintf(stderr, "sc-hostsim: --call wants normal|dvt[@T_S], got '%s'\n", optarg);
                return 2;
            }
            break;
        }
        case O_QUIET: o->quiet = 1; break;
        case O_LIVE: o->live.pace = 1; break;
        case O_CAN_UDP:
            if (parse_u64(optarg, 65535u, &u) || u == 0u) {
                fprintf(stderr, "sc-hostsim: --can-udp wants a port 1..65535, got '%s'\n", optarg);
                return 2;
            }
            o->live.can_port = (uint16_t)u;
            break;
        case O_STATE_UDP:
        case O_DLINK_UDP: {
            char host[256];
            uint16_t port;
            if (sc_udp_parse_target(optarg, host, sizeof host, &port) != 0) {
                fprintf(stderr, "sc-hostsim: --%s wants HOST:PORT or PORT, got '%s'\n",
                        c == O_STATE_UDP ? "state-udp" : "dlink-udp", optarg);
                return 2;
            }
            if (c == O_STATE_UDP) {
                o->live.state_target = optarg;
            } else {
                o->live.dlink_target = optarg;
            }
            break;
        }
        case O_STATE_OUT: o->live.state_file = optarg; break;
        case O_HELP: usage(stdout); return -1;
        case O_VERSION: printf("sc-hostsim %s\n", SC_HOSTSIM_VERSION); return -1;
        default:
            fprintf(stderr, "sc-hostsim: unknown or incomplete option '%s'\n", argv[optind - 1]);
            usage(stderr);
            return 2;
        }
    }
    if (optind != argc) {
        fprintf(stderr, "sc-hostsim: unexpected argument '%s'\n", argv[optind]);
        return 2;
    }
    if (o->live.can_port && (o->replay_path || o->csv_path)) {
        fprintf(stderr, "sc-hostsim: --can-udp cannot be combined with --replay or --csv\n");
        return 2;
    }
    if (o->replay_path && (o->csv_path || o->record_path || o->bundle_path || o->call)) {
        fprintf(stderr, "sc-hostsim: --replay cannot be combined with --csv, --record, "
                        "--record-bundle or --call\n");
        return 2;
    }
    if (o->cg_iterations != 0u && o->bundle_path) {
        /* a bundle records the method, not the solver's budget: a session with another budget
         * would not replay to its image hashes */
        fprintf(stderr, "sc-hostsim: --cg-iterations cannot be combined with --record-bundle "
                        "(a bundle does not record it)\n");
        return 2;
    }
    if (o->bundle_path) {
        /* a bundle holds what the engine received; a bus-off or a display link down acts
         * outside the received frames and would not replay: refuse rather than record a
         * session that cannot be reproduced */
        for (uint32_t i = 0; i < o->faults.n; i++) {
            if (o->faults.ep[i].kind == SC_HS_EP_BUS_OFF ||
                o->faults.ep[i].kind == SC_HS_EP_LINK_DOWN) {
                fprintf(stderr, "sc-hostsim: --record-bundle cannot record busoff or linkdown "
                                "episodes (they act outside the received CAN frames)\n");
                return 2;
            }
        }
    }
    return 0;
}

/* ---- recording ----------------------------------------------------------------------------- */

typedef struct recorder {
    FILE *fp;
    uint64_t frames;
    uint64_t errors;
    sc_bundle_writer *bundle; /* also into the bundle (NULL: no bundle) */
} recorder;

static void record_frame(void *user, const sc_can_frame *f)
{
    recorder *r = user;
    sc_candump_rec rec = {.ts_us = f->ts_ns / 1000u, .frame = *f};
    strcpy(rec.iface, "hs0");
    if (r->bundle != NULL) {
        sc_bundle_add_can(r->bundle, &rec);
    }
    if (r->fp == NULL) {
        return;
    }
    char line[SC_CANDUMP_LINE_MAX + 2];
    int n = sc_candump_format(&rec, line, sizeof(line));
    if (n < 0 || fputs(line, r->fp) == EOF) {
        r->errors++;
        return;
    }
    r->frames++;
}

/* ---- bundles ------------------------------------------------------------------------------ */

#define BUNDLE_MAX_BYTES ((size_t)1 << 30)

/* JSON string body: quotes, backslashes and control bytes escaped. */
static void json_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        const unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\') {
            fprintf(f, "\\%c", ch);
        } else if (ch < 0x20u || ch > 0x7Eu) {
            fprintf(f, "\\u%04x", ch);
        } else {
            fputc(ch, f);
        }
    }
    fputc('"', f);
}

static int name_cmp(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The replayed bundle's bytes, freed at exit (every return path of main). */
static uint8_t *g_bundle_buf;
static void free_bundle_buf(void)
{
    free(g_bundle_buf);
    g_bundle_buf = NULL;
}

/* --list-bundles DIR: every *.scb as a JSON object, refused ones with their reason; sorted by
 * file name. 0, or 1 when DIR cannot be read. */
static int list_bundles(const char *dir)
{
    DIR *d = opendir(dir);
    if (d == NULL) {
        fprintf(stderr, "sc-hostsim: cannot read %s: %s\n", dir, strerror(errno));
        return 1;
    }
    static char *names[4096];
    size_t n = 0;
    const struct dirent *de;
    while ((de = readdir(d)) != NULL && n < sizeof names / sizeof names[0]) {
        const size_t l = strlen(de->d_name);
        if (l > 4u && strcmp(de->d_name + l - 4u, ".scb") == 0) {
            names[n] = strdup(de->d_name);
            if (names[n] != NULL) {
                n++;
            }
        }
    }
    closedir(d);
    qsort(names, n, sizeof names[0], name_cmp);
    uint32_t refused = 0;
    printf("{\"dir\": ");
    json_str(stdout, dir);
    printf(", \"bundles\": [");
    for (size_t i = 0; i < n; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        printf("%s\n  {\"file\": ", i ? "," : "");
        json_str(stdout, names[i]);
        uint8_t *buf;
        size_t len;
        sc_bundle_info info;
        sc_bundle_reject why = SC_BDL_OK;
        uint64_t line = 0;
        int rc = sc_bundle_read_file(path, BUNDLE_MAX_BYTES, &buf, &len);
        if (rc == SC_OK) {
            rc = sc_bundle_parse(buf, len, &info, &why, &line);
            free(buf);
        }
        if (rc != SC_OK) {
            refused++;
            printf(", \"error\": ");
            json_str(stdout, why != SC_BDL_OK ? sc_bundle_reject_name(why) : sc_err_str(rc));
            printf(", \"line\": %" PRIu64 "}", line);
        } else {
            const sc_bundle_meta *m = &info.meta;
            printf(", \"case\": ");
            json_str(stdout, m->case_name);
            printf(", \"case_id\": \"0x%08x\", \"method\": \"%s\", \"date\": ", m->case_id,
                   m->method ? "fem" : "msds");
            json_str(stdout, m->date);
            printf(", \"source\": ");
            json_str(stdout, m->source);
            printf(", \"frames\": %" PRIu64 ", \"rate_hz\": %u, \"seconds\": %.3f, "
                   "\"can_frames\": %" PRIu64 ", \"events\": %" PRIu64 ", \"score\": %u, "
                   "\"score_max\": %u, \"criteria_met\": %u, \"call\": \"%s\", "
                   "\"finding\": \"%s\"}",
                   m->frames, m->rate_hz, (double)m->frames / (double)m->rate_hz, info.can_count,
                   info.ev_count, m->score, m->score_max, m->criteria, sc_bundle_call_name(m->call),
                   sc_bundle_call_name(m->finding));
        }
        free(names[i]);
    }
    printf("%s], \"count\": %zu, \"refused\": %u}\n", n ? "\n" : "", n, refused);
    return 0;
}

/* The engine's log records since the last call, into the bundle (the hostsim log's ring keeps
 * the last SC_HS_LOG_RING; more in one frame are counted as lost). */
static void bundle_events(sc_bundle_writer *w, const sc_hs_log *log, uint64_t *seen,
                          uint64_t frame, uint64_t *lost)
{
    if (log->total - *seen > SC_HS_LOG_RING) {
        *lost += log->total - *seen - SC_HS_LOG_RING;
        *seen = log->total - SC_HS_LOG_RING;
    }
    for (; *seen < log->total; (*seen)++) {
        const sc_hs_log_record *r = &log->ring[*seen % SC_HS_LOG_RING];
        sc_bundle_add_event(w, frame, r->event, r->err, r->a, r->b);
    }
}

/* ---- output ------------------------------------------------------------------------------- */

static int write_frame_png(const options *o, sc_scanconv *conv, uint8_t *raster,
                           const sc_hs_display *d, uint32_t frame_no)
{
    char path[4096];
    snprintf(path, sizeof(path), "%s/frame_%05u.png", o->out_dir, frame_no);
    if (d->colour_lines > 0u && d->last_info.frame_no == d->info.frame_no) {
        /* colour Doppler of the same frame: RGB, the colour plane packed to the image stride */
        static int8_t colour[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
        uint8_t *rgb = malloc(3u * (size_t)conv->cap_w * conv->cap_h); /* fit: width <= cap_w */
        if (rgb != NULL) {
            const uint32_t n = d->last_info.samples;
            for (uint32_t l = 0; l < d->last_info.lines; l++) {
                memcpy(colour + (size_t)l * n, d->colour + (size_t)l * SC_MAX_SCAN_SAMPLES, n);
            }
            sc_scanconv_render_colour(conv, &d->last_info, d->last, colour, n, rgb);
            sc_overlay_draw_rgb(rgb, raster, conv->width, conv->height, &d->last_info);
            const int rc = sc_png_write(path, conv->width, conv->height, 3, rgb, 3u * conv->width);
            free(rgb);
            return rc;
        }
    }
    sc_scanconv_render(conv, &d->last_info, d->last, d->last_info.samples, raster);
    sc_overlay_draw(raster, conv->width, conv->height, &d->last_info);
    return sc_png_write(path, conv->width, conv->height, 1, raster, conv->width);
}

static int write_frame_raw(const char *path, const sc_display_frame_info *info,
                           const uint8_t *image)
{
    FILE *fp = fopen(path, "wb");
    if (!fp) {
        return -1;
    }
    uint8_t h[24] = "SCFRAME1";
    h[8] = (uint8_t)info->lines;
    h[9] = (uint8_t)(info->lines >> 8);
    h[10] = (uint8_t)info->samples;
    h[11] = (uint8_t)(info->samples >> 8);
    h[12] = (uint8_t)info->geometry_id;
    h[13] = (uint8_t)(info->geometry_id >> 8);
    /* probe-face radius in 1/100 mm (0: linear); older files have 0 here */
    const float r_cmm = info->geometry_id == 1u ? info->radius_mm * 100.0f + 0.5f : 0.0f;
    const uint16_t r16 = r_cmm > 0.0f && r_cmm < 65535.0f ? (uint16_t)r_cmm : 0u;
    h[14] = (uint8_t)r16;
    h[15] = (uint8_t)(r16 >> 8);
    memcpy(h + 16, &info->depth_mm, 4);
    memcpy(h + 20, &info->width_mm, 4);
    size_t n = (size_t)info->lines * info->samples;
    int ok = fwrite(h, 1, sizeof(h), fp) == sizeof(h) && fwrite(image, 1, n, fp) == n;
    return (fclose(fp) == 0 && ok) ? 0 : -1;
}

/* The sweep script's length, shortened so that the probe's aperture stays over the case
 * volume: the sweep runs along the tracker's x axis, centred on p_vol (volume frame). */
static float sweep_length_on_case(const sc_case *cs, const sc_scan_def *scan, const float p_vol[3],
                                  float length_mm)
{
    const float ax_t[3] = {1.0f, 0.0f, 0.0f};
    float ax[3];
    sc_xform_rotate(&cs->tracker_to_volume, ax_t, ax);
    const float half_ap = scan->kind == SC_SCAN_GEOM_LINEAR
                              ? 0.5f * scan->width_mm
                              : scan->radius_mm * sinf(scan->sector_deg * (float)M_PI / 360.0f);
    float room = INFINITY; /* how far the centre may move either way */
    for (int a = 0; a < 3; a++) {
        const float c = fabsf(ax[a]);
        if (c < 1e-3f) {
            continue;
        }
        const sc_volume *v = &cs->volume;
        const float lo = v->origin_mm[a] - 0.5f * v->spacing_mm[a];
        const float hi = lo + (float)v->dim[a] * v->spacing_mm[a];
        const float r = fminf(p_vol[a] - lo, hi - p_vol[a]) - half_ap * c;
        room = fminf(room, r / c);
    }
    const float max_len = room > 0.0f ? 2.0f * room : 0.0f;
    if (length_mm > max_len) {
        fprintf(stderr, "sc-hostsim: sweep shortened from %.0f to %.1f mm to stay on the case\n",
                (double)length_mm, (double)max_len);
        return max_len;
    }
    return length_mm;
}

static double mono_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int mkdir_p(const char *dir)
{
    char buf[4096];
    if (strlen(dir) >= sizeof(buf)) {
        return -1;
    }
    strcpy(buf, dir);
    for (char *p = buf + 1; *p; p++) {
        if (*p == '/') {
            *p = '\0';
            if (mkdir(buf, 0755) != 0 && errno != EEXIST) {
                return -1;
            }
            *p = '/';
        }
    }
    return (mkdir(buf, 0755) != 0 && errno != EEXIST) ? -1 : 0;
}

/* ---- main ---------------------------------------------------------------------------------- */

static sc_hs_rig rig; /* about 20 MB: static, allocated once */
static sc_emu emu;
static sc_emu_row csv_rows[100000];

static sc_hs_fault_run faults;
static sc_hs_live live;

/* sc_emu_send_fn over a CAN device (the simulated tracker node); a silence episode discards */
static int send_peer(void *ctx, const sc_can_frame *f)
{
    if (sc_hs_fault_run_silenced(&faults)) {
        return SC_OK;
    }
    return sc_can_send((const sc_can_dev *)ctx, f);
}

int main(int argc, char **argv)
{
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc) {
        return rc < 0 ? 0 : rc;
    }
    if (o.list_dir) {
        return list_bundles(o.list_dir);
    }
    /* a bundle to replay: it names the case, the method and the length */
    static sc_bundle_info binfo;
    uint8_t *bbuf = NULL;
    atexit(free_bundle_buf);
    size_t blen = 0;
    int bundle_replay = 0;
    char bundle_case[SC_BUNDLE_TEXT_MAX + 8];
    if (o.replay_path) {
        rc = sc_bundle_read_file(o.replay_path, BUNDLE_MAX_BYTES, &bbuf, &blen);
        g_bundle_buf = bbuf;
        if (rc != SC_OK) {
            fprintf(stderr, "sc-hostsim: cannot read %s: %s\n", o.replay_path, sc_err_str(rc));
            return 1;
        }
        bundle_replay = sc_bundle_is_bundle(bbuf, blen);
        if (bundle_replay && o.cg_iterations != 0u) {
            fprintf(stderr, "sc-hostsim: %s is a bundle, which does not record --cg-iterations: "
                            "refused (it replays with the budget it was recorded with)\n",
                    o.replay_path);
            return 2;
        }
        if (!bundle_replay) {
            free(bbuf);
            bbuf = NULL;
            g_bundle_buf = NULL;
        } else {
            sc_bundle_reject why;
            uint64_t line;
            if (sc_bundle_parse(bbuf, blen, &binfo, &why, &line) != SC_OK) {
                fprintf(stderr, "sc-hostsim: %s: bundle refused: %s (line %" PRIu64 ")\n",
                        o.replay_path, sc_bundle_reject_name(why), line);
                return 1;
            }
            const sc_bundle_meta *m = &binfo.meta;
            char want[1100];
            snprintf(want, sizeof want, "%s%s", o.case_name,
                     strstr(o.case_name, ".scase") ? "" : ".scase");
            if (o.case_set && strcmp(want, m->case_name) != 0) {
                fprintf(stderr, "sc-hostsim: %s was recorded on case '%s'; --case '%s' is "
                                "another case: refused\n", o.replay_path, m->case_name,
                        o.case_name);
                return 1;
            }
            if ((o.method >= 0 && o.method != (int)m->method) || o.seconds_set || o.faults_set ||
                o.point_set) {
                fprintf(stderr, "sc-hostsim: a bundle sets the method, the length and the "
                                "probe; --method, --seconds, --faults and --point do not apply\n");
                return 2;
            }
            snprintf(bundle_case, sizeof bundle_case, "%s", m->case_name);
            o.case_name = bundle_case;
            o.method = (int)m->method;
            o.rx_cost_ns = (uint64_t)m->rx_cost_us * 1000u;
        }
    }
    if (mkdir_p(o.out_dir) != 0) {
        fprintf(stderr, "sc-hostsim: cannot create %s: %s\n", o.out_dir, strerror(errno));
        return 1;
    }

    /* the kernel variant for this CPU (core/physics/sc_simd.h; SONOCOMP_SIMD overrides): all variants
     * give the same bits, so the outputs do not depend on it */
    if (sc_cpu_select_simd() != SC_OK) {
        fprintf(stderr,
                "sc-hostsim: SONOCOMP_SIMD=%s refused (not built or not on this CPU), using %s\n",
                getenv("SONOCOMP_SIMD"), sc_simd_name(sc_simd_selected()));
    }
    /* the mat-vec's prefetch: a hint, the same bits either way; not measured here (the time is
     * virtual), so the mesh decides unless SONOCOMP_PREFETCH says (sc_cpu.h) */
    if (sc_cpu_select_prefetch(0, NULL) != SC_OK) {
        fprintf(stderr, "sc-hostsim: SONOCOMP_PREFETCH=%s refused (mesh, on or off), by the mesh\n",
                getenv("SONOCOMP_PREFETCH"));
    }

    /* engine on the host simulator, cases mapped from files */
    sc_engine_def def = sc_engine_default_def();
    def.watchdog_timeout_ms = 0; /* no watchdog on the simulator */
    static const char *const catalogue[] = {"neck-ijv.scase", "femoral.scase",
                                            "femoral-dvt.scase"};
    for (uint32_t i = 0; i < 3u; i++) {
        def.case_names[i] = catalogue[i];
    }
    def.case_count = 3u;
    if (o.method >= 0) {
        def.tissue.method = (sc_tissue_method)o.method;
    }
    if (o.cg_iterations != 0u) {
        def.tissue.fem.cg_iterations = o.cg_iterations;
    }
    rc = sc_hs_rig_init(&rig, &def, o.seed, 0);
    if (rc != SC_OK) {
        fprintf(stderr, "sc-hostsim: engine init failed: %s\n", sc_err_str(rc));
        return 1;
    }
    rig.tap.cost_clock = &rig.clock;
    rig.tap.cost_ns = o.rx_cost_ns;
    static sc_storage_linux storage;
    sc_storage_linux_init(&storage, o.cases_dir);
    rig.hal.storage = sc_storage_linux_dev(&storage);

    char case_name[1024];
    if (strchr(o.case_name, '/') || strstr(o.case_name, ".scase")) {
        snprintf(case_name, sizeof(case_name), "%s", o.case_name);
    } else {
        snprintf(case_name, sizeof(case_name), "%s.scase", o.case_name);
    }
    if (bundle_replay && binfo.meta.rate_hz != def.sched.rate_hz) {
        fprintf(stderr, "sc-hostsim: %s was recorded at %u Hz, this engine runs at %u Hz: "
                        "refused\n", o.replay_path, binfo.meta.rate_hz, def.sched.rate_hz);
        return 1;
    }
    rc = sc_engine_load_case(&rig.engine, case_name);
    if (rc != SC_OK && bundle_replay) {
        fprintf(stderr, "sc-hostsim: %s: the bundle's case '%s' %s in %s (%s): refused\n",
                o.replay_path, case_name, rc == SC_ERR_NOT_FOUND ? "is not" : "cannot be loaded",
                o.cases_dir, sc_err_str(rc));
        return 1;
    }
    if (rc != SC_OK) {
        fprintf(stderr, "sc-hostsim: case '%s' refused: %s (%s)%s\n", case_name,
                sc_err_name(rc), sc_err_str(rc),
                rc == SC_ERR_NOT_FOUND ? "; build the cases first (cmake --build ... --target cases)"
                                       : "");
        return 1;
    }
    const sc_case *cs = sc_engine_get_case(&rig.engine);
    if (bundle_replay && cs->case_id != binfo.meta.case_id) {
        fprintf(stderr, "sc-hostsim: %s: case '%s' in %s is not the bundle's: its content id is "
                        "0x%08x, the bundle's 0x%08x: refused\n",
                o.replay_path, case_name, o.cases_dir, cs->case_id, binfo.meta.case_id);
        return 1;
    }

    /* probe: emulator script or replay */
    FILE *replay = NULL;
    sc_candump_reader reader;
    sc_candump_rec pending;
    int have_pending = 0;
    recorder rec = {0};
    size_t bpos = binfo.can_off;
    if (bundle_replay) {
        /* the bundle's CAN records, fed below */
    } else if (o.replay_path) {
        replay = sc_fopen_regular(o.replay_path);
        if (!replay) {
            fprintf(stderr, "sc-hostsim: cannot open %s: %s\n", o.replay_path, strerror(errno));
            return 1;
        }
        sc_candump_reader_init(&reader, replay);
    } else {
        sc_emu_def ed = sc_emu_default_def();
        if (o.csv_path) {
            FILE *fp = sc_fopen_regular(o.csv_path);
            size_t n = 0, bad = 0;
            if (!fp) {
                fprintf(stderr, "sc-hostsim: cannot open %s: %s\n", o.csv_path, strerror(errno));
                return 1;
            }
            rc = sc_emu_load_csv(fp, csv_rows, sizeof(csv_rows) / sizeof(csv_rows[0]), &n, &bad);
            fclose(fp);
            if (rc != SC_OK) {
                fprintf(stderr, "sc-hostsim: %s:%zu: %s\n", o.csv_path, bad, sc_err_str(rc));
                return 1;
            }
            ed.script = SC_EMU_CSV;
            ed.rows = csv_rows;
            ed.n_rows = n;
        } else if (sc_emu_script_from_name(o.script, &ed.script) != SC_OK ||
                   ed.script == SC_EMU_CSV) {
            fprintf(stderr, "sc-hostsim: unknown script '%s' (press, sweep, rock, lift)\n",
                    o.script);
            return 2;
        }
        /* contact point: over the vein of the case unless given, in the tracker frame */
        float p_vol[3];
        if (o.point_set) {
            memcpy(p_vol, o.point_mm, sizeof(p_vol));
        } else {
            /* top centre of the mesh box: the phantoms centre their vessels under it */
            p_vol[0] = cs->mesh.origin_mm[0] + 0.5f * cs->mesh.size_mm[0];
            p_vol[1] = cs->mesh.origin_mm[1] + 0.5f * cs->mesh.size_mm[1];
            p_vol[2] = cs->mesh.origin_mm[2];
        }
        const sc_xform v2t = sc_xform_inverse(&cs->tracker_to_volume);
        sc_xform_apply(&v2t, p_vol, ed.point_mm);
        ed.depth_mm = o.depth_mm;
        if (ed.script == SC_EMU_SWEEP) {
            ed.length_mm = sweep_length_on_case(cs, &rig.engine.bscan.def.scan, p_vol, ed.length_mm);
        }
        ed.duration_s = o.seconds;
        ed.fd = o.fd;
        rc = sc_emu_init(&emu, &ed);
        if (rc != SC_OK) {
            fprintf(stderr, "sc-hostsim: emulator: %s\n", sc_err_str(rc));
            return 2;
        }
        if (o.record_path) {
            rec.fp = fopen(o.record_path, "w");
            if (!rec.fp) {
                fprintf(stderr, "sc-hostsim: cannot write %s: %s\n", o.record_path,
                        strerror(errno));
                return 1;
            }
            rig.tap.fn = record_frame;
            rig.tap.user = &rec;
        }
    }
    static sc_bundle_writer bw;
    if (o.bundle_path) {
        if (sc_bundle_writer_open(&bw) != SC_OK) {
            fprintf(stderr, "sc-hostsim: no temporary file for the bundle\n");
            return 1;
        }
        rec.bundle = &bw;
        rig.tap.fn = record_frame;
        rig.tap.user = &rec;
    }
    static sc_cmdsign signer;
    int call_pending = 0;
    if (o.call) {
        if (sc_cmdsign_init(&signer, sc_secoc_bench_key, 0u, 1000u, 0) != SC_OK) {
            return 1;
        }
        call_pending = 1;
    }
    uint64_t log_seen = rig.log.total, events_lost = 0, hash_mismatches = 0;
    uint32_t first_mismatch = 0;

    char path[4096];
    snprintf(path, sizeof(path), "%s/frames.csv", o.out_dir);
    FILE *csv = fopen(path, "w");
    if (!csv) {
        fprintf(stderr, "sc-hostsim: cannot write %s: %s\n", path, strerror(errno));
        return 1;
    }
    fprintf(csv, "frame,t_s,tracked,contact,vein_area_ratio,artery_area_ratio,state,faults,"
                 "image_hash\n");

    sc_scanconv conv;
    uint8_t *raster = malloc((size_t)o.png_width * o.png_height);
    if (!raster || sc_scanconv_init(&conv, o.png_width, o.png_height) != 0) {
        fprintf(stderr, "sc-hostsim: out of memory\n");
        return 1;
    }
    sc_scanconv_set_fit(&conv, 1); /* the PNG is the image's box: no black band below it */
    static uint8_t deepest[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
    sc_display_frame_info deepest_info = {0};
    float min_vein = 2.0f, artery_at_min = -1.0f, deepest_z = -1e30f;
    int have_vein = 0;
    uint32_t min_vein_frame = 0, contact_frames = 0, pngs = 0, png_errors = 0;
    sc_stats wall;
    sc_stats_reset(&wall);

    const uint64_t period = sc_engine_get_sched(&rig.engine)->period_ns;
    const uint64_t t0 = rig.clock.now_ns;
    if (sc_hs_fault_run_init(&faults, &o.faults, &rig) != SC_OK) {
        fprintf(stderr, "sc-hostsim: no bus node left for the flood\n");
        return 1;
    }
    const int live_on = o.live.pace || o.live.can_port || o.live.state_target ||
                        o.live.dlink_target || o.live.state_file;
    if (live_on) {
        char why[256];
        if (sc_hs_live_open(&live, &o.live, &rig, why, sizeof why) != SC_OK) {
            fprintf(stderr, "sc-hostsim: %s\n", why);
            return 1;
        }
        if (o.live.pace) {
            printf("sc-hostsim: live, case %s, %.0f s at most (SIGINT/SIGTERM stop)\n", case_name,
                   o.seconds);
            fflush(stdout);
        }
    }
    uint32_t frames = bundle_replay ? (uint32_t)binfo.meta.frames
                                    : (uint32_t)ceil(o.seconds * 1e9 / (double)period);
    if (bundle_replay) {
        o.seconds = (double)frames * (double)period * 1e-9;
    }
    const uint64_t call_ns =
        o.call_t_s >= 0.0 ? (uint64_t)llround(o.call_t_s * 1e9)
                          : (uint64_t)llround(fmax(0.0, o.seconds - 0.5) * 1e9);
    for (uint32_t i = 0; i < frames; i++) {
        /* release time of the frame about to run */
        const uint64_t release = sc_engine_next_release_ns(&rig.engine);
        sc_hs_fault_run_before(&faults, release);
        if (live_on) {
            sc_hs_live_before_frame(&live, &rig, release);
            if (sc_hs_live_stop()) {
                frames = i;
                break;
            }
        }
        if (o.live.can_port) {
            /* the probe and the commands come in over UDP */
        } else if (bundle_replay) {
            const char *line;
            size_t len;
            for (;;) {
                if (!have_pending) {
                    size_t p2 = bpos;
                    sc_candump_reject why;
                    if (!sc_bundle_next_line(bbuf, binfo.can_off + binfo.can_len, &p2, &line,
                                             &len) ||
                        sc_candump_parse_line(line, len, &pending, &why) != SC_OK) {
                        break;
                    }
                    bpos = p2;
                    have_pending = 1;
                }
                if (pending.ts_us * 1000u > release) {
                    break;
                }
                (void)sc_hs_can_inject(&rig.bus, rig.engine_node, &pending.frame);
                have_pending = 0;
            }
        } else if (replay) {
            for (;;) {
                if (!have_pending) {
                    int r = sc_candump_reader_next(&reader, &pending);
                    if (r != SC_OK) {
                        break;
                    }
                    have_pending = 1;
                }
                if (pending.ts_us * 1000u > release) {
                    break;
                }
                (void)sc_hs_can_inject(&rig.bus, rig.engine_node, &pending.frame);
                have_pending = 0;
            }
        } else {
            /* every sample due before this frame, from the tracker node */
            (void)sc_emu_feed(&emu, release - t0, send_peer, &rig.peer);
            if (call_pending && release - t0 >= call_ns) {
                /* the trainee's call: a freshness sync, then CmdAssessment, each signed */
                const sc_cmd c = {.kind = SC_CMD_ASSESS, .assess_action = SC_ASSESS_ACTION_CALL,
                                  .assess_call = o.call};
                sc_can_frame cf[4];
                rc = sc_cmdsign_sync(&signer, &cf[0]);
                if (rc == SC_OK) {
                    rc = sc_cmdsign_command(&signer, &c, &cf[2]);
                }
                for (int k = 0; k < 4 && rc == SC_OK; k++) {
                    (void)send_peer(&rig.peer, &cf[k]);
                }
                call_pending = 0;
            }
        }
        const double w0 = mono_s();
        sc_engine_step(&rig.engine, NULL);
        sc_stats_add(&wall, (uint64_t)((mono_s() - w0) * 1e9));
        sc_hs_fault_run_after(&faults, release);

        sc_engine_status st;
        sc_engine_get_status(&rig.engine, &st);
        /* the hash of the last complete frame, computed here: the recorder's history of
         * hashes ends after SC_HS_DISPLAY_HISTORY frames, a session may run longer */
        const uint64_t h =
            rig.display.frames_complete
                ? sc_hs_hash64(rig.display.last, (uint64_t)rig.display.last_info.lines *
                                                     rig.display.last_info.samples, 0)
                : 0u;
        if (o.bundle_path) {
            bundle_events(&bw, &rig.log, &log_seen, i, &events_lost);
            sc_bundle_add_hash(&bw, i, h);
        }
        if (bundle_replay) {
            const char *line;
            size_t len;
            size_t hp = binfo.hash_off;
            static size_t hash_pos;
            if (i == 0u) {
                hash_pos = hp;
            }
            if (sc_bundle_next_line(bbuf, binfo.hash_off + binfo.hash_len, &hash_pos, &line,
                                    &len) &&
                sc_bundle_hash_of_line(line, len) != h) {
                if (hash_mismatches++ == 0u) {
                    first_mismatch = i;
                }
            }
        }
        fprintf(csv, "%u,%.4f,%u,%u,%.4f,%.4f,%s,0x%04x,%016" PRIx64 "\n", i,
                (double)(rig.clock.now_ns - t0) * 1e-9, st.probe_tracked, st.probe_contact,
                (double)st.vein_area_ratio, (double)st.artery_area_ratio,
                sc_health_state_name(st.state), st.faults, h);
        if (st.probe_contact) {
            contact_frames++;
            /* the deepest compression: the smallest vein ratio; a case without a vein label
             * (no ratio) takes the deepest probe position instead, so the image is written */
            const float probe_z = sc_engine_get_probe(&rig.engine)->pose_volume.pos_mm[2];
            const int by_vein = st.vein_area_ratio >= 0.0f && st.vein_area_ratio < min_vein;
            const int by_depth = !have_vein && st.vein_area_ratio < 0.0f && probe_z > deepest_z;
            if (st.vein_area_ratio >= 0.0f) {
                have_vein = 1;
            }
            if (by_depth) {
                deepest_z = probe_z;
            }
            if (by_vein || by_depth) {
                if (by_vein) {
                    min_vein = st.vein_area_ratio;
                }
                artery_at_min = st.artery_area_ratio;
                min_vein_frame = i;
                deepest_info = rig.display.last_info;
                memcpy(deepest, rig.display.last,
                       (size_t)deepest_info.lines * deepest_info.samples);
            }
        }
        if (o.every && i % o.every == 0u && rig.display.frames_complete) {
            if (write_frame_png(&o, &conv, raster, &rig.display, i) == 0) {
                pngs++;
            } else {
                png_errors++;
            }
        }
        if (!o.quiet && i % 60u == 59u) {
            printf("t=%5.2fs frame %5u state=%-8s tracked=%u contact=%u vein=%5.2f artery=%5.2f\n",
                   (double)(rig.clock.now_ns - t0) * 1e-9, i + 1u, sc_health_state_name(st.state),
                   st.probe_tracked, st.probe_contact, (double)st.vein_area_ratio,
                   (double)st.artery_area_ratio);
        }
    }
    fclose(csv);
    if (rec.fp) {
        fclose(rec.fp);
    }
    const sc_assess_report *ar = sc_engine_assessment(&rig.engine);
    int bundle_rc = SC_OK;
    if (o.bundle_path) {
        sc_bundle_meta m;
        memset(&m, 0, sizeof m);
        const char *base = strrchr(case_name, '/') ? strrchr(case_name, '/') + 1 : case_name;
        if (strlen(base) >= sizeof m.case_name) {
            base = ""; /* refused by the writer below: a bundle names its case in 127 bytes */
        }
        memcpy(m.case_name, base, strlen(base) + 1u);
        m.case_id = cs->case_id;
        m.method = (uint8_t)(sc_engine_get_tissue(&rig.engine) != NULL &&
                             rig.engine.def.tissue.method == SC_TISSUE_FEM);
        m.rate_hz = def.sched.rate_hz;
        m.frames = frames;
        m.rx_cost_us = (uint32_t)(o.rx_cost_ns / 1000u);
        const char *src = o.csv_path ? o.csv_path : o.script;
        snprintf(m.source, sizeof m.source, "%s%s", o.csv_path ? "csv:" : "script:", src);
        for (char *q = m.source; *q; q++) {
            *q = (*q == ' ' || (unsigned char)*q < 0x20u || (unsigned char)*q > 0x7Eu) ? '_' : *q;
        }
        const time_t now = time(NULL);
        struct tm tmv;
        if (gmtime_r(&now, &tmv) == NULL ||
            strftime(m.date, sizeof m.date, "%Y-%m-%dT%H:%M:%SZ", &tmv) == 0u) {
            snprintf(m.date, sizeof m.date, "unknown");
        }
        m.score = ar->score;
        m.score_max = ar->score_max;
        m.criteria = ar->criteria_met;
        m.call = ar->call;
        m.finding = ar->finding;
        for (int v = 0; v < 3; v++) {
            m.min_ratio[v] = ar->vessel[v].min_ratio;
        }
        m.peak_force_n = ar->peak_force_n;
        bundle_rc = sc_bundle_writer_finish(&bw, &m, o.bundle_path);
        sc_bundle_writer_close(&bw);
        if (bundle_rc != SC_OK) {
            fprintf(stderr, "sc-hostsim: cannot write the bundle %s: %s\n", o.bundle_path,
                    sc_err_str(bundle_rc));
        }
    }
    if (replay) {
        fclose(replay);
    }
    if (deepest_info.lines) {
        sc_scanconv_render(&conv, &deepest_info, deepest, deepest_info.samples, raster);
        sc_overlay_draw(raster, conv.width, conv.height, &deepest_info);
        snprintf(path, sizeof(path), "%s/deepest_compression.png", o.out_dir);
        if (sc_png_write(path, conv.width, conv.height, 1, raster, conv.width) == 0) {
            pngs++;
        }
        if (o.frame_raw_path && write_frame_raw(o.frame_raw_path, &deepest_info, deepest) != 0) {
            fprintf(stderr, "sc-hostsim: cannot write %s\n", o.frame_raw_path);
        }
    }

    /* summary */
    sc_engine_status st;
    sc_engine_get_status(&rig.engine, &st);
    const sc_tracker *trk = sc_engine_get_tracker(&rig.engine);
    const sc_trk_counters *tc = sc_tracker_counters(trk);
    const sc_tissue *tis = sc_engine_get_tissue(&rig.engine);
    const uint64_t last_hash =
        rig.display.hash_count ? rig.display.hashes[rig.display.hash_count - 1u] : 0u;
    snprintf(path, sizeof(path), "%s/summary.txt", o.out_dir);
    FILE *sf = fopen(path, "w");
    FILE *outs[2] = {stdout, sf};
    for (int k = 0; k < 2; k++) {
        FILE *f = outs[k];
        if (!f) {
            continue;
        }
        fprintf(f, "sonocomp host simulator run\n");
        fprintf(f, "case            %s (%s), volume %ux%ux%u, mesh %ux%ux%u = %u nodes, %u tets\n",
                cs->name, case_name, cs->volume.dim[0], cs->volume.dim[1], cs->volume.dim[2],
                cs->mesh.nx, cs->mesh.ny, cs->mesh.nz, tis ? tis->mesh.node_count : 0u,
                tis ? tis->mesh.tet_count : 0u);
        fprintf(f, "probe           %s%s, %.2f s simulated, %u frames at %u Hz\n",
                o.live.can_port ? "CAN over UDP, " : (replay ? "replay of " : (o.csv_path ? "csv " : "script ")),
                o.live.can_port ? "live" : (replay ? o.replay_path : (o.csv_path ? o.csv_path : o.script)), o.seconds,
                frames, def.sched.rate_hz);
        fprintf(f, "method          %s, %u CG iterations per frame\n",
                st.method == SC_TISSUE_FEM ? "fem" : "msds",
                tis ? (unsigned)tis->fem.def.cg_iterations : 0u);
        fprintf(f, "display         %" PRIu64 " complete frames, %" PRIu64
                   " incomplete, %" PRIu64 " protocol errors\n",
                rig.display.frames_complete, rig.display.frames_incomplete,
                rig.display.protocol_errors);
        if (have_vein) {
            char art[48];
            if (artery_at_min >= 0.0f) {
                snprintf(art, sizeof art, "artery %.3f there", (double)artery_at_min);
            } else {
                snprintf(art, sizeof art, "no artery label in the case");
            }
            fprintf(f, "compression     min vein area ratio %.3f at frame %u (%s); "
                       "%u frames in contact\n",
                    (double)min_vein, min_vein_frame, art, contact_frames);
        } else if (contact_frames) {
            /* no vein in this case (or never seen): say so instead of a -1 ratio */
            fprintf(f, "compression     no vein label in the case; deepest press at frame %u "
                       "(artery %s); %u frames in contact\n",
                    min_vein_frame, artery_at_min >= 0.0f ? "measured" : "none in the case",
                    contact_frames);
            if (artery_at_min >= 0.0f) {
                fprintf(f, "                artery area ratio %.3f there\n", (double)artery_at_min);
            }
        } else {
            fprintf(f, "compression     no frame in contact\n");
        }
        fprintf(f, "tracker         %u frames, %u poses accepted, %u E2E rejects, "
                   "%u implausible, %u lift events\n",
                tc->frames, tc->outcome[SC_TRK_POSE_ACCEPTED],
                sc_tracker_rejected_e2e(trk), sc_tracker_rejected_implausible(trk),
                tc->lift_events);
        fprintf(f, "tracker dups    %u duplicates (not rejects) of %" PRIu64
                   " the bus duplicated from the tracker; %u commands refused by "
                   "authentication\n",
                tc->outcome[SC_TRK_DUPLICATE], rig.bus.by_sender[rig.peer_node].duplicated,
                sc_tracker_rejected_auth(trk));
        fprintf(f, "health          raised: tracker data %u, tracker timeout %u, bus-off %u, "
                   "display link %u, deadline %u\n",
                rig.engine.health.raised[SC_FAULT_TRACKER_DATA],
                rig.engine.health.raised[SC_FAULT_TRACKER_TIMEOUT],
                rig.engine.health.raised[SC_FAULT_CAN_BUS_OFF],
                rig.engine.health.raised[SC_FAULT_DISPLAY_LINK],
                rig.engine.health.raised[SC_FAULT_DEADLINE]);
        fprintf(f, "bus faults      injected: %" PRIu64 " dropped, %" PRIu64 " corrupted, %" PRIu64
                   " duplicated, %" PRIu64 " reordered; %" PRIu64 " error frames; engine node: "
                   "%" PRIu64 " filtered, %u overruns\n",
                rig.bus.injected.dropped, rig.bus.injected.corrupted,
                rig.bus.injected.duplicated, rig.bus.injected.reordered,
                rig.bus.injected.error_frames, rig.bus.nodes[rig.engine_node].rx_filtered,
                rig.bus.nodes[rig.engine_node].rx_overruns);
        fprintf(f, "deadline        %" PRIu64 " misses on the virtual clock (rx cost %" PRIu64
                   " ns per CAN frame), %" PRIu64 " frames with the rx drain at its bound\n",
                rig.engine.sched.misses, o.rx_cost_ns,
                sc_engine_get_counters(&rig.engine)->can_rx_burst_limited);
        for (uint32_t ei = 0; ei < faults.plan.n; ei++) {
            const sc_hs_episode *e = &faults.plan.ep[ei];
            fprintf(f, "episode %-8s %.3f..%.3f s: fault raised %u times, recovered %d frames "
                       "after, %u untracked frames, injected %" PRIu64 ", filtered %" PRIu64 "\n",
                    sc_hs_episode_kind_name(e->kind), (double)e->start_ns * 1e-9,
                    e->end_ns == UINT64_MAX ? o.seconds : (double)e->end_ns * 1e-9, e->edges,
                    e->recover_frames, e->untracked_frames, e->injected, e->filtered);
        }
        if (faults.silenced) {
            fprintf(f, "silence         %" PRIu64 " tracker frames not sent\n", faults.silenced);
        }
        fprintf(f, "host CPU time   per frame mean %.3f ms, p99 %.3f ms, worst %.3f ms "
                   "(wall clock on this host)\n",
                (double)sc_stats_mean_ns(&wall) * 1e-6,
                (double)sc_stats_percentile_ns(&wall, 990) * 1e-6, (double)wall.worst_ns * 1e-6);
        fprintf(f, "final state     %s, faults 0x%04x\n", sc_health_state_name(st.state),
                st.faults);
        fprintf(f, "hashes          last image %016" PRIx64 ", tissue state %016" PRIx64 "\n",
                last_hash, sc_engine_state_hash(&rig.engine));
        fprintf(f, "output          %u PNG files%s in %s, frames.csv, summary.txt\n", pngs,
                png_errors ? " (some failed)" : "", o.out_dir);
        if (rec.fp) {
            fprintf(f, "recorded        %" PRIu64 " frames to %s\n", rec.frames, o.record_path);
        }
        fprintf(f, "assessment      score %u/%u (criteria 0x%02x), call %s, finding %s, vein "
                   "min %.3f%s, peak force %.2f N\n",
                ar->score, ar->score_max, ar->criteria_met, sc_bundle_call_name(ar->call),
                sc_bundle_call_name(ar->finding), (double)ar->vessel[SC_ASSESS_VEIN].min_ratio,
                ar->vessel[SC_ASSESS_VEIN].coapted ? " (coapted)" : "",
                (double)ar->peak_force_n);
        if (o.bundle_path && bundle_rc == SC_OK) {
            fprintf(f, "bundle          %s: %u frames, %" PRIu64 " CAN records, %" PRIu64
                       " events (%" PRIu64 " lost)\n",
                    o.bundle_path, frames, bw.n_can, bw.n_ev, events_lost);
        }
        if (bundle_replay) {
            fprintf(f, "bundle replay   %u frames: %s", frames,
                    hash_mismatches ? "IMAGE HASHES DIFFER" : "every image hash identical");
            if (hash_mismatches) {
                fprintf(f, " (%" PRIu64 " frames, the first at frame %u)", hash_mismatches,
                        first_mismatch);
            }
            fprintf(f, "; recorded score %u/%u, replayed %u/%u\n", binfo.meta.score,
                    binfo.meta.score_max, ar->score, ar->score_max);
        }
        if (live_on) {
            sc_hs_live_summary(&live, &rig, f);
        }
    }
    if (sf) {
        fclose(sf);
    }
    if (live_on) {
        sc_hs_live_close(&live);
    }
    sc_scanconv_free(&conv);
    free(raster);
    return (png_errors || rec.errors || bundle_rc != SC_OK || hash_mismatches) ? 1 : 0;
}
