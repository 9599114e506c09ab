/*
 * bench_dlink.c: `bench-dlink`, the cost of the UDP display link sender per frame.
 *
 * Opens the link (platform/linux/sc_udp_display.c) to a receiver socket on 127.0.0.1 that a
 * second thread drains (so the socket buffer never fills and every packet is delivered), then
 * sends N frames of LINES lines of SAMPLES samples through the hal display ops (frame_begin,
 * line, frame_end) for each batch size of the sweep: batch 1 is the per-packet path (one send()
 * per packet, the sender before sendmmsg batching), larger batches one sendmmsg() per batch.
 *
 * Per frame it measures the sender's time from frame_begin to the return of frame_end, on the
 * calling thread's CPU clock (CLOCK_THREAD_CPUTIME_ID: what the frame loop pays, mostly system
 * time in the socket calls) and on CLOCK_MONOTONIC (wall: includes preemption on a loaded
 * machine). The sample lines are prepared once: only the link's own work (encode with CRC, the
 * copy into the batch, the system calls) is timed. The receiver checks every frame's packets
 * arrive as BEGIN, lines 0..n-1 in order, END (order errors must be 0).
 *
 * Not a test: figures depend on the machine; compare rows of one run.
 */
#include <arpa/inet.h>
#include <errno.h>
#include <getopt.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "sc_dlink.h"
#include "sc_udp_display.h"

#define MAX_FRAMES 100000u

typedef struct rx_state {
    int fd;
    int tick_us; /* 0: sleep in poll() until a packet comes (sc-viewer); > 0: wake on a timer */
    atomic_int stop;
    uint64_t wakes; /* times the receiver found packets after sleeping */
    uint32_t idle_ticks;
    uint64_t packets;
    uint64_t lines;
    uint64_t order_errors; /* a packet not the one expected after the previous one */
} rx_state;

/* Drain the receiver socket until told to stop and nothing more arrives for 50 ms; check the
 * packet order of each frame from the header's type and line index (docs/display-link.md).
 * Like sc-viewer: sleep, then read until the socket is empty. A receiver asleep in poll() is
 * woken by the sender's system call for its packet (on loopback the sender runs the receive
 * path), and that wake-up is much of a packet's cost on a VM; with tick_us the receiver sleeps
 * on a timer instead, which leaves the sender's own cost. */
static void *rx_main(void *arg)
{
    rx_state *rx = arg;
    uint8_t buf[2048];
    int expect_type = SC_DLINK_FRAME_BEGIN;
    uint32_t expect_line = 0;
    struct pollfd p = {rx->fd, POLLIN, 0};
    for (;;) {
        if (rx->tick_us > 0) {
            usleep((useconds_t)rx->tick_us);
        }
        const int r = poll(&p, 1, rx->tick_us > 0 ? 0 : 50);
        if (r <= 0) {
            if (atomic_load(&rx->stop) && (rx->tick_us == 0 || rx->idle_ticks++ > 50)) {
                break;
            }
            continue;
        }
        rx->wakes++;
        rx->idle_ticks = 0;
        for (;;) {
            const ssize_t n = recv(rx->fd, buf, sizeof buf, MSG_DONTWAIT);
            if (n < 0) {
                break;
            }
            if (n < (ssize_t)SC_DLINK_HEADER_SIZE) {
                continue;
            }
            rx->packets++;
            const int type = buf[5];
            const uint32_t line = (uint32_t)buf[12] | (uint32_t)buf[13] << 8;
            const uint32_t count = (uint32_t)buf[14] | (uint32_t)buf[15] << 8;
            if (type == SC_DLINK_LINE) {
                rx->lines++;
            }
            if (type != expect_type || (type == SC_DLINK_LINE && line != expect_line)) {
                rx->order_errors++;
            }
            if (type == SC_DLINK_FRAME_BEGIN) {
                expect_type = SC_DLINK_LINE;
                expect_line = 0;
            } else if (type == SC_DLINK_LINE) {
                expect_line = line + 1u;
                expect_type = expect_line >= count ? SC_DLINK_FRAME_END : SC_DLINK_LINE;
            } else {
                expect_type = SC_DLINK_FRAME_BEGIN;
            }
        }
    }
    return NULL;
}

static uint64_t now_ns(clockid_t c)
{
    struct timespec ts;
    clock_gettime(c, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

typedef struct summary {
    double mean_us, p50_us, p99_us;
} summary;

static summary summarize(uint64_t *v, uint32_t n)
{
    summary s = {0.0, 0.0, 0.0};
    if (n == 0u) {
        return s;
    }
    double sum = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        sum += (double)v[i];
    }
    qsort(v, n, sizeof v[0], cmp_u64);
    s.mean_us = sum / n / 1e3;
    s.p50_us = (double)v[(n - 1u) / 2u] / 1e3;
    s.p99_us = (double)v[(uint32_t)((uint64_t)(n - 1u) * 99u / 100u)] / 1e3;
    return s;
}

static void usage(FILE *f)
{
    fprintf(f, "usage: bench-dlink [--frames N] [--rate HZ] [--lines N] [--samples N]\n"
               "                   [--batches LIST] [--drop-permille P] [--rx-tick-us US]\n"
               "Defaults: 1000 frames, 120 Hz (0..1000; 0: back to back), 256 lines, 512 samples,\n"
               "batches 1,8,32,64 (1: one send() per packet, the per-line path), receiver\n"
               "asleep in poll() (0; US > 0: it wakes every US microseconds instead).\n");
}

static uint64_t g_cpu[MAX_FRAMES], g_wall[MAX_FRAMES];

int main(int argc, char **argv)
{
    unsigned frames = 1000u, rate = 120u, lines = 256u, samples = 512u, drop = 0u, tick_us = 0u;
    char batches[128] = "1,8,32,64";
    static const struct option opts[] = {{"frames", required_argument, 0, 'n'},
                                         {"rate", required_argument, 0, 'r'},
                                         {"lines", required_argument, 0, 'l'},
                                         {"samples", required_argument, 0, 's'},
                                         {"batches", required_argument, 0, 'b'},
                                         {"drop-permille", required_argument, 0, 'd'},
                                         {"rx-tick-us", required_argument, 0, 't'},
                                         {"help", no_argument, 0, 'h'},
                                         {0, 0, 0, 0}};
    int c;
    while ((c = getopt_long(argc, argv, "n:r:l:s:b:d:t:h", opts, NULL)) != -1) {
        int ok = 1;
        char extra;
        switch (c) {
        case 'n':
            ok =
                sscanf(optarg, "%u%c", &frames, &extra) == 1 && frames > 0u && frames <= MAX_FRAMES;
            break;
        case 'r':
            ok = sscanf(optarg, "%u%c", &rate, &extra) == 1 && rate <= 1000u; /* 0: back to back */
            break;
        case 'l':
            ok = sscanf(optarg, "%u%c", &lines, &extra) == 1 && lines >= 1u &&
                 lines <= SC_MAX_SCAN_LINES;
            break;
        case 's':
            ok = sscanf(optarg, "%u%c", &samples, &extra) == 1 && samples >= 1u &&
                 samples <= SC_MAX_SCAN_SAMPLES;
            break;
        case 'b':
            ok = strlen(optarg) < sizeof batches;
            if (ok) {
                snprintf(batches, sizeof batches, "%s", optarg);
            }
            break;
        case 'd':
            ok = sscanf(optarg, "%u%c", &drop, &extra) == 1 && drop <= 1000u;
            break;
        case 't':
            ok = sscanf(optarg, "%u%c", &tick_us, &extra) == 1 && tick_us <= 100000u;
            break;
        case 'h':
            usage(stdout);
            return 0;
        default:
            ok = 0;
        }
        if (!ok) {
            fprintf(stderr, "bench-dlink: bad value for option -%c: %s\n", c, optarg ? optarg : "");
            usage(stderr);
            return 2;
        }
    }

    static uint8_t line_buf[SC_MAX_SCAN_LINES][SC_MAX_SCAN_SAMPLES];
    for (unsigned l = 0; l < lines; l++) {
        for (unsigned k = 0; k < samples; k++) {
            line_buf[l][k] = (uint8_t)((l * 31u + k * 7u) ^ (k >> 3));
        }
    }

    printf("bench-dlink: %u frames of %u lines x %u samples (%u-byte line datagrams), %s%u Hz, "
           "drop injection %u permille, receiver thread on 127.0.0.1 %s",
           frames, lines, samples, (unsigned)SC_DLINK_HEADER_SIZE + samples,
           rate ? "paced at " : "back to back, ", rate, drop,
           tick_us ? "waking every " : "asleep in poll()\n");
    if (tick_us) {
        printf("%u us\n", tick_us);
    }
    printf("per frame, frame_begin .. frame_end return, in us:\n");
    printf("%-6s %9s %9s %9s  %9s %9s %9s  %8s %10s %8s %10s %6s %8s\n", "batch", "cpu_mean",
           "cpu_p50", "cpu_p99", "wall_mean", "wall_p50", "wall_p99", "sys/frm", "lines_sent",
           "dropped", "rx_lines", "order", "rxwk/frm");

    char *save = NULL;
    for (char *tok = strtok_r(batches, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        const unsigned batch = (unsigned)strtoul(tok, NULL, 10);
        rx_state rx;
        memset(&rx, 0, sizeof rx);
        rx.fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
        rx.tick_us = (int)tick_us;
        int rcvbuf = 4 * 1024 * 1024;
        (void)setsockopt(rx.fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
        struct sockaddr_in a;
        memset(&a, 0, sizeof a);
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        socklen_t alen = sizeof a;
        if (rx.fd < 0 || bind(rx.fd, (struct sockaddr *)&a, sizeof a) != 0 ||
            getsockname(rx.fd, (struct sockaddr *)&a, &alen) != 0) {
            fprintf(stderr, "bench-dlink: receiver socket: %s\n", strerror(errno));
            return 1;
        }
        pthread_t th;
        if (pthread_create(&th, NULL, rx_main, &rx) != 0) {
            fprintf(stderr, "bench-dlink: cannot start the receiver thread\n");
            return 1;
        }

        static sc_udp_display u;
        sc_udp_display_def def = sc_udp_display_default_def();
        def.port = ntohs(a.sin_port);
        def.inject_drop_permille = drop;
        def.batch_packets = batch;
        const int rc = sc_udp_display_open(&u, &def);
        if (rc != 0) {
            fprintf(stderr, "bench-dlink: batch %u: open: %s\n", batch, sc_err_str(rc));
            return 1;
        }
        sc_display_dev dev = sc_udp_display_dev(&u);
        const uint64_t period_ns = rate ? 1000000000u / rate : 0u;
        uint64_t release = now_ns(CLOCK_MONOTONIC);
        uint64_t calls0 = 0;
        const unsigned warmup = 20u;
        for (unsigned f = 0; f < warmup + frames; f++) {
            if (f == warmup) {
                calls0 = u.send_calls;
            }
            if (period_ns) {
                release += period_ns;
                const struct timespec ts = {(time_t)(release / 1000000000u),
                                            (long)(release % 1000000000u)};
                while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
                }
            }
            const sc_display_frame_info info = {.frame_no = f,
                                                .lines = (uint16_t)lines,
                                                .samples = (uint16_t)samples,
                                                .geometry_id = 0u,
                                                .flags = 1u,
                                                .depth_mm = 40.0f,
                                                .width_mm = 38.0f,
                                                .radius_mm = 0.0f};
            const uint64_t c0 = now_ns(CLOCK_THREAD_CPUTIME_ID), w0 = now_ns(CLOCK_MONOTONIC);
            (void)sc_display_frame_begin(&dev, &info);
            for (unsigned l = 0; l < lines; l++) {
                (void)sc_display_line(&dev, f, (uint16_t)l, line_buf[l], (uint16_t)samples);
            }
            (void)sc_display_frame_end(&dev, SC_DISPLAY_END_PLAIN(f));
            const uint64_t w1 = now_ns(CLOCK_MONOTONIC), c1 = now_ns(CLOCK_THREAD_CPUTIME_ID);
            if (f >= warmup) {
                g_cpu[f - warmup] = c1 - c0;
                g_wall[f - warmup] = w1 - w0;
            }
        }
        const uint64_t calls = u.send_calls - calls0;
        atomic_store(&rx.stop, 1);
        pthread_join(th, NULL);
        const summary sc = summarize(g_cpu, frames), sw = summarize(g_wall, frames);
        printf("%-6u %9.1f %9.1f %9.1f  %9.1f %9.1f %9.1f  %8.2f %10llu %8llu %10llu %6llu "
               "%8.1f\n",
               batch, sc.mean_us, sc.p50_us, sc.p99_us, sw.mean_us, sw.p50_us, sw.p99_us,
               (double)calls / frames, (unsigned long long)u.lines_sent,
               (unsigned long long)u.lines_dropped, (unsigned long long)rx.lines,
               (unsigned long long)rx.order_errors, (double)rx.wakes / (warmup + frames));
        sc_udp_display_close(&u);
        close(rx.fd);
    }
    printf("sys/frm: send system calls per frame; lines_sent, dropped: the sender's counts over\n"
           "warm-up and measured frames; rx_lines: lines the receiver got (lines_sent minus\n"
           "injected drops when the loopback path lost nothing); order: packets out of order;\n"
           "rxwk/frm: receiver wake-ups per frame (each found one or more packets).\n");
    return 0;
}
