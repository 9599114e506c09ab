/*
 * sc_viewer.c: `sc-viewer`, the display controller's stand-in on the bench.
 *
 * Receives the display link (docs/display-link.md) on a UDP port, assembles frames with
 * core/sc_dlink (counting lost, late and duplicate lines and rejected packets), shows them live
 * in an SDL2 window with an overlay (frame rate, probe contact, the vessels' compression
 * measure, losses), and can record PNG frames and an animated GIF of the session. Exits by
 * itself after --frames N closed frames, --seconds S, or --idle S without packets, and prints a
 * one-line key=value summary on stdout (what the loopback test reads).
 *
 * Threads: a receiver thread owns the socket and the assembler (so that slow rendering or a
 * slow disk never makes the socket overflow); closed frames go through a small queue to the
 * main thread, which renders, records and shows them. A frame the main thread could not take
 * in time is counted (frames_not_shown), never the receiver's concern.
 */
#include <arpa/inet.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#ifdef SC_VIEWER_SDL
#include <SDL.h>
#endif

#include "sc_dlink.h"
#include "sc_err.h"
#include "sc_png_write.h"
#include "sc_scan_overlay.h"
#include "vw_cine.h"
#include "sc_scanconv.h"
#include "sc_doppler.h"
#include "vw_gif.h"
#include "vw_overlay.h"

#define VW_QUEUE   4u
#define VW_VERSION "1.0"

typedef struct vw_opts {
    const char *bind_addr;
    const char *sender;      /* accepted source address, "any": every source */
    int sender_any;
    struct in_addr sender_ip; /* resolved sender */
    uint16_t port;
    int headless;
    uint64_t frames; /* 0: no limit */
    double seconds;  /* 0: no limit */
    double idle_s;   /* 0: no limit; counted from the first packet */
    const char *png_dir;
    uint32_t png_every;
    const char *gif_path;
    uint32_t gif_every;
    const char *screenshot;
    uint32_t width, height;
    double hold_s; /* keep the window showing the last frame this long before exiting */
    int quiet;
} vw_opts;

typedef struct vw_slot {
    sc_dlink_done done; /* image pointer replaced by the slot's own copy */
    uint8_t image[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
} vw_slot;

typedef struct vw_shared {
    pthread_mutex_t lock;
    pthread_cond_t cond;
    sc_dlink_asm rx; /* under lock */
    vw_slot slots[VW_QUEUE];
    uint32_t q_head, q_tail; /* q_head - q_tail frames waiting */
    uint64_t frames_not_shown;
    uint64_t frames_target; /* 0: none; the receiver stops taking packets once reached */
    double first_packet_s;  /* 0 until the first datagram */
    double last_packet_s;
    atomic_int stop_rx;
    int fd;
    int sender_any;
    struct in_addr sender_ip;
    uint64_t rej_sender;   /* datagrams from another source: refused, under lock */
    struct in_addr last_refused;
} vw_shared;

static vw_shared g_sh;
static volatile sig_atomic_t g_signal;

static void on_signal(int sig)
{
    g_signal = sig;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Caller holds the lock. */
static void enqueue_done(vw_shared *sh)
{
    const sc_dlink_done *d = sc_dlink_asm_done(&sh->rx);
    if (!d) {
        return;
    }
    if (sh->q_head - sh->q_tail >= VW_QUEUE) {
        sh->q_tail++; /* drop the oldest waiting frame */
        sh->frames_not_shown++;
    }
    vw_slot *s = &sh->slots[sh->q_head % VW_QUEUE];
    s->done = *d;
    memcpy(s->image, d->image, (size_t)d->frame.line_count * SC_MAX_SCAN_SAMPLES);
    s->done.image = s->image;
    sh->q_head++;
    pthread_cond_signal(&sh->cond);
}

static uint64_t frames_closed(const vw_shared *sh)
{
    return sh->rx.stats.frames_complete + sh->rx.stats.frames_incomplete;
}

static void *rx_main(void *arg)
{
    vw_shared *sh = arg;
    uint8_t buf[2048];
    struct pollfd p = {sh->fd, POLLIN, 0};
    while (!atomic_load(&sh->stop_rx)) {
        if (poll(&p, 1, 20) <= 0) {
            continue;
        }
        for (;;) {
            struct sockaddr_in from;
            socklen_t from_len = sizeof from;
            memset(&from, 0, sizeof from);
            ssize_t n = recvfrom(sh->fd, buf, sizeof buf, MSG_DONTWAIT, (struct sockaddr *)&from,
                                 &from_len);
            if (n < 0) {
                break;
            }
            const double t = now_s();
            pthread_mutex_lock(&sh->lock);
            if (!sh->sender_any && (from.sin_family != AF_INET ||
                                    from.sin_addr.s_addr != sh->sender_ip.s_addr)) {
                /* only the configured sender's frames: a forged CRC-valid frame from
                 * anyone else is refused before it reaches the assembler */
                sh->rej_sender++;
                sh->last_refused = from.sin_addr;
                pthread_mutex_unlock(&sh->lock);
                continue;
            }
            if (atomic_load(&sh->stop_rx) ||
                (sh->frames_target && frames_closed(sh) >= sh->frames_target)) {
                pthread_mutex_unlock(&sh->lock);
                continue; /* drain the socket without counting */
            }
            if (sh->first_packet_s <= 0.0) {
                sh->first_packet_s = t;
            }
            sh->last_packet_s = t;
            if (sc_dlink_asm_push(&sh->rx, buf, (size_t)n) == 1) {
                enqueue_done(sh);
            }
            pthread_mutex_unlock(&sh->lock);
        }
    }
    return NULL;
}

/* An IPv4 address of a name or dotted quad: 0, or -1 when it does not resolve. */
static int resolve_ipv4(const char *name, struct in_addr *out)
{
    struct addrinfo hints, *res = NULL;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_DGRAM;
    if (getaddrinfo(name, NULL, &hints, &res) != 0 || !res) {
        return -1;
    }
    *out = ((const struct sockaddr_in *)(const void *)res->ai_addr)->sin_addr;
    freeaddrinfo(res);
    return 0;
}

/* The accepted sender: --sender, or the loopback engine when the viewer listens on loopback.
 * 0, or 2 (usage error, printed). */
static int resolve_sender(vw_opts *o)
{
    if (o->sender && strcmp(o->sender, "any") == 0) {
        o->sender_any = 1;
        return 0;
    }
    if (o->sender == NULL) {
        struct in_addr b;
        if (resolve_ipv4(o->bind_addr, &b) != 0 || (ntohl(b.s_addr) >> 24) != 127u) {
            fprintf(stderr, "sc-viewer: --bind %s is not a loopback address: name the display "
                            "link's sender with --sender ADDR (or --sender any)\n",
                    o->bind_addr);
            return 2;
        }
        o->sender = "127.0.0.1";
    }
    if (resolve_ipv4(o->sender, &o->sender_ip) != 0) {
        fprintf(stderr, "sc-viewer: --sender %s: not an IPv4 address or host name\n", o->sender);
        return 2;
    }
    return 0;
}

static int open_socket(const vw_opts *o)
{
    struct addrinfo hints, *res = NULL;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_DGRAM;
    hints.ai_flags = AI_PASSIVE;
    char port[8];
    snprintf(port, sizeof port, "%u", (unsigned)o->port);
    if (getaddrinfo(o->bind_addr, port, &hints, &res) != 0 || !res) {
        fprintf(stderr, "sc-viewer: cannot resolve %s\n", o->bind_addr);
        return -1;
    }
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        freeaddrinfo(res);
        return -1;
    }
    /* a few frames of slack; FORCE passes net.core.rmem_max when we may (root) */
    int rcv = 8 * 1024 * 1024;
    if (setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &rcv, sizeof rcv) != 0) {
        (void)setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcv, sizeof rcv);
    }
    if (bind(fd, res->ai_addr, res->ai_addrlen) != 0) {
        fprintf(stderr, "sc-viewer: bind %s:%u: %s\n", o->bind_addr, (unsigned)o->port,
                strerror(errno));
        freeaddrinfo(res);
        close(fd);
        return -1;
    }
    freeaddrinfo(res);
    return fd;
}

/* ---- rendering -------------------------------------------------------------------------- */

typedef struct vw_render {
    sc_scanconv conv;
    uint8_t *grey;  /* w*h scan-converted */
    uint8_t *index; /* w*h palette indices with overlay */
    uint8_t *rgb;   /* w*h*3 */
    uint8_t palette[768];
    uint32_t w, h;
    /* pulsed-wave Doppler: the last VW_SPEC_COLS spectrum columns, scrolling */
    uint8_t spec[256][SC_DLINK_SPECTRUM_MAX];
    uint32_t spec_n, spec_head;
    uint16_t spec_bins;
} vw_render;

#define VW_SPEC_COLS 256u

static int render_init(vw_render *r, uint32_t w, uint32_t h)
{
    memset(r, 0, sizeof *r);
    r->w = w;
    r->h = h;
    r->grey = calloc((size_t)w * h, 1);
    r->index = calloc((size_t)w * h, 1);
    r->rgb = calloc((size_t)w * h * 3u, 1);
    vw_palette(r->palette);
    return (r->grey && r->index && r->rgb && sc_scanconv_init(&r->conv, w, h) == 0) ? 0 : -1;
}

static void render_free(vw_render *r)
{
    sc_scanconv_free(&r->conv);
    free(r->grey);
    free(r->index);
    free(r->rgb);
}

/* Colour Doppler (display link version 3) over the RGB raster: the colour plane through the
 * scan converter's table (scanner map: red toward the probe, blue away), and the pulsed-wave
 * spectrum as a scrolling strip at the bottom right (velocity up = toward, zero line marked). */
static void render_doppler(vw_render *r, const sc_dlink_done *d)
{
    if (d->colour != NULL) {
        const size_t n = (size_t)r->w * r->h;
        for (size_t i = 0; i < n; i++) {
            const uint32_t v = r->conv.lut[i];
            if (v != UINT32_MAX && d->colour[v] != 0) {
                sc_doppler_colour_rgb(d->colour[v], r->rgb + 3u * i);
            }
        }
    }
    if (!d->doppler_seen || d->doppler.bins == 0u) {
        return;
    }
    r->spec_bins = d->doppler.bins;
    memcpy(r->spec[r->spec_head], d->doppler.spectrum, d->doppler.bins);
    r->spec_head = (r->spec_head + 1u) % VW_SPEC_COLS;
    r->spec_n = r->spec_n < VW_SPEC_COLS ? r->spec_n + 1u : VW_SPEC_COLS;
    const uint32_t sh = r->spec_bins / 2u; /* two bins per row */
    const uint32_t sw = r->w < VW_SPEC_COLS ? r->w : VW_SPEC_COLS;
    if (r->h < sh + 4u) {
        return;
    }
    const uint32_t y0 = r->h - sh - 2u, x0 = r->w - sw;
    for (uint32_t c = 0; c < sw; c++) {
        /* newest column at the right */
        const uint32_t age = sw - 1u - c;
        const uint8_t *col =
            age < r->spec_n ? r->spec[(r->spec_head + VW_SPEC_COLS - 1u - age) % VW_SPEC_COLS]
                            : NULL;
        for (uint32_t y = 0; y < sh; y++) {
            const uint32_t bin = r->spec_bins - 1u - 2u * y; /* top: fastest toward */
            uint8_t g = col ? (uint8_t)(col[bin] > col[bin - 1u] ? col[bin] : col[bin - 1u]) : 0u;
            if (y == sh / 2u) {
                g = 128u; /* the zero-velocity line */
            }
            uint8_t *px = r->rgb + 3u * ((size_t)(y0 + y) * r->w + x0 + c);
            px[0] = px[1] = px[2] = g;
        }
    }
}

static void render_frame(vw_render *r, const sc_dlink_done *d, double fps, uint64_t lost_total)
{
    sc_display_frame_info info = {.frame_no = d->frame.frame_no,
                                  .lines = d->frame.line_count,
                                  .samples = d->frame.samples,
                                  .geometry_id = d->frame.geometry_id,
                                  .flags = d->frame.flags,
                                  .depth_mm = d->begin.depth_mm,
                                  .width_mm = d->begin.width_mm,
                                  .radius_mm = d->begin.radius_mm};
    if (d->params_known) { /* FRAME_PARAMS: the readout and the focus marker */
        info.gain_db = d->params.gain_db;
        info.dynamic_range_db = d->params.dynamic_range_db;
        info.focus_mm = d->params.focus_mm;
        info.frequency_mhz = d->params.frequency_mhz;
        for (uint32_t i = 0; i < SC_DLINK_PARAMS_TGC && i < SC_DISPLAY_TGC_BANDS; i++) {
            info.tgc_db[i] = d->params.tgc_db[i];
        }
    }
    sc_scanconv_render(&r->conv, &info, d->image, SC_MAX_SCAN_SAMPLES, r->grey);
    /* the scanner's display items below the viewer's own band (sc_scan_overlay.h: depth
     * scale, orientation, probe type; what the link does not carry is left out) */
    const int band_px = (r->w >= 400u ? 2 : 1) * 9 * 2 + 4;
    sc_overlay_draw_below(r->grey, r->w, r->h, &info, band_px);
    const size_t n = (size_t)r->w * r->h;
    for (size_t i = 0; i < n; i++) {
        r->index[i] = vw_grey_index(r->grey[i]);
    }
    /* overlay: a band with two lines of text at scale 2 */
    const int sc = r->w >= 400u ? 2 : 1;
    const int lh = 9 * sc;
    vw_fill_rect(r->index, r->w, r->h, 0, 0, (int)r->w, 2 * lh + 4, VW_COL_BAND);
    char t[96];
    snprintf(t, sizeof t, "FPS %.1f  FRAME %u", fps, (unsigned)d->frame.frame_no);
    int x = vw_text(r->index, r->w, r->h, 4, 2, sc, VW_COL_TEXT, t);
    snprintf(t, sizeof t, "  LOST %llu", (unsigned long long)lost_total);
    vw_text(r->index, r->w, r->h, x, 2, sc, lost_total ? VW_COL_WARN : VW_COL_TEXT, t);
    const int contact = (d->frame.flags & 1u) != 0;
    x = vw_text(r->index, r->w, r->h, 4, 2 + lh, sc, contact ? VW_COL_OK : VW_COL_BAD,
                contact ? "CONTACT" : "NO CONTACT");
    if (d->end.compression_pm <= 1000u) {
        snprintf(t, sizeof t, "  VEIN COMPRESSION %u%%",
                 (unsigned)(d->end.compression_pm + 5u) / 10u);
    } else {
        snprintf(t, sizeof t, "  VEIN COMPRESSION --");
    }
    x = vw_text(r->index, r->w, r->h, x, 2 + lh, sc, VW_COL_VESSEL, t);
    if (d->frame.flags & 2u) {
        vw_text(r->index, r->w, r->h, x, 2 + lh, sc, VW_COL_WARN, "  FROZEN");
    }
    if (d->lines_lost) {
        /* a red tick at the right edge marks a frame with lost lines */
        vw_fill_rect(r->index, r->w, r->h, (int)r->w - 3 * sc - 4, 4, 3 * sc, 2 * lh - 4,
                     VW_COL_BAD);
    }
    for (size_t i = 0; i < n; i++) {
        memcpy(r->rgb + 3u * i, r->palette + 3u * r->index[i], 3u);
    }
    render_doppler(r, d);
}

/* ---- freeze, cine loop, calipers (window only) ------------------------------------------- */

/* The viewer's cine loop: the last VW_CINE_FRAMES frames (2 s at 60 Hz). */
#define VW_CINE_FRAMES 120u

typedef struct vw_freeze {
    vw_cine cine;
    int frozen;
    uint32_t back; /* cine position: frames before the newest */
    int cal_n;     /* caliper points set (0..2) */
    double cal[2][2];
} vw_freeze;

#ifdef SC_VIEWER_SDL
/* A frozen cine frame with the calipers and their distance in mm. */
static void render_frozen(vw_render *r, vw_freeze *fz)
{
    const sc_dlink_done *d = vw_cine_get(&fz->cine, fz->back);
    if (d == NULL) {
        return;
    }
    render_frame(r, d, 0.0, 0u);
    const int sc = r->w >= 400u ? 2 : 1;
    char t[96];
    snprintf(t, sizeof t, "FROZEN  CINE -%u/%u", (unsigned)fz->back, (unsigned)fz->cine.count);
    vw_text(r->index, r->w, r->h, 4, (int)r->h - 10 * sc, sc, VW_COL_WARN, t);
    for (int i = 0; i < fz->cal_n; i++) {
        vw_fill_rect(r->index, r->w, r->h, (int)fz->cal[i][0] - 3, (int)fz->cal[i][1], 7, 1,
                     VW_COL_VESSEL);
        vw_fill_rect(r->index, r->w, r->h, (int)fz->cal[i][0], (int)fz->cal[i][1] - 3, 1, 7,
                     VW_COL_VESSEL);
    }
    if (fz->cal_n == 2) {
        const sc_display_frame_info info = {.lines = d->frame.line_count,
                                            .samples = d->frame.samples,
                                            .geometry_id = d->frame.geometry_id,
                                            .depth_mm = d->begin.depth_mm,
                                            .width_mm = d->begin.width_mm,
                                            .radius_mm = d->begin.radius_mm};
        const double mm = vw_caliper_mm(&info, r->w, r->h, fz->cal[0][0], fz->cal[0][1],
                                        fz->cal[1][0], fz->cal[1][1]);
        snprintf(t, sizeof t, "DIST %.1f MM", mm);
        vw_text(r->index, r->w, r->h, 4, (int)r->h - 20 * sc, sc, VW_COL_VESSEL, t);
    }
    const size_t n = (size_t)r->w * r->h;
    for (size_t i = 0; i < n; i++) {
        memcpy(r->rgb + 3u * i, r->palette + 3u * r->index[i], 3u);
    }
}
#endif

/* ---- main ------------------------------------------------------------------------------- */

static void usage(FILE *f)
{
    fprintf(f, "usage: sc-viewer [options]\n"
               "Receive the sonocomp display link (docs/display-link.md), show and record it.\n\n"
               "  -p, --port N          UDP port (default 5600)\n"
               "  -b, --bind ADDR       local address (default 127.0.0.1, loopback only)\n"
               "  -s, --sender ADDR     accept datagrams from this IPv4 address or host only\n"
               "                        (default 127.0.0.1; needed with a non-loopback --bind;\n"
               "                        any: from everyone); others are refused and counted\n"
               "      --headless        no window (tests, recording on a server)\n"
               "  -n, --frames N        exit after N closed frames\n"
               "  -t, --seconds S       exit after S seconds\n"
               "      --idle S          exit S seconds after the last packet (once one arrived)\n"
               "      --record-png DIR  write frames as DIR/view_<frame>.png (DIR must exist)\n"
               "      --png-every N     record every N-th shown frame (default 1)\n"
               "      --gif FILE        record an animated GIF of the session\n"
               "      --gif-every N     every N-th shown frame goes into the GIF (default 2)\n"
               "      --screenshot FILE PNG of the window content at exit\n"
               "      --size WxH        raster / window size (default 640x640)\n"
               "      --hold S          keep the window open S seconds after the end\n"
               "  -q, --quiet           no per-second status on stderr\n"
               "  -h, --help            this help\n"
               "  -V, --version         version\n\n"
               "Window keys: space freezes (and unfreezes) the image; while frozen, left /\n"
               "right step back / forward through the cine loop of the last 120 frames and\n"
               "two mouse clicks set calipers (distance in mm); Esc or q quits.\n"
               "At exit prints one line of key=value statistics on stdout.\n"
               "Exit status: 0 ok, 1 runtime error, 2 usage error.\n");
}

static int parse_u64(const char *s, uint64_t *out)
{
    char *end = NULL;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || !end || *end || s[0] == '-' || end == s) {
        return -1;
    }
    *out = v;
    return 0;
}

static int parse_double(const char *s, double *out)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || !end || *end || end == s || !isfinite(v) || v < 0.0) {
        return -1;
    }
    *out = v;
    return 0;
}

/* The command line into *o (nothing else is touched: tests/fuzz/fuzz_cli_viewer.c calls it).
 * Returns -1 to go on, 0 after --help or --version, 2 for a usage error. */
static int parse_opts(int argc, char **argv, vw_opts *o)
{
    *o = (vw_opts){.bind_addr = "127.0.0.1",
                   .sender = NULL,
                   .port = 5600u,
                   .png_every = 1u,
                   .gif_every = 2u,
                   .width = 640u,
                   .height = 640u};
    optind = 0; /* glibc: a full re-initialisation, so that it can be called again */
    enum {
        OPT_HEADLESS = 1000,
        OPT_IDLE,
        OPT_PNG,
        OPT_PNG_EVERY,
        OPT_GIF,
        OPT_GIF_EVERY,
        OPT_SHOT,
        OPT_SIZE,
        OPT_HOLD
    };
    static const struct option lo[] = {{"port", required_argument, NULL, 'p'},
                                       {"bind", required_argument, NULL, 'b'},
                                       {"sender", required_argument, NULL, 's'},
                                       {"headless", no_argument, NULL, OPT_HEADLESS},
                                       {"frames", required_argument, NULL, 'n'},
                                       {"seconds", required_argument, NULL, 't'},
                                       {"idle", required_argument, NULL, OPT_IDLE},
                                       {"record-png", required_argument, NULL, OPT_PNG},
                                       {"png-every", required_argument, NULL, OPT_PNG_EVERY},
                                       {"gif", required_argument, NULL, OPT_GIF},
                                       {"gif-every", required_argument, NULL, OPT_GIF_EVERY},
                                       {"screenshot", required_argument, NULL, OPT_SHOT},
                                       {"size", required_argument, NULL, OPT_SIZE},
                                       {"quiet", no_argument, NULL, 'q'},
                                       {"hold", required_argument, NULL, OPT_HOLD},
                                       {"help", no_argument, NULL, 'h'},
                                       {"version", no_argument, NULL, 'V'},
                                       {NULL, 0, NULL, 0}};
    int c;
    uint64_t u;
    while ((c = getopt_long(argc, argv, "p:b:s:n:t:qhV", lo, NULL)) != -1) {
        switch (c) {
        case 'p':
            if (parse_u64(optarg, &u) || u == 0u || u > 65535u) {
                fprintf(stderr, "sc-viewer: --port %s: expected 1..65535\n", optarg);
                return 2;
            }
            o->port = (uint16_t)u;
            break;
        case 'b':
            o->bind_addr = optarg;
            break;
        case 's':
            o->sender = optarg;
            break;
        case OPT_HEADLESS:
            o->headless = 1;
            break;
        case 'n':
            if (parse_u64(optarg, &o->frames)) {
                fprintf(stderr, "sc-viewer: --frames %s: expected a count\n", optarg);
                return 2;
            }
            break;
        case 't':
            if (parse_double(optarg, &o->seconds)) {
                fprintf(stderr, "sc-viewer: --seconds %s: expected seconds\n", optarg);
                return 2;
            }
            break;
        case OPT_IDLE:
            if (parse_double(optarg, &o->idle_s)) {
                fprintf(stderr, "sc-viewer: --idle %s: expected seconds\n", optarg);
                return 2;
            }
            break;
        case OPT_PNG:
            o->png_dir = optarg;
            break;
        case OPT_HOLD:
            if (parse_double(optarg, &o->hold_s) || o->hold_s > 3600.0) {
                fprintf(stderr, "sc-viewer: --hold %s: expected seconds\n", optarg);
                return 2;
            }
            break;
        case OPT_PNG_EVERY:
        case OPT_GIF_EVERY:
            if (parse_u64(optarg, &u) || u == 0u || u > 1000000u) {
                fprintf(stderr, "sc-viewer: %s %s: expected a count >= 1\n",
                        c == OPT_PNG_EVERY ? "--png-every" : "--gif-every", optarg);
                return 2;
            }
            if (c == OPT_PNG_EVERY) {
                o->png_every = (uint32_t)u;
            } else {
                o->gif_every = (uint32_t)u;
            }
            break;
        case OPT_GIF:
            o->gif_path = optarg;
            break;
        case OPT_SHOT:
            o->screenshot = optarg;
            break;
        case OPT_SIZE: {
            unsigned w = 0, h = 0;
            char extra;
            if (sscanf(optarg, "%ux%u%c", &w, &h, &extra) != 2 || w < 64u || h < 64u || w > 4096u ||
                h > 4096u) {
                fprintf(stderr, "sc-viewer: --size %s: expected WxH, 64..4096\n", optarg);
                return 2;
            }
            o->width = w;
            o->height = h;
            break;
        }
        case 'q':
            o->quiet = 1;
            break;
        case 'h':
            usage(stdout);
            return 0;
        case 'V':
            printf("sc-viewer %s (display link version %u)\n", VW_VERSION, SC_DLINK_VERSION);
            return 0;
        default:
            usage(stderr);
            return 2;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "sc-viewer: unexpected argument %s\n", argv[optind]);
        return 2;
    }
    return -1;
}

int main(int argc, char **argv)
{
    vw_opts o;
    const int parsed = parse_opts(argc, argv, &o);
    if (parsed >= 0) {
        return parsed;
    }
    if (o.png_dir) {
        struct stat sb;
        if (stat(o.png_dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
            fprintf(stderr, "sc-viewer: --record-png %s: not a directory\n", o.png_dir);
            return 2;
        }
    }

    const int src = resolve_sender(&o);
    if (src != 0) {
        return src;
    }

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    vw_shared *sh = &g_sh;
    pthread_mutex_init(&sh->lock, NULL);
    pthread_cond_init(&sh->cond, NULL);
    sc_dlink_asm_init(&sh->rx);
    sh->frames_target = o.frames;
    sh->sender_any = o.sender_any;
    sh->sender_ip = o.sender_ip;
    atomic_init(&sh->stop_rx, 0);
    sh->fd = open_socket(&o);
    if (sh->fd < 0) {
        return 1;
    }

    vw_render r;
    if (render_init(&r, o.width, o.height) != 0) {
        fprintf(stderr, "sc-viewer: out of memory\n");
        return 1;
    }
    static vw_freeze fz; /* window: space freezes, left/right step the cine, clicks: calipers */
    const int cine_ok = o.headless ? 0 : vw_cine_init(&fz.cine, VW_CINE_FRAMES) == 0;
    vw_gif gif;
    int gif_open = 0;
    if (o.gif_path) {
        if (vw_gif_open(&gif, o.gif_path, (uint16_t)o.width, (uint16_t)o.height, r.palette) != 0) {
            fprintf(stderr, "sc-viewer: --gif %s: %s\n", o.gif_path, strerror(errno));
            return 1;
        }
        gif_open = 1;
    }

#ifdef SC_VIEWER_SDL
    SDL_Window *win = NULL;
    SDL_Renderer *ren = NULL;
    SDL_Texture *tex = NULL;
    if (!o.headless) {
        if (SDL_Init(SDL_INIT_VIDEO) != 0) {
            fprintf(stderr, "sc-viewer: no display (%s): running headless\n", SDL_GetError());
            o.headless = 1;
        } else {
            win = SDL_CreateWindow("sonocomp viewer", SDL_WINDOWPOS_CENTERED,
                                   SDL_WINDOWPOS_CENTERED, (int)o.width, (int)o.height, 0);
            ren = win ? SDL_CreateRenderer(win, -1, SDL_RENDERER_SOFTWARE) : NULL;
            tex = ren ? SDL_CreateTexture(ren, SDL_PIXELFORMAT_RGB24, SDL_TEXTUREACCESS_STREAMING,
                                          (int)o.width, (int)o.height)
                      : NULL;
            if (!tex) {
                fprintf(stderr, "sc-viewer: SDL window: %s: running headless\n", SDL_GetError());
                o.headless = 1;
            }
        }
    }
#else
    if (!o.headless) {
        fprintf(stderr, "sc-viewer: built without SDL2: running headless\n");
        o.headless = 1;
    }
#endif

    pthread_t rx_thread;
    if (pthread_create(&rx_thread, NULL, rx_main, sh) != 0) {
        fprintf(stderr, "sc-viewer: cannot start the receiver\n");
        return 1;
    }
    if (!o.quiet) {
        fprintf(stderr, "sc-viewer: listening on %s:%u for %s%s\n", o.bind_addr,
                (unsigned)o.port, o.sender_any ? "any sender" : o.sender,
                o.headless ? " (headless)" : "");
    }

    const double t0 = now_s();
    double last_status = t0;
    uint64_t refused_reported = 0;
    double last_refused_report = 0.0;
    double fps = 0.0;
    double fps_t = t0;
    uint64_t fps_n = 0;
    uint64_t shown = 0, png_written = 0, png_errors = 0;
    int have_frame = 0;
    int rc = 0;
    const int need_render = !o.headless || o.png_dir || o.gif_path || o.screenshot;
    for (;;) {
        vw_slot local;
        int got = 0;
        uint64_t lost_total = 0;
        pthread_mutex_lock(&sh->lock);
        if (sh->q_head == sh->q_tail) {
            struct timespec until;
            clock_gettime(CLOCK_REALTIME, &until);
            until.tv_nsec += 20 * 1000 * 1000;
            if (until.tv_nsec >= 1000000000L) {
                until.tv_sec++;
                until.tv_nsec -= 1000000000L;
            }
            pthread_cond_timedwait(&sh->cond, &sh->lock, &until);
        }
        if (sh->q_head != sh->q_tail) {
            local.done = sh->slots[sh->q_tail % VW_QUEUE].done;
            memcpy(local.image, sh->slots[sh->q_tail % VW_QUEUE].image,
                   (size_t)local.done.frame.line_count * SC_MAX_SCAN_SAMPLES);
            local.done.image = local.image;
            sh->q_tail++;
            got = 1;
        }
        lost_total = sh->rx.stats.lines_lost;
        const uint64_t refused = sh->rej_sender;
        const struct in_addr refused_from = sh->last_refused;
        const uint64_t closed = frames_closed(sh);
        const int queue_empty = sh->q_head == sh->q_tail;
        const double first = sh->first_packet_s, last = sh->last_packet_s;
        pthread_mutex_unlock(&sh->lock);

        const double t = now_s();
        if (got) {
            shown++;
            fps_n++;
            if (t - fps_t >= 0.5) {
                fps = (double)fps_n / (t - fps_t);
                fps_n = 0;
                fps_t = t;
            }
            if (cine_ok && !fz.frozen) {
                vw_cine_push(&fz.cine, &local.done);
            }
            if (need_render) {
                render_frame(&r, &local.done, fps, lost_total);
                have_frame = 1;
            }
            if (o.png_dir && (shown - 1u) % o.png_every == 0u) {
                char path[4200];
                snprintf(path, sizeof path, "%s/view_%06u.png", o.png_dir,
                         (unsigned)local.done.frame.frame_no);
                if (sc_png_write(path, r.w, r.h, 3u, r.rgb, (size_t)r.w * 3u) == 0) {
                    png_written++;
                } else {
                    png_errors++;
                }
            }
            if (gif_open && (shown - 1u) % o.gif_every == 0u) {
                double d = fps > 1.0 ? 100.0 * o.gif_every / fps : 100.0 * o.gif_every / 60.0;
                uint16_t delay = (uint16_t)(d < 2.0 ? 2.0 : (d > 100.0 ? 100.0 : d + 0.5));
                if (vw_gif_add(&gif, r.index, delay) != 0) {
                    fprintf(stderr, "sc-viewer: GIF write failed\n");
                    gif_open = 0;
                    vw_gif_close(&gif);
                    rc = 1;
                }
            }
#ifdef SC_VIEWER_SDL
            if (tex && !fz.frozen) {
                SDL_UpdateTexture(tex, NULL, r.rgb, (int)(r.w * 3u));
                SDL_RenderClear(ren);
                SDL_RenderCopy(ren, tex, NULL, NULL);
                SDL_RenderPresent(ren);
            }
#endif
        }
#ifdef SC_VIEWER_SDL
        if (win) {
            SDL_Event ev;
            int redraw = 0;
            while (SDL_PollEvent(&ev)) {
                if (ev.type == SDL_QUIT ||
                    (ev.type == SDL_KEYDOWN &&
                     (ev.key.keysym.sym == SDLK_ESCAPE || ev.key.keysym.sym == SDLK_q))) {
                    g_signal = SIGINT;
                } else if (cine_ok && ev.type == SDL_KEYDOWN && ev.key.keysym.sym == SDLK_SPACE) {
                    fz.frozen = !fz.frozen && fz.cine.count > 0u;
                    fz.back = 0u;
                    fz.cal_n = 0;
                    redraw = fz.frozen;
                } else if (fz.frozen && ev.type == SDL_KEYDOWN &&
                           (ev.key.keysym.sym == SDLK_LEFT || ev.key.keysym.sym == SDLK_RIGHT)) {
                    fz.back =
                        vw_cine_step(&fz.cine, fz.back, ev.key.keysym.sym == SDLK_LEFT ? 1 : -1);
                    redraw = 1;
                } else if (fz.frozen && ev.type == SDL_MOUSEBUTTONDOWN) {
                    if (fz.cal_n == 2) {
                        fz.cal_n = 0;
                    }
                    fz.cal[fz.cal_n][0] = ev.button.x;
                    fz.cal[fz.cal_n][1] = ev.button.y;
                    fz.cal_n++;
                    redraw = 1;
                }
            }
            if (redraw && tex) {
                render_frozen(&r, &fz);
                SDL_UpdateTexture(tex, NULL, r.rgb, (int)(r.w * 3u));
                SDL_RenderClear(ren);
                SDL_RenderCopy(ren, tex, NULL, NULL);
                SDL_RenderPresent(ren);
            }
        }
#endif
        if (!o.quiet && t - last_status >= 1.0) {
            last_status = t;
            fprintf(stderr, "sc-viewer: frames=%llu fps=%.1f lines_lost=%llu\n",
                    (unsigned long long)closed, fps, (unsigned long long)lost_total);
        }
        if (refused != refused_reported && t - last_refused_report >= 1.0) {
            last_refused_report = t;
            /* reported even with --quiet: someone else is sending to the display */
            char ip[INET_ADDRSTRLEN] = "?";
            (void)inet_ntop(AF_INET, &refused_from, ip, sizeof ip);
            fprintf(stderr, "sc-viewer: refused %llu datagrams from senders other than %s "
                            "(last from %s)\n",
                    (unsigned long long)(refused - refused_reported), o.sender, ip);
            refused_reported = refused;
        }
        if (g_signal || (o.frames && closed >= o.frames && queue_empty) ||
            (o.seconds > 0.0 && t - t0 >= o.seconds) ||
            (o.idle_s > 0.0 && first > 0.0 && t - last >= o.idle_s)) {
            break;
        }
    }

    atomic_store(&sh->stop_rx, 1);
    pthread_join(rx_thread, NULL);
    pthread_mutex_lock(&sh->lock);
    /* with --frames N the stream may go on: do not close a frame beyond N half-received */
    if (!o.frames || frames_closed(sh) < o.frames) {
        (void)sc_dlink_asm_flush(&sh->rx);
    }
    const sc_dlink_rx_stats st = sh->rx.stats;
    const uint64_t closed = frames_closed(sh), not_shown = sh->frames_not_shown;
    const uint64_t rej_sender = sh->rej_sender;
    pthread_mutex_unlock(&sh->lock);

    if (o.screenshot && have_frame) {
        int shot_rc = -1;
#ifdef SC_VIEWER_SDL
        if (ren) {
            /* what the window really shows, read back from the renderer */
            uint8_t *buf = malloc((size_t)o.width * o.height * 3u);
            if (buf && SDL_RenderReadPixels(ren, NULL, SDL_PIXELFORMAT_RGB24, buf,
                                            (int)(o.width * 3u)) == 0) {
                shot_rc =
                    sc_png_write(o.screenshot, o.width, o.height, 3u, buf, (size_t)o.width * 3u);
            }
            free(buf);
        } else
#endif
        {
            shot_rc = sc_png_write(o.screenshot, r.w, r.h, 3u, r.rgb, (size_t)r.w * 3u);
        }
        if (shot_rc != 0) {
            fprintf(stderr, "sc-viewer: screenshot %s failed\n", o.screenshot);
            rc = 1;
        }
    }
#ifdef SC_VIEWER_SDL
    if (tex && o.hold_s > 0.0 && !g_signal) {
        const double until = now_s() + o.hold_s;
        while (now_s() < until && !g_signal) {
            SDL_Event ev;
            while (SDL_PollEvent(&ev)) {
                if (ev.type == SDL_QUIT) {
                    g_signal = SIGINT;
                }
            }
            SDL_RenderClear(ren);
            SDL_RenderCopy(ren, tex, NULL, NULL);
            SDL_RenderPresent(ren);
            struct timespec nap = {0, 50 * 1000 * 1000};
            nanosleep(&nap, NULL);
        }
    }
#endif
    uint32_t gif_frames = 0;
    if (gif_open) {
        gif_frames = gif.frames;
        if (vw_gif_close(&gif) != 0) {
            fprintf(stderr, "sc-viewer: GIF write failed\n");
            rc = 1;
        }
    }
#ifdef SC_VIEWER_SDL
    if (tex) {
        SDL_DestroyTexture(tex);
    }
    if (ren) {
        SDL_DestroyRenderer(ren);
    }
    if (win) {
        SDL_DestroyWindow(win);
    }
    SDL_Quit();
#endif
    render_free(&r);
    if (cine_ok) {
        vw_cine_free(&fz.cine);
    }
    close(sh->fd);
    if (png_errors) {
        rc = 1;
    }
    printf("frames=%llu complete=%llu incomplete=%llu lines_received=%llu lines_lost=%llu "
           "lines_late=%llu lines_duplicate=%llu rejected=%llu rej_crc=%llu "
           "sender_dropped=%llu begins_missing=%llu ends_missing=%llu shown=%llu "
           "not_shown=%llu png=%llu gif_frames=%u seconds=%.2f rej_sender=%llu\n",
           (unsigned long long)closed, (unsigned long long)st.frames_complete,
           (unsigned long long)st.frames_incomplete, (unsigned long long)st.lines_received,
           (unsigned long long)st.lines_lost, (unsigned long long)st.lines_late,
           (unsigned long long)st.lines_duplicate, (unsigned long long)st.rejected,
           (unsigned long long)st.rej_crc, (unsigned long long)st.lines_sender_dropped,
           (unsigned long long)st.begins_missing, (unsigned long long)st.ends_missing,
           (unsigned long long)shown, (unsigned long long)not_shown,
           (unsigned long long)png_written, gif_frames, now_s() - t0,
           (unsigned long long)rej_sender);
    return rc;
}
