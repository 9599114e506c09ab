/*
 * sc-cmd-latency: how long the page's commands take to reach a live engine while a tracker
 * streams poses, measured from outside as the console sees it (tools/cmd-latency.sh runs it
 * against sc-hostsim --live). Over CAN over UDP (sc_udpcan.h) it sends the tracker emulator's
 * poses at --rate-hz (the press script: from 2 mm above the default point to 1 mm into the
 * skin, held), first a CmdDoppler with colour on (the engine images and colours every frame,
 * as in the console's Doppler test; not measured) and then, every --every-ms, one signed
 * command (CmdAssessment reset: cheap to apply, each one counted by the engine), each
 * preceded by a freshness sync, as the gateway sends them. Nothing is sent before the
 * engine's first FRAME record arrives (it is up). It listens to the engine's
 * state stream (--state-port) and takes a command as acknowledged when a FRAME record's
 * "commands applied + refused" counter reaches it. Per command: latency in wall-clock ms from
 * the send to the first FRAME record showing it, and in engine frames (record's frame number
 * minus the last frame number seen at the send). Queue depth: the engine's UDP socket's
 * receive queue (bytes, from /proc/net/udp, sampled at each command) and the datagrams it
 * holds at the observed bytes per datagram. Prints a table: p50, p99, worst, commands lost.
 * A benchmark, not a test: the figures depend on the host's load.
 */
#include <arpa/inet.h>
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "sc_canproto.h"
#include "sc_cmdsign.h"
#include "sc_err.h"
#include "sc_secoc.h"
#include "sc_state.h"
#include "sc_trkemu.h"
#include "sc_udp_state.h"
#include "sc_udpcan.h"

#define MAX_CMDS 4096u

typedef struct lat_cli {
    const char *can_udp; /* HOST:PORT of the engine's CAN over UDP */
    unsigned state_port; /* where the engine sends its state stream */
    double rate_hz, seconds, every_ms;
} lat_cli;

static void usage(FILE *f)
{
    fprintf(f, "usage: sc-cmd-latency --can-udp HOST:PORT --state-port PORT [--rate-hz 100]\n"
               "                      [--seconds 20] [--every-ms 500]\n"
               "  tracker poses at --rate-hz and one signed command every --every-ms to the\n"
               "  engine's CAN over UDP; latency to the engine's FRAME record that counts it\n");
}

static int parse_double(const char *s, double lo, double hi, double *out)
{
    char *end = NULL;
    errno = 0;
    const double v = strtod(s, &end);
    if (errno != 0 || end == s || *end != '\0' || !isfinite(v) || v < lo || v > hi) {
        return -1;
    }
    *out = v;
    return 0;
}

/* The command line into *a. -1 to go on, 0 after --help, 2 for a usage error (a message said
 * why). tests/fuzz/fuzz_cli_cmd_latency.c calls it. */
static int parse_cli(int argc, char **argv, lat_cli *a)
{
    *a = (lat_cli){.rate_hz = 100.0, .seconds = 20.0, .every_ms = 500.0};
    optind = 0;
    static const struct option opts[] = {{"can-udp", required_argument, 0, 'u'},
                                         {"state-port", required_argument, 0, 'p'},
                                         {"rate-hz", required_argument, 0, 'r'},
                                         {"seconds", required_argument, 0, 's'},
                                         {"every-ms", required_argument, 0, 'e'},
                                         {"help", no_argument, 0, 'h'},
                                         {0, 0, 0, 0}};
    int c;
    double v;
    while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        switch (c) {
        case 'u':
            a->can_udp = optarg;
            break;
        case 'p':
            if (parse_double(optarg, 1.0, 65535.0, &v) != 0 || v > floor(v)) {
                fprintf(stderr, "sc-cmd-latency: --state-port: 1..65535\n");
                return 2;
            }
            a->state_port = (unsigned)v;
            break;
        case 'r':
            if (parse_double(optarg, 1.0, 1000.0, &a->rate_hz) != 0) {
                fprintf(stderr, "sc-cmd-latency: --rate-hz: 1..1000\n");
                return 2;
            }
            break;
        case 's':
            if (parse_double(optarg, 1.0, 3600.0, &a->seconds) != 0) {
                fprintf(stderr, "sc-cmd-latency: --seconds: 1..3600\n");
                return 2;
            }
            break;
        case 'e':
            if (parse_double(optarg, 20.0, 60000.0, &a->every_ms) != 0) {
                fprintf(stderr, "sc-cmd-latency: --every-ms: 20..60000\n");
                return 2;
            }
            break;
        case 'h':
            usage(stdout);
            return 0;
        default:
            usage(stderr);
            return 2;
        }
    }
    if (optind != argc || a->can_udp == NULL || a->state_port == 0u) {
        usage(stderr);
        return 2;
    }
    char host[256];
    uint16_t port;
    if (sc_udp_parse_target(a->can_udp, host, sizeof host, &port) != 0) {
        fprintf(stderr, "sc-cmd-latency: --can-udp %s is not HOST:PORT\n", a->can_udp);
        return 2;
    }
    if (a->seconds * 1000.0 / a->every_ms > (double)MAX_CMDS) {
        fprintf(stderr, "sc-cmd-latency: at most %u commands (--seconds / --every-ms)\n", MAX_CMDS);
        return 2;
    }
    return -1;
}

static double mono_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* The receive queue (bytes) of the UDP socket bound to 127.0.0.1:port, -1 if not found. */
static long udp_rx_queue(unsigned port)
{
    FILE *f = fopen("/proc/net/udp", "r");
    if (f == NULL) {
        return -1;
    }
    char line[512];
    long q = -1;
    while (fgets(line, sizeof line, f)) {
        unsigned sl, la, lp, ra, rp, st;
        unsigned long tx, rx;
        if (sscanf(line, " %u: %x:%x %x:%x %x %lx:%lx", &sl, &la, &lp, &ra, &rp, &st, &tx, &rx) ==
                8 &&
            lp == port) {
            q = (long)rx;
            break;
        }
    }
    fclose(f);
    return q;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double pct(const double *sorted, size_t n, double p)
{
    if (n == 0u) {
        return NAN;
    }
    size_t i = (size_t)ceil(p * (double)n) - (p > 0.0 ? 1u : 0u);
    return sorted[i < n ? i : n - 1u];
}

typedef struct sent_cmd {
    double t_s;
    uint32_t frame_at_send;
    long rxq_bytes;
    double lat_ms;
    int64_t lat_frames;
} sent_cmd;

static sent_cmd g_cmds[MAX_CMDS];

int main(int argc, char **argv)
{
    lat_cli a;
    const int prc = parse_cli(argc, argv, &a);
    if (prc >= 0) {
        return prc;
    }
    char host[256];
    uint16_t can_port;
    (void)sc_udp_parse_target(a.can_udp, host, sizeof host, &can_port);
    sc_udpcan tx;
    if (sc_udpcan_open_tx(&tx, host, can_port) != SC_OK) {
        fprintf(stderr, "sc-cmd-latency: cannot open CAN over UDP to %s\n", a.can_udp);
        return 1;
    }
    const sc_can_dev dev = sc_udpcan_dev(&tx);
    const int rx = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons((uint16_t)a.state_port)};
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (rx < 0 || bind(rx, (struct sockaddr *)&sa, sizeof sa) != 0) {
        fprintf(stderr, "sc-cmd-latency: cannot bind the state port %u: %s\n", a.state_port,
                strerror(errno));
        return 1;
    }
    /* the probe pressed 1 mm into the skin over the default point and held there (the press
     * script's descent from 2 mm above), so that the engine images and colours every frame */
    sc_emu_def def = sc_emu_default_def();
    def.script = SC_EMU_PRESS;
    def.rate_hz = a.rate_hz;
    def.hover_mm = 2.0f;
    def.depth_mm = 1.0f;
    def.duration_s = a.seconds + 5.0;
    static sc_emu emu;
    if (sc_emu_init(&emu, &def) != SC_OK) {
        fprintf(stderr, "sc-cmd-latency: the tracker emulator refuses rate %.1f Hz\n", a.rate_hz);
        return 2;
    }
    sc_cmdsign signer;
    (void)sc_cmdsign_init(&signer, sc_secoc_bench_key, 2u, sc_cmdsign_fv_now(), 1);
    /* colour Doppler on first (not measured), as the console's Doppler test turns it on */
    const sc_cmd colour = {
        .kind = SC_CMD_DOPPLER,
        .doppler = {.on = 1, .prf_hz = 3000.0f, .steer_deg = 0.0f, .gain_db = 0.0f}};
    int colour_sent = 0;
    const sc_cmd cmd = {.kind = SC_CMD_ASSESS,
                        .assess_action = SC_ASSESS_ACTION_RESET,
                        .assess_call = SC_ASSESS_CALL_NONE};

    const double t0 = mono_s();
    double next_pose = 0.0, next_cmd = 1.0; /* the first command after 1 s of poses */
    uint32_t n_cmds = 0, acked = 0, last_frame = 0;
    int have_base = 0;
    uint64_t base = 0, frames_seen = 0, poses_sent = 0, send_failed = 0;
    long rxq_max = 0;
    double start = 0.0; /* the first FRAME record: the run's seconds count from there */
    for (;;) {
        const double now = mono_s() - t0;
        if (have_base &&
            (now >= start + a.seconds + 5.0 || (now >= start + a.seconds && acked == n_cmds))) {
            break; /* 5 s for the last acknowledgements */
        }
        if (!have_base) {
            /* nothing is sent before the engine's first FRAME record: it is up */
            next_pose = now;
            next_cmd = now + 1.0;
            if (now > 60.0) {
                fprintf(stderr, "sc-cmd-latency: no FRAME record on port %u in 60 s\n",
                        a.state_port);
                return 1;
            }
        } else if (now >= next_pose && now < start + a.seconds) {
            sc_can_frame f[SC_EMU_MAX_FRAMES];
            uint64_t t_ns;
            const int k = sc_emu_next(&emu, f, SC_EMU_MAX_FRAMES, &t_ns);
            for (int j = 0; j < k; j++) {
                send_failed += sc_can_send(&dev, &f[j]) != SC_OK;
            }
            poses_sent++;
            next_pose += 1.0 / a.rate_hz;
        }
        if (have_base && !colour_sent) {
            sc_can_frame f[4];
            if (sc_cmdsign_sync(&signer, &f[0]) == SC_OK &&
                sc_cmdsign_command(&signer, &colour, &f[2]) == SC_OK) {
                for (int j = 0; j < 4; j++) {
                    send_failed += sc_can_send(&dev, &f[j]) != SC_OK;
                }
            }
            colour_sent = 1;
            base++; /* its acknowledgement is not a measured command's */
        }
        if (have_base && now >= next_cmd && now < start + a.seconds && n_cmds < MAX_CMDS) {
            sc_can_frame f[4];
            if (sc_cmdsign_sync(&signer, &f[0]) == SC_OK &&
                sc_cmdsign_command(&signer, &cmd, &f[2]) == SC_OK) {
                const long q = udp_rx_queue(can_port);
                for (int j = 0; j < 4; j++) {
                    send_failed += sc_can_send(&dev, &f[j]) != SC_OK;
                }
                g_cmds[n_cmds] = (sent_cmd){.t_s = mono_s() - t0,
                                            .frame_at_send = last_frame,
                                            .rxq_bytes = q,
                                            .lat_ms = NAN};
                rxq_max = q > rxq_max ? q : rxq_max;
                n_cmds++;
            }
            next_cmd += a.every_ms * 1e-3;
        }
        /* state records until the next pose is due */
        double wait = next_pose - (mono_s() - t0);
        int ms = !have_base ? 100 : wait > 0.0 ? (int)(wait * 1e3) : 0;
        struct pollfd pfd = {.fd = rx, .events = POLLIN};
        if (poll(&pfd, 1, ms) > 0) {
            uint8_t rec[SC_STATE_RECORD_MAX + 1];
            ssize_t n;
            while ((n = recv(rx, rec, sizeof rec, MSG_DONTWAIT)) > 0) {
                uint32_t seq, fno;
                if (sc_state_check(rec, (uint32_t)n, &seq, &fno) != SC_STATE_FRAME ||
                    n < (ssize_t)(SC_STATE_HEADER_SIZE + SC_STATE_FRAME_SIZE)) {
                    continue;
                }
                const uint8_t *p = rec + SC_STATE_HEADER_SIZE + 136;
                uint64_t applied = 0, refused = 0;
                for (int b = 0; b < 8; b++) {
                    applied |= (uint64_t)p[b] << (8 * b);
                    refused |= (uint64_t)p[8 + b] << (8 * b);
                }
                const uint64_t done = applied + refused;
                const double t = mono_s() - t0;
                frames_seen++;
                last_frame = fno;
                if (!have_base) {
                    base = done;
                    have_base = 1;
                    start = t;
                }
                while (acked < n_cmds && done - base > acked) {
                    g_cmds[acked].lat_ms = (t - g_cmds[acked].t_s) * 1e3;
                    g_cmds[acked].lat_frames = (int64_t)fno - (int64_t)g_cmds[acked].frame_at_send;
                    acked++;
                }
            }
        }
    }
    static double lat[MAX_CMDS], fr[MAX_CMDS], q[MAX_CMDS];
    for (uint32_t i = 0; i < acked; i++) {
        lat[i] = g_cmds[i].lat_ms;
        fr[i] = (double)g_cmds[i].lat_frames;
    }
    for (uint32_t i = 0; i < n_cmds; i++) {
        q[i] = (double)g_cmds[i].rxq_bytes;
    }
    qsort(lat, acked, sizeof lat[0], cmp_double);
    qsort(fr, acked, sizeof fr[0], cmp_double);
    qsort(q, n_cmds, sizeof q[0], cmp_double);
    printf("sc-cmd-latency: tracker %.0f Hz (%" PRIu64 " poses, %" PRIu64
           " send failures), one command every %.0f ms, %.0f s; %" PRIu64 " FRAME records\n",
           a.rate_hz, poses_sent, send_failed, a.every_ms, a.seconds, frames_seen);
    printf("| measure | p50 | p99 | worst |\n| --- | ---: | ---: | ---: |\n");
    printf("| command -> FRAME record, ms | %.0f | %.0f | %.0f |\n", pct(lat, acked, 0.5),
           pct(lat, acked, 0.99), acked ? lat[acked - 1u] : NAN);
    printf("| command -> FRAME record, engine frames | %.0f | %.0f | %.0f |\n", pct(fr, acked, 0.5),
           pct(fr, acked, 0.99), acked ? fr[acked - 1u] : NAN);
    printf("| engine's UDP receive queue at a send, bytes (76-byte datagrams, about 1 KB each "
           "in the kernel) | %.0f | %.0f | %ld |\n",
           pct(q, n_cmds, 0.5), pct(q, n_cmds, 0.99), rxq_max);
    printf("commands: %u sent, %u acknowledged, %u not acknowledged\n", n_cmds, acked,
           n_cmds - acked);
    sc_udpcan_close(&tx);
    close(rx);
    return acked == n_cmds && n_cmds > 0u ? 0 : 1;
}
