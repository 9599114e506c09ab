/* sc-tracker-listen: the engine's CAN receive side on its own, for the bench: drains a
 * SocketCAN interface at the engine's frame rate (at most SC_CAN_RX_BURST_MAX frames per
 * frame, kernel filters on the protocol's ids) into the tracker, or replays a candump -l log
 * through it on the log's time stamps; optionally records what it received as a candump -l
 * log; prints the tracker's counters as key=value lines.
 *
 *   sc-tracker-listen (--iface vcan0 [--duration-s 5] [--log FILE] | --replay FILE)
 *                     [--rate-hz 60] [--no-filters]
 * Exit 0; 1 on an I/O error; 2 on a usage error. */
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "sc_candump.h"
#include "sc_config.h"
#include "sc_err.h"
#include "sc_socketcan.h"
#include "sc_tracker.h"

typedef struct stats {
    uint64_t frames, polls, polls_with_pose, ts_missing, ts_backwards, last_ts;
} stats;

static uint64_t mono_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000u + (uint64_t)t.tv_nsec;
}

static void feed(sc_tracker *t, stats *st, const sc_can_frame *f, uint64_t now)
{
    st->frames++;
    if (f->ts_ns == 0u) {
        st->ts_missing++;
    } else if (f->ts_ns < st->last_ts) {
        st->ts_backwards++;
    } else {
        st->last_ts = f->ts_ns;
    }
    (void)sc_tracker_on_frame(t, f, now);
}

static void poll_once(sc_tracker *t, stats *st, uint64_t now)
{
    sc_pose p;
    int contact;
    st->polls++;
    st->polls_with_pose += sc_tracker_poll(t, now, &p, &contact) == 0;
}

static void report(const sc_tracker *t, const stats *st)
{
    const sc_trk_counters *k = sc_tracker_counters(t);
    printf("frames=%llu\n", (unsigned long long)st->frames);
    for (int o = 0; o < (int)SC_TRK_OUTCOME_COUNT; o++) {
        printf("%s=%u\n", sc_trk_outcome_name((sc_trk_outcome)o), k->outcome[o]);
    }
    printf("rejected_e2e=%u\nrejected_implausible=%u\n", sc_tracker_rejected_e2e(t),
           sc_tracker_rejected_implausible(t));
    printf("incomplete=%u\nlift_events=%u\ne2e_lost=%u\n", k->incomplete, k->lift_events,
           k->e2e_lost);
    printf("polls=%llu\npolls_with_pose=%llu\nts_missing=%llu\nts_backwards=%llu\n",
           (unsigned long long)st->polls, (unsigned long long)st->polls_with_pose,
           (unsigned long long)st->ts_missing, (unsigned long long)st->ts_backwards);
}

int main(int argc, char **argv)
{
    const char *iface = NULL, *replay = NULL, *log_path = NULL;
    double duration_s = 5.0, rate_hz = 60.0;
    int filters = 1;
    static const struct option opts[] = {
        {"iface", required_argument, 0, 'i'},
        {"replay", required_argument, 0, 'r'},
        {"log", required_argument, 0, 'l'},
        {"duration-s", required_argument, 0, 'd'},
        {"rate-hz", required_argument, 0, 'R'},
        {"no-filters", no_argument, 0, 'n'},
        {0, 0, 0, 0},
    };
    int c;
    while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        char *end = NULL;
        switch (c) {
        case 'i':
            iface = optarg;
            break;
        case 'r':
            replay = optarg;
            break;
        case 'l':
            log_path = optarg;
            break;
        case 'd':
            duration_s = strtod(optarg, &end);
            break;
        case 'R':
            rate_hz = strtod(optarg, &end);
            break;
        case 'n':
            filters = 0;
            break;
        default:
            return 2;
        }
        if (end && (*end != '\0' || end == optarg)) {
            fprintf(stderr, "sc-tracker-listen: bad number %s\n", optarg);
            return 2;
        }
    }
    if ((iface == NULL) == (replay == NULL) || !(rate_hz >= 1.0 && rate_hz <= 1000.0) ||
        !(duration_s > 0.0)) {
        fprintf(stderr, "usage: sc-tracker-listen (--iface IF [--duration-s S] [--log FILE] | "
                        "--replay FILE) [--rate-hz HZ] [--no-filters]\n");
        return 2;
    }
    static sc_tracker trk;
    sc_tracker_def td = sc_tracker_default_def();
    if (sc_tracker_init(&trk, &td) != 0) {
        return 1;
    }
    stats st;
    memset(&st, 0, sizeof st);
    const uint64_t period_ns = (uint64_t)(1e9 / rate_hz);

    if (replay) {
        FILE *fp = fopen(replay, "r");
        if (fp == NULL) {
            fprintf(stderr, "sc-tracker-listen: %s: %s\n", replay, strerror(errno));
            return 1;
        }
        sc_candump_reader rd;
        sc_candump_reader_init(&rd, fp);
        sc_candump_rec rec;
        int have = sc_candump_reader_next(&rd, &rec) == 0;
        uint64_t now = have ? rec.frame.ts_ns : 0u;
        while (have) {
            unsigned burst = 0;
            while (have && rec.frame.ts_ns <= now && burst < SC_CAN_RX_BURST_MAX) {
                feed(&trk, &st, &rec.frame, now);
                burst++;
                have = sc_candump_reader_next(&rd, &rec) == 0;
            }
            poll_once(&trk, &st, now);
            now += period_ns;
        }
        for (int k = 0; k < 30; k++) { /* half a second of silence after the log */
            poll_once(&trk, &st, now);
            now += period_ns;
        }
        fclose(fp);
        printf("log_records=%u\nlog_rejected=%u\n", rd.records,
               sc_candump_reader_rejected_total(&rd));
        report(&trk, &st);
        return 0;
    }

    static sc_socketcan node;
    int rc = sc_socketcan_open(&node, sc_socketcan_sys_posix(), NULL, iface);
    if (rc != 0) {
        fprintf(stderr, "sc-tracker-listen: cannot open %s: %s (%s)\n", iface, sc_err_str(rc),
                strerror(errno));
        return 1;
    }
    const sc_can_dev dev = sc_socketcan_dev(&node);
    if (filters) {
        const sc_can_filter f[] = {
            /* the engine's filters (core/sc_engine.c): exactly the protocol's receive ids */
            {.id = SC_CANID_CMD_CASE, .mask = 0x7FCu, .flags = 0},
            {.id = SC_CANID_CMD_SYNC, .mask = 0x7FFu, .flags = 0},
            {.id = SC_CANID_AUTH_CASE, .mask = 0x7FCu, .flags = 0},
            {.id = SC_CANID_AUTH_SYNC, .mask = 0x7FFu, .flags = 0},
            {.id = SC_CANID_POSE_POS, .mask = 0x7FEu, .flags = 0},
            {.id = SC_CANID_POSE_AUX, .mask = 0x7FFu, .flags = 0},
            {.id = SC_CANID_POSE_FD, .mask = 0x7FFu, .flags = 0},
        };
        rc = sc_can_set_filters(&dev, f, sizeof f / sizeof f[0]);
        if (rc != 0) {
            fprintf(stderr, "sc-tracker-listen: filters: %s\n", sc_err_str(rc));
            return 1;
        }
    }
    FILE *log = NULL;
    if (log_path && (log = fopen(log_path, "w")) == NULL) {
        fprintf(stderr, "sc-tracker-listen: %s: %s\n", log_path, strerror(errno));
        return 1;
    }
    printf("fd_capable=%d\nuid=%u\n", node.fd_capable, (unsigned)getuid());
    fflush(stdout);
    const uint64_t start = mono_ns();
    const uint64_t end = start + (uint64_t)(duration_s * 1e9);
    uint64_t next = start;
    uint64_t burst_limited = 0;
    while (next < end) {
        struct timespec ts = {(time_t)(next / 1000000000u), (long)(next % 1000000000u)};
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
        }
        const uint64_t now = mono_ns();
        unsigned b = 0;
        for (; b < SC_CAN_RX_BURST_MAX; b++) {
            sc_can_frame f;
            if (sc_can_recv(&dev, &f) != 0) {
                break;
            }
            feed(&trk, &st, &f, now);
            if (log) {
                sc_candump_rec r;
                memset(&r, 0, sizeof r);
                snprintf(r.iface, sizeof r.iface, "%s", iface);
                r.ts_us = f.ts_ns / 1000u;
                r.frame = f;
                (void)sc_candump_write(log, &r);
            }
        }
        burst_limited += b == SC_CAN_RX_BURST_MAX;
        poll_once(&trk, &st, now);
        next += period_ns;
    }
    if (log) {
        fclose(log);
    }
    sc_can_counters cnt;
    sc_can_state state;
    (void)sc_can_get_state(&dev, &state, &cnt);
    printf("burst_limited=%llu\nkernel_drops=%u\ncan_state=%d\n", (unsigned long long)burst_limited,
           cnt.rx_dropped, (int)state);
    /* REALTIME steps move kernel stamps taken before them (sc_socketcan.h): said, not hidden */
    printf("clock_steps=%u\nclock_uncertainty_ns=%llu\n", node.tsconv.steps,
           (unsigned long long)node.tsconv.uncertainty_ns);
    report(&trk, &st);
    sc_socketcan_close(&node);
    return 0;
}
