/* test_can_tracker_bus.c: the tracker behind the host simulator's CAN bus with fault injection,
 * fed by the tracker emulator, drained at 60 Hz as the engine's rx stage does (at most
 * SC_CAN_RX_BURST_MAX frames per frame); received traffic recorded as a candump -l log through
 * the receive tap, then replayed.
 * Properties: a pose the tracker accepts is always exactly a pose the emulator sent with that
 * counter (never a corrupted or stale one); every injected fault is counted (corruption, one
 * wrong CRC per corrupted copy delivered; duplicates; losses as counter gaps); the replay of
 * the recorded log reproduces the live run's outcomes and poses bit for bit. */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_assert.h"
#include "sc_candump.h"
#include "sc_config.h"
#include "sc_hs_can.h"
#include "sc_hs_can_tap.h"
#include "sc_hs_clock.h"
#include "sc_tracker.h"
#include "sc_trkemu.h"

#define START_NS UINT64_C(1000000000)
#define FRAME_NS UINT64_C(16666667) /* 60 Hz */
#define MAX_SENT 4096u

typedef struct sent_frame {
    sc_can_frame f;
} sent_frame;

typedef struct session {
    /* oracle: every frame the emulator sent, in order */
    sent_frame sent[MAX_SENT * 3u];
    uint32_t n_sent;
    /* per-stream view of delivered intact frames (index by id & 0xF: 0x100..0x102, 0x110) */
    int have_last[16];
    uint8_t last_counter[16];
    uint32_t exp_gap_lost;  /* gaps of 1..max_delta-1 frames */
    uint32_t exp_wrong_seq; /* bigger jumps (or going back) */
    uint32_t exp_repeated;
    uint32_t exp_bad_crc; /* delivered copies that differ from what was sent */
    uint32_t delivered;
    FILE *log;
    uint64_t hash;
    uint32_t accepted, bad_pose, polls, polls_with_pose;
    uint32_t polls_live, polls_live_without_pose; /* while the emulator was sending */
} session;

static void hash_bytes(session *s, const void *p, size_t n)
{
    const uint8_t *b = p;
    for (size_t i = 0; i < n; i++) {
        s->hash = (s->hash ^ b[i]) * UINT64_C(1099511628211);
    }
}

static int intact(const session *s, const sc_can_frame *f)
{
    for (uint32_t i = s->n_sent; i-- > 0u && i + 64u > s->n_sent;) {
        const sc_can_frame *g = &s->sent[i].f;
        if (g->id == f->id && g->len == f->len && memcmp(g->data, f->data, f->len) == 0) {
            return 1;
        }
    }
    return 0;
}

static void on_delivered(void *user, const sc_can_frame *f)
{
    session *s = user;
    s->delivered++;
    if (s->log) {
        sc_candump_rec rec;
        memset(&rec, 0, sizeof rec);
        strcpy(rec.iface, "vcan0");
        rec.ts_us = f->ts_ns / 1000u;
        rec.frame = *f;
        assert_int_equal(sc_candump_write(s->log, &rec), 0);
    }
    if (!intact(s, f)) {
        s->exp_bad_crc++;
        return;
    }
    const unsigned k = f->id & 0xFu;
    const uint8_t c = (uint8_t)(f->data[1] & 0x0Fu);
    if (s->have_last[k]) {
        const unsigned delta = (c + 16u - s->last_counter[k]) % 16u;
        if (delta == 0u) {
            s->exp_repeated++;
            return;
        }
        if (delta <= 3u) {
            s->exp_gap_lost += delta - 1u;
        } else {
            s->exp_wrong_seq++;
        }
    }
    s->have_last[k] = 1;
    s->last_counter[k] = c;
}

/* The pose the tracker would hold for a sent sample: decoded and normalised as it does. */
static int matches_a_sent_sample(const session *s, const sc_trk_sample *smp, int fd)
{
    for (uint32_t i = s->n_sent; i-- > 0u && i + 96u > s->n_sent;) {
        const sc_can_frame *g = &s->sent[i].f;
        if ((g->data[1] & 0x0Fu) != smp->counter ||
            g->id != (fd ? (uint32_t)SC_CANID_POSE_FD : (uint32_t)SC_CANID_POSE_AUX)) {
            continue;
        }
        sc_pose_msg m;
        memset(&m, 0, sizeof m);
        const uint32_t first = fd ? i : i - 2u;
        for (uint32_t j = first; j <= i; j++) {
            (void)sc_canproto_decode_pose_part(&s->sent[j].f, &m);
        }
        const float inv = 1.0f / sqrtf(sc_quat_norm2(m.q));
        int same = memcmp(m.pos_mm, smp->pose.pos_mm, sizeof m.pos_mm) == 0;
        for (int q = 0; q < 4; q++) {
            const float want = m.q[q] * inv;
            same = same && memcmp(&want, &smp->pose.q[q], sizeof want) == 0;
        }
        if (same) {
            return 1;
        }
    }
    return 0;
}

static void run_session(session *s, sc_tracker *t, const sc_hs_can_faults *faults, int fd,
                        uint64_t seed, FILE *replay_from)
{
    static sc_hs_clock clk;
    static sc_hs_can_bus bus;
    static sc_hs_can_tap tap;
    sc_hs_clock_init(&clk, START_NS);
    const sc_clock_dev clock = sc_hs_clock_dev(&clk);
    sc_hs_can_bus_init(&bus, &clock, seed);
    const int rx_node = sc_hs_can_add_node(&bus);
    const int tx_node = sc_hs_can_add_node(&bus);
    assert_true(rx_node >= 0 && tx_node >= 0);
    sc_hs_can_set_faults(&bus, faults);
    sc_hs_can_tap_init(&tap, sc_hs_can_dev(&bus, (uint32_t)rx_node), &clock, on_delivered, s);
    const sc_can_dev rx = sc_hs_can_tap_dev(&tap);
    const sc_can_dev tx = sc_hs_can_dev(&bus, (uint32_t)tx_node);
    sc_tracker_def td = sc_tracker_default_def();
    assert_int_equal(sc_tracker_init(t, &td), 0);

    sc_emu_def d = sc_emu_default_def();
    d.script = SC_EMU_SWEEP;
    d.fd = fd;
    d.duration_s = 20.0;
    static sc_emu emu;
    assert_int_equal(sc_emu_init(&emu, &d), 0);
    sc_can_frame fr[SC_EMU_MAX_FRAMES];
    uint64_t t_emu = 0;
    int n = replay_from ? SC_ERR_NOT_FOUND : sc_emu_next(&emu, fr, SC_EMU_MAX_FRAMES, &t_emu);
    sc_candump_reader rd;
    sc_candump_rec rec;
    int have_rec = 0;
    if (replay_from) {
        sc_candump_reader_init(&rd, replay_from);
        have_rec = sc_candump_reader_next(&rd, &rec) == 0;
    }
    for (uint64_t k = 0; k < 20u * 60u + 30u; k++) {
        const uint64_t now = START_NS + k * FRAME_NS;
        /* the tracker sends at its own rate between engine frames */
        while (n >= 0 && START_NS + t_emu <= now) {
            if (START_NS + t_emu > clk.now_ns) {
                sc_hs_clock_advance_ns(&clk, START_NS + t_emu - clk.now_ns);
            }
            for (int i = 0; i < n; i++) {
                assert_true(s->n_sent < SC_COUNT_OF(s->sent));
                s->sent[s->n_sent++].f = fr[i];
                assert_int_equal(sc_can_send(&tx, &fr[i]), 0);
            }
            n = sc_emu_next(&emu, fr, SC_EMU_MAX_FRAMES, &t_emu);
        }
        if (n < 0 && !replay_from) {
            sc_hs_can_flush(&bus);
        }
        /* replay: inject the frames the live run drained in this frame */
        while (have_rec && rec.frame.ts_ns <= now) {
            assert_int_equal(sc_hs_can_inject(&bus, (uint32_t)rx_node, &rec.frame), 0);
            have_rec = sc_candump_reader_next(&rd, &rec) == 0;
        }
        sc_hs_clock_advance_ns(&clk, now - clk.now_ns);
        /* rx stage: bounded drain */
        for (unsigned b = 0; b < SC_CAN_RX_BURST_MAX; b++) {
            sc_can_frame f;
            if (sc_can_recv(&rx, &f) != 0) {
                break;
            }
            const sc_trk_outcome o = sc_tracker_on_frame(t, &f, now);
            hash_bytes(s, &o, sizeof o);
            if (o == SC_TRK_POSE_ACCEPTED) {
                s->accepted++;
                /* the time the tracker keeps for the pose (speed and timeout decisions) */
                hash_bytes(s, &sc_tracker_sample(t)->rx_ns, sizeof(uint64_t));
                if (!replay_from && !matches_a_sent_sample(s, sc_tracker_sample(t), fd)) {
                    s->bad_pose++;
                }
            }
        }
        sc_pose p;
        int contact = 0;
        const int rc = sc_tracker_poll(t, now, &p, &contact);
        s->polls++;
        if (now < START_NS + (uint64_t)(d.duration_s * 1e9)) {
            s->polls_live++;
            s->polls_live_without_pose += rc != 0;
        }
        if (rc == 0) {
            s->polls_with_pose++;
            hash_bytes(s, &p, sizeof p);
        }
        hash_bytes(s, &contact, sizeof contact);
    }
    if (replay_from) {
        assert_false(have_rec); /* every recorded frame was replayed */
        assert_int_equal(sc_candump_reader_rejected_total(&rd), 0);
    }
}

static session live, again;
static sc_tracker trk_live, trk_again;

static void corruption_is_always_caught_and_counted_once_per_corrupted_copy(void **state)
{
    (void)state;
    for (int fd = 0; fd <= 1; fd++) {
        memset(&live, 0, sizeof live);
        const sc_hs_can_faults f = {.corrupt_ppm = 10000u}; /* 1 % */
        run_session(&live, &trk_live, &f, fd, 7u, NULL);
        const sc_trk_counters *k = sc_tracker_counters(&trk_live);
        assert_true(live.exp_bad_crc > 10u);
        assert_int_equal(k->outcome[SC_TRK_E2E_WRONG_CRC], live.exp_bad_crc);
        assert_int_equal(live.bad_pose, 0);
        /* the tracker falls silent at the end of the run: exactly that one lift */
        assert_int_equal(k->lift_events, 1);
        assert_int_equal(live.polls_live_without_pose, 0);
    }
}

static void duplicates_are_counted_as_duplicates_not_rejects(void **state)
{
    (void)state;
    for (int fd = 0; fd <= 1; fd++) {
        memset(&live, 0, sizeof live);
        const sc_hs_can_faults f = {.duplicate_ppm = 20000u};
        run_session(&live, &trk_live, &f, fd, 8u, NULL);
        const sc_trk_counters *k = sc_tracker_counters(&trk_live);
        assert_true(live.exp_repeated > 10u);
        assert_int_equal(live.exp_repeated, live.delivered - live.n_sent); /* nothing else */
        /* byte-for-byte repeats: nothing lost, nothing wrong: counted apart from the rejects */
        assert_int_equal(k->outcome[SC_TRK_DUPLICATE], live.exp_repeated);
        assert_int_equal(sc_tracker_rejected_e2e(&trk_live), 0);
        assert_int_equal(live.bad_pose, 0);
        assert_int_equal(k->outcome[SC_TRK_POSE_ACCEPTED], fd ? live.n_sent : live.n_sent / 3u);
    }
}

static void losses_are_counted_as_counter_gaps_or_wrong_sequences(void **state)
{
    (void)state;
    for (int fd = 0; fd <= 1; fd++) {
        memset(&live, 0, sizeof live);
        const sc_hs_can_faults f = {.drop_ppm = 100000u}; /* 10 % */
        run_session(&live, &trk_live, &f, fd, 9u, NULL);
        const sc_trk_counters *k = sc_tracker_counters(&trk_live);
        assert_true(live.exp_gap_lost > 100u);
        assert_int_equal(k->e2e_lost, live.exp_gap_lost);
        assert_int_equal(k->outcome[SC_TRK_E2E_WRONG_SEQUENCE], live.exp_wrong_seq);
        assert_int_equal(live.bad_pose, 0);
        /* a classic sample with a lost part never completes; the FD sample is all or nothing */
        if (!fd) {
            assert_true(k->incomplete > 0u);
        }
        /* 60 Hz polls over a 100 Hz tracker losing 10 %: the probe stays tracked */
        assert_true(live.polls_live_without_pose * 100u <= live.polls_live);
        printf("# %s, 10%% loss: %u of %u polls without a pose while the tracker sent, "
               "%u lifts, %u samples accepted of %u\n",
               fd ? "FD" : "classic", live.polls_live_without_pose, live.polls_live, k->lift_events,
               live.accepted, fd ? live.n_sent : live.n_sent / 3u);
    }
}

static void combined_faults_never_yield_a_bad_pose_and_replay_is_bit_exact(void **state)
{
    (void)state;
    for (int fd = 0; fd <= 1; fd++) {
        memset(&live, 0, sizeof live);
        memset(&again, 0, sizeof again);
        const sc_hs_can_faults f = {.drop_ppm = 100000u,
                                    .corrupt_ppm = 10000u,
                                    .duplicate_ppm = 10000u,
                                    .reorder_ppm = 10000u};
        char *buf = NULL;
        size_t len = 0;
        live.log = open_memstream(&buf, &len);
        assert_non_null(live.log);
        run_session(&live, &trk_live, &f, fd, 10u + (uint64_t)fd, NULL);
        fclose(live.log);
        live.log = NULL;
        const sc_trk_counters *k = sc_tracker_counters(&trk_live);
        assert_int_equal(live.bad_pose, 0);
        assert_int_equal(k->outcome[SC_TRK_E2E_WRONG_CRC], live.exp_bad_crc);
        assert_true(k->outcome[SC_TRK_DUPLICATE] >= 1u);
        assert_true(live.accepted > (fd ? 1500u : 1000u));

        FILE *in = fmemopen(buf, len, "r");
        assert_non_null(in);
        run_session(&again, &trk_again, &f, fd, 10u + (uint64_t)fd, in);
        fclose(in);
        free(buf);
        assert_int_equal(again.accepted, live.accepted);
        assert_int_equal(again.polls_with_pose, live.polls_with_pose);
        assert_true(again.hash == live.hash);
        assert_memory_equal(sc_tracker_counters(&trk_again), sc_tracker_counters(&trk_live),
                            sizeof(sc_trk_counters));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(corruption_is_always_caught_and_counted_once_per_corrupted_copy),
        cmocka_unit_test(duplicates_are_counted_as_duplicates_not_rejects),
        cmocka_unit_test(losses_are_counted_as_counter_gaps_or_wrong_sequences),
        cmocka_unit_test(combined_faults_never_yield_a_bad_pose_and_replay_is_bit_exact),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
