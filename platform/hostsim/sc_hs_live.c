/* sc_hs_live.c: the host simulator's live mode, see sc_hs_live.h. */
#include "sc_hs_live.h"

#include <errno.h>
#include <inttypes.h>
#include <signal.h>
#include <string.h>
#include <time.h>

#include "sc_err.h"
#include "sc_state.h"

static volatile sig_atomic_t g_stop;

static void on_signal(int sig)
{
    (void)sig;
    g_stop = 1;
}

int sc_hs_live_stop(void)
{
    return g_stop != 0;
}

static double wall_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* the display tee: the rig's recorder (hashes, PNGs) and the UDP display link */
static int tee_begin(void *ctx, const sc_display_frame_info *info)
{
    sc_hs_live *l = ctx;
    if (l->have_dlink) {
        sc_display_dev d = sc_udp_display_dev(&l->dlink);
        (void)sc_display_frame_begin(&d, info);
    }
    return sc_display_frame_begin(&l->recorder, info);
}

static int tee_line(void *ctx, uint32_t fno, uint16_t li, const uint8_t *s, uint16_t n)
{
    sc_hs_live *l = ctx;
    if (l->have_dlink) {
        sc_display_dev d = sc_udp_display_dev(&l->dlink);
        (void)sc_display_line(&d, fno, li, s, n);
    }
    return sc_display_line(&l->recorder, fno, li, s, n);
}

static int tee_end(void *ctx, const sc_display_end_info *end)
{
    sc_hs_live *l = ctx;
    if (l->have_dlink) {
        sc_display_dev d = sc_udp_display_dev(&l->dlink);
        (void)sc_display_frame_end(&d, end);
    }
    return sc_display_frame_end(&l->recorder, end);
}

/* colour Doppler (display link version 3): to the display link and the recorder alike */
static int tee_colour(void *ctx, uint32_t fno, uint16_t li, uint16_t first, const int8_t *v,
                      uint16_t count)
{
    sc_hs_live *l = ctx;
    if (l->have_dlink) {
        sc_display_dev d = sc_udp_display_dev(&l->dlink);
        (void)sc_display_colour_line(&d, fno, li, first, v, count);
    }
    return sc_display_colour_line(&l->recorder, fno, li, first, v, count);
}

static int tee_doppler(void *ctx, const sc_display_doppler_info *info)
{
    sc_hs_live *l = ctx;
    if (l->have_dlink) {
        sc_display_dev d = sc_udp_display_dev(&l->dlink);
        (void)sc_display_doppler(&d, info);
    }
    return sc_display_doppler(&l->recorder, info);
}

static int tee_state(void *ctx, sc_display_link_state *st)
{
    sc_hs_live *l = ctx;
    return sc_display_get_link_state(&l->recorder, st);
}

/* the state device: UDP and/or a file */
static int live_state_send(void *ctx, const uint8_t *rec, uint16_t len)
{
    sc_hs_live *l = ctx;
    int rc = SC_OK;
    if (l->def.state_target) {
        sc_state_dev d = sc_udp_state_dev(&l->state);
        rc = sc_state_send(&d, rec, len);
    }
    if (l->state_fp) {
        const uint8_t h[2] = {(uint8_t)len, (uint8_t)(len >> 8)};
        if (fwrite(h, 1, 2, l->state_fp) != 2u || fwrite(rec, 1, len, l->state_fp) != len) {
            return SC_ERR_IO;
        }
        l->state_file_records++;
    }
    return rc;
}

int sc_hs_live_open(sc_hs_live *l, const sc_hs_live_def *def, sc_hs_rig *rig, char *err,
                    size_t cap)
{
    memset(l, 0, sizeof *l);
    l->def = *def;
    l->can.fd = -1;
    l->state.fd = -1;
    char host[256];
    uint16_t port;
    if (def->can_port) {
        const sc_can_rxmb_def mbd = sc_can_rxmb_default_def();
        if (sc_can_rxmb_init(&l->rxmb, &mbd) != SC_OK) {
            snprintf(err, cap, "receive mailboxes: bad definition");
            return SC_ERR_RANGE;
        }
        if (sc_udpcan_open_rx(&l->can, def->can_port) != SC_OK) {
            snprintf(err, cap, "cannot bind UDP CAN port %u: %s", (unsigned)def->can_port,
                     strerror(l->can.last_errno));
            return SC_ERR_IO;
        }
    }
    if (def->state_target) {
        if (sc_udp_parse_target(def->state_target, host, sizeof host, &port) != 0 ||
            sc_udp_state_open(&l->state, host, port) != SC_OK) {
            snprintf(err, cap, "cannot open the state stream to %s", def->state_target);
            return SC_ERR_IO;
        }
    }
    if (def->state_file) {
        l->state_fp = fopen(def->state_file, "wb");
        if (l->state_fp == NULL) {
            snprintf(err, cap, "cannot write %s: %s", def->state_file, strerror(errno));
            return SC_ERR_IO;
        }
    }
    if (def->dlink_target) {
        sc_udp_display_def ud = sc_udp_display_default_def();
        if (sc_udp_parse_target(def->dlink_target, host, sizeof host, &port) != 0) {
            snprintf(err, cap, "display link target '%s' is not HOST:PORT", def->dlink_target);
            return SC_ERR_INVALID_ARG;
        }
        ud.host = host;
        ud.port = port;
        if (sc_udp_display_open(&l->dlink, &ud) != SC_OK) {
            snprintf(err, cap, "cannot open the display link to %s", def->dlink_target);
            return SC_ERR_IO;
        }
        l->have_dlink = 1;
    }
    static const sc_display_ops tee = {
        .frame_begin = tee_begin, .line = tee_line, .frame_end = tee_end, .link_state = tee_state,
        .colour_line = tee_colour, .doppler = tee_doppler};
    l->recorder = rig->hal.display;
    rig->hal.display = (sc_display_dev){.ops = &tee, .ctx = l};
    if (def->state_target || def->state_file) {
        static const sc_state_ops sops = {.send = live_state_send};
        rig->hal.state = (sc_state_dev){.ops = &sops, .ctx = l};
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    l->wall0_s = wall_s();
    l->t0_ns = rig->clock.now_ns;
    return SC_OK;
}

void sc_hs_live_before_frame(sc_hs_live *l, sc_hs_rig *rig, uint64_t release_ns)
{
    if (l->def.pace) {
        const double due = l->wall0_s + (double)(release_ns - l->t0_ns) * 1e-9;
        const double now = wall_s();
        if (due > now) {
            const double d = due - now;
            struct timespec ts = {(time_t)d, (long)((d - (double)(time_t)d) * 1e9)};
            while (nanosleep(&ts, &ts) != 0 && errno == EINTR && !g_stop) {
            }
        }
    }
    if (l->def.can_port) {
        const sc_can_dev dev = sc_udpcan_dev(&l->can);
        const uint32_t n = sc_can_rxmb_drain(&l->rxmb, &dev, SC_HS_LIVE_DRAIN_MAX, release_ns);
        l->drained_max = n > l->drained_max ? n : l->drained_max;
        l->drain_limited += n == SC_HS_LIVE_DRAIN_MAX;
        const sc_hs_can_node *node = &rig->bus.nodes[rig->engine_node];
        uint32_t budget =
            node->count < SC_CAN_RX_BURST_MAX ? SC_CAN_RX_BURST_MAX - node->count : 0u;
        sc_can_frame f;
        for (; budget > 0u && sc_can_rxmb_take(&l->rxmb, &f) == SC_OK; budget--) {
            if (sc_hs_can_inject(&rig->bus, rig->engine_node, &f) == SC_OK) {
                l->can_injected++;
            } else {
                l->can_overruns++;
            }
        }
    }
}

void sc_hs_live_summary(const sc_hs_live *l, const sc_hs_rig *rig, FILE *f)
{
    const sc_state_tx *t = sc_engine_get_state_tx(&rig->engine);
    fprintf(f, "live            %" PRIu64 " CAN frames in over UDP (%" PRIu64 " malformed, %" PRIu64
               " overruns); state stream %" PRIu64 " records sent, %" PRIu64 " dropped%s\n",
            l->can_injected, l->can.rejected, l->can_overruns, t->records_sent,
            t->records_dropped, l->state_fp ? " (also written to the state file)" : "");
    if (l->def.can_port) {
        const sc_can_rxmb_counters *c = &l->rxmb.c;
        fprintf(f,
                "can rx          mailboxes: %" PRIu64 " commands, %" PRIu64
                " stream frames taken; %" PRIu64
                " stream frames overwritten by newer ones, %" PRIu64
                " commands refused (mailbox full); deepest %u commands, %u stream frames; "
                "up to %u datagrams drained before a frame (%" PRIu64 " drains at the bound)\n",
                c->prio_taken, c->stream_taken, c->stream_overwritten, c->prio_dropped,
                c->prio_depth_max, c->stream_depth_max, l->drained_max, l->drain_limited);
    }
}

void sc_hs_live_close(sc_hs_live *l)
{
    sc_udpcan_close(&l->can);
    sc_udp_state_close(&l->state);
    if (l->have_dlink) {
        sc_udp_display_close(&l->dlink);
    }
    if (l->state_fp) {
        fclose(l->state_fp);
    }
}
