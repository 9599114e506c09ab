/* bench-can: cost of the CAN receive path, the work the engine's rx stage does per frame.
 * Prints a table: ns per call (median of 7 runs) of CRC-8, E2E check, pose encode, pose part
 * decode, tracker on_frame (classic part, FD pose, rejected CRC) and poll, and the worst case of
 * one engine frame's rx stage (SC_CAN_RX_BURST_MAX frames + poll).
 *   bench-can [iterations (default 200000)] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sc_config.h"
#include "sc_e2e.h"
#include "sc_tracker.h"

static uint64_t now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static volatile uint32_t sink;
static sc_tracker trk;
static sc_can_frame classic[3 * 16], fd[16], bad;

typedef void (*bench_fn)(uint32_t n);

static void b_crc8(uint32_t n)
{
    uint8_t d[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    for (uint32_t i = 0; i < n; i++) {
        d[1] = (uint8_t)i;
        sink += sc_crc8_j1850(d, 8, 0);
    }
}

static void b_e2e_check(uint32_t n)
{
    sc_e2e_rx rx;
    sc_e2e_rx_def def = sc_e2e_rx_default_def(SC_CANID_POSE_POS);
    sc_e2e_rx_init(&rx, &def);
    for (uint32_t i = 0; i < n; i++) {
        const sc_can_frame *f = &classic[(i % 16u) * 3u];
        sink += (uint32_t)sc_e2e_check(&rx, f->data, f->len, i);
    }
}

static void b_encode(uint32_t n)
{
    sc_pose_msg p = {.pos_mm = {1.0f, 2.0f, 3.0f}, .q = {1.0f, 0.0f, 0.0f, 0.0f}};
    sc_can_frame f[3];
    size_t k;
    for (uint32_t i = 0; i < n; i++) {
        p.pos_mm[0] = (float)(i & 1023u) * 0.1f;
        sink += (uint32_t)sc_canproto_encode_pose(&p, (uint8_t)(i & 15u), 0, f, 3, &k);
    }
}

static void b_decode(uint32_t n)
{
    sc_pose_msg p;
    for (uint32_t i = 0; i < n; i++) {
        sink += (uint32_t)sc_canproto_decode_pose_part(&classic[i % 48u], &p);
    }
}

static void b_on_frame_classic(uint32_t n)
{
    sc_tracker_def d = sc_tracker_default_def();
    sc_tracker_init(&trk, &d);
    for (uint32_t i = 0; i < n; i++) {
        /* a new sample every 3 frames, 10 ms apart */
        sink += (uint32_t)sc_tracker_on_frame(&trk, &classic[i % 48u],
                                              (uint64_t)(i / 3u) * 10000000u + 1u);
    }
}

static void b_on_frame_fd(uint32_t n)
{
    sc_tracker_def d = sc_tracker_default_def();
    sc_tracker_init(&trk, &d);
    for (uint32_t i = 0; i < n; i++) {
        sink += (uint32_t)sc_tracker_on_frame(&trk, &fd[i % 16u], (uint64_t)i * 10000000u + 1u);
    }
}

static void b_on_frame_bad(uint32_t n)
{
    sc_tracker_def d = sc_tracker_default_def();
    sc_tracker_init(&trk, &d);
    for (uint32_t i = 0; i < n; i++) {
        sink += (uint32_t)sc_tracker_on_frame(&trk, &bad, i);
    }
}

static void b_poll(uint32_t n)
{
    sc_pose p;
    int c;
    for (uint32_t i = 0; i < n; i++) {
        sink += (uint32_t)sc_tracker_poll(&trk, (uint64_t)i, &p, &c);
    }
}

static double run(bench_fn fn, uint32_t n)
{
    uint64_t t[7];
    for (int r = 0; r < 7; r++) {
        const uint64_t a = now_ns();
        fn(n);
        t[r] = now_ns() - a;
    }
    qsort(t, 7, sizeof t[0], cmp_u64);
    return (double)t[3] / (double)n;
}

int main(int argc, char **argv)
{
    const uint32_t n = argc > 1 ? (uint32_t)strtoul(argv[1], NULL, 10) : 200000u;
    for (uint32_t s = 0; s < 16u; s++) {
        sc_pose_msg p = {.pos_mm = {(float)s * 0.2f, 0.0f, 5.0f},
                         .q = {1.0f, 0.0f, 0.0f, 0.0f},
                         .force_n = 1.0f,
                         .force_valid = 1};
        size_t k;
        sc_canproto_encode_pose(&p, (uint8_t)s, 0, &classic[s * 3u], 3, &k);
        sc_canproto_encode_pose(&p, (uint8_t)s, 1, &fd[s], 1, &k);
    }
    bad = classic[0];
    bad.data[0] ^= 0xFFu;
    const struct {
        const char *name;
        bench_fn fn;
    } rows[] = {
        {"crc8 (8 bytes)", b_crc8},
        {"e2e check (8 bytes)", b_e2e_check},
        {"encode pose (3 classic frames)", b_encode},
        {"decode pose part", b_decode},
        {"tracker on_frame, classic part", b_on_frame_classic},
        {"tracker on_frame, FD pose", b_on_frame_fd},
        {"tracker on_frame, wrong CRC", b_on_frame_bad},
        {"tracker poll", b_poll},
    };
    double per[8];
    printf("%-34s %12s\n", "operation", "ns/call");
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        per[i] = run(rows[i].fn, n);
        printf("%-34s %12.1f\n", rows[i].name, per[i]);
    }
    const double worst = (double)SC_CAN_RX_BURST_MAX * (per[4] > per[5] ? per[4] : per[5]) + per[7];
    printf("%-34s %12.1f   (%u frames + poll)\n", "rx stage bound per engine frame", worst,
           (unsigned)SC_CAN_RX_BURST_MAX);
    printf("(sizeof(sc_tracker) = %zu bytes)\n", sizeof(sc_tracker));
    return 0;
}
