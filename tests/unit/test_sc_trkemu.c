/* test_sc_trkemu.c: the tracker emulator against the engine's tracker, directly (no bus):
 * every script is plausible from end to end, and every injected fault is counted by the
 * tracker exactly as often as it was injected. */
#include "sc_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sc_err.h"
#include "sc_tracker.h"
#include "sc_trkemu.h"

typedef struct run_result {
    uint32_t polls_with_pose;
    uint32_t polls;
} run_result;

/* Runs the emulator into a fresh tracker; polls at 60 Hz. */
static run_result run(sc_emu *e, sc_tracker *t)
{
    sc_tracker_def td = sc_tracker_default_def();
    assert_int_equal(sc_tracker_init(t, &td), 0);
    run_result r = {0, 0};
    sc_can_frame fr[SC_EMU_MAX_FRAMES];
    uint64_t t_ns = 0, next_poll = 0;
    int n;
    while ((n = sc_emu_next(e, fr, SC_EMU_MAX_FRAMES, &t_ns)) >= 0) {
        for (; next_poll <= t_ns; next_poll += 16666667u) {
            sc_pose p;
            int contact;
            r.polls++;
            r.polls_with_pose += sc_tracker_poll(t, next_poll, &p, &contact) == 0;
        }
        for (int k = 0; k < n; k++) {
            fr[k].ts_ns = t_ns + (uint64_t)k * 100000u;
            (void)sc_tracker_on_frame(t, &fr[k], fr[k].ts_ns);
        }
    }
    assert_int_equal(n, SC_ERR_NOT_FOUND);
    return r;
}

static void every_script_is_accepted_whole_classic_and_fd(void **state)
{
    (void)state;
    static sc_emu_row rows[3] = {
        {0.0, {0.0f, 0.0f, 20.0f}, {0.0f, 1.0f, 0.0f, 0.0f}, -1.0f},
        {2.0, {10.0f, 5.0f, -5.0f}, {0.0f, 0.9659258f, 0.258819f, 0.0f}, 2.5f},
        {4.0, {20.0f, 0.0f, 20.0f}, {0.0f, 1.0f, 0.0f, 0.0f}, -1.0f},
    };
    for (int s = 0; s < (int)SC_EMU_SCRIPT_COUNT; s++) {
        for (int fd = 0; fd <= 1; fd++) {
            sc_emu_def d = sc_emu_default_def();
            d.script = (sc_emu_script)s;
            d.fd = fd;
            d.duration_s = 8.0;
            d.rows = rows;
            d.n_rows = 3;
            sc_emu e;
            assert_int_equal(sc_emu_init(&e, &d), 0);
            static sc_tracker t;
            run(&e, &t);
            const sc_trk_counters *k = sc_tracker_counters(&t);
            assert_int_equal(k->outcome[SC_TRK_POSE_ACCEPTED], e.samples_sent);
            assert_int_equal(sc_tracker_rejected_e2e(&t), 0);
            assert_int_equal(sc_tracker_rejected_implausible(&t), 0);
            assert_int_equal(k->incomplete, 0);
            /* lift: silence after 2.5 s is one lift event; the others never lift */
            assert_int_equal(k->lift_events, s == SC_EMU_LIFT ? 1u : 0u);
        }
    }
}

static void press_goes_down_to_the_depth_and_back_with_a_contact_force(void **state)
{
    (void)state;
    sc_emu_def d = sc_emu_default_def();
    const sc_pose_msg hover = sc_emu_pose_at(&d, 0.25);
    const sc_pose_msg pressed = sc_emu_pose_at(&d, 2.0);
    assert_true(fabsf(hover.pos_mm[2] - 30.0f) < 1e-4f);
    assert_true(fabsf(pressed.pos_mm[2] + 10.0f) < 1e-4f);
    assert_true(fabsf(pressed.force_n - 5.0f) < 1e-4f); /* 0.5 N/mm x 10 mm */
    assert_true(fabsf(hover.force_n) < 1e-6f);
    d.script = SC_EMU_ROCK;
    const sc_pose_msg tilted = sc_emu_pose_at(&d, 1.0); /* quarter period: full angle */
    /* angle between base and tilted orientation = 15 degrees: |dot| = cos(7.5 deg) */
    float dot = 0.0f;
    for (int k = 0; k < 4; k++) {
        dot += tilted.q[k] * d.base_q[k];
    }
    assert_true(fabsf(fabsf(dot) - cosf(7.5f * 3.14159265f / 180.0f)) < 1e-5f);
}

static void every_injected_fault_is_counted_by_the_tracker(void **state)
{
    (void)state;
    for (int fd = 0; fd <= 1; fd++) {
        sc_emu_def d = sc_emu_default_def();
        d.script = SC_EMU_SWEEP;
        d.fd = fd;
        d.duration_s = 30.0;
        d.faults[0] = (sc_emu_fault){SC_EMU_F_BAD_CRC, 7u, 0.0};
        d.faults[1] = (sc_emu_fault){SC_EMU_F_REPEAT, 11u, 0.0};
        d.faults[2] = (sc_emu_fault){SC_EMU_F_IMPLAUSIBLE, 13u, 0.0};
        d.faults[3] = (sc_emu_fault){SC_EMU_F_COUNTER_JUMP, 97u, 0.0};
        d.faults[4] = (sc_emu_fault){SC_EMU_F_SILENCE, 500u, 0.0};
        d.n_faults = 5;
        sc_emu e;
        assert_int_equal(sc_emu_init(&e, &d), 0);
        static sc_tracker t;
        const run_result r = run(&e, &t);
        const sc_trk_counters *k = sc_tracker_counters(&t);
        const uint32_t parts = fd ? 1u : 3u;
        for (int f = 0; f < (int)SC_EMU_F_COUNT; f++) {
            assert_true(e.injected[f] > 0u);
        }
        assert_int_equal(k->outcome[SC_TRK_E2E_WRONG_CRC], e.injected[SC_EMU_F_BAD_CRC]);
        /* a sample sent twice is a duplicate of every frame: counted, not rejected */
        assert_int_equal(k->outcome[SC_TRK_DUPLICATE], parts * e.injected[SC_EMU_F_REPEAT]);
        assert_int_equal(k->outcome[SC_TRK_E2E_REPEATED], 0);
        assert_int_equal(k->outcome[SC_TRK_E2E_WRONG_SEQUENCE],
                         parts * e.injected[SC_EMU_F_COUNTER_JUMP]);
        assert_int_equal(sc_tracker_rejected_implausible(&t), e.injected[SC_EMU_F_IMPLAUSIBLE]);
        assert_int_equal(k->lift_events, e.injected[SC_EMU_F_SILENCE]);
        /* a classic sample with a corrupted part never completes */
        assert_int_equal(k->incomplete, fd ? 0u : e.injected[SC_EMU_F_BAD_CRC]);
        /* every other sample was accepted */
        assert_int_equal(k->outcome[SC_TRK_POSE_ACCEPTED],
                         e.samples_sent - e.injected[SC_EMU_F_BAD_CRC] -
                             e.injected[SC_EMU_F_IMPLAUSIBLE] - e.injected[SC_EMU_F_COUNTER_JUMP]);
        /* between silences the engine always had a pose (polls at 60 Hz, poses at 100 Hz) */
        assert_true(r.polls_with_pose + e.injected[SC_EMU_F_SILENCE] * 20u >= r.polls);
        assert_true(r.polls_with_pose < r.polls);
    }
}

static void csv_rows_load_and_bad_rows_name_their_line(void **state)
{
    (void)state;
    char good[] =
        "t_s,x,y,z,qw,qx,qy,qz,force\n# comment\n0,1,2,3,1,0,0,0\n0.5, 1,2,3, 1,0,0,0, 4.5\n";
    sc_emu_row rows[4];
    size_t n = 0, bad = 0;
    FILE *fp = fmemopen(good, strlen(good), "r");
    assert_int_equal(sc_emu_load_csv(fp, rows, 4, &n, &bad), 0);
    fclose(fp);
    assert_int_equal(n, 2);
    assert_true(fabsf(rows[1].force_n - 4.5f) < 1e-6f && rows[0].force_n < 0.0f);
    char nonmono[] = "0,1,2,3,1,0,0,0\n0,1,2,3,1,0,0,0\n";
    fp = fmemopen(nonmono, strlen(nonmono), "r");
    assert_int_equal(sc_emu_load_csv(fp, rows, 4, &n, &bad), SC_ERR_PARSE);
    fclose(fp);
    assert_int_equal(bad, 2);
    char shortrow[] = "0,1,2,3,1,0,0,0\n1,2,3\n";
    fp = fmemopen(shortrow, strlen(shortrow), "r");
    assert_int_equal(sc_emu_load_csv(fp, rows, 4, &n, &bad), SC_ERR_PARSE);
    fclose(fp);
    assert_int_equal(bad, 2);
    char junk[] = "0,1,2,3,1,0,0,0,x\n";
    fp = fmemopen(junk, strlen(junk), "r");
    assert_int_equal(sc_emu_load_csv(fp, rows, 4, &n, &bad), SC_ERR_PARSE);
    fclose(fp);
}

/* A line longer than a row can be (or holding a NUL) is refused with its own number, never
 * read in pieces: here a 600-byte comment whose tail would parse as a second row. */
static void csv_overlong_lines_are_refused_whole(void **state)
{
    (void)state;
    static char text[1024];
    sc_emu_row rows[4];
    size_t n = 0, bad = 0;
    int len = snprintf(text, sizeof text, "0,1,2,3,1,0,0,0\n#%*s1,1,2,3,1,0,0,0\n", 600, "");
    FILE *fp = fmemopen(text, (size_t)len, "r");
    assert_int_equal(sc_emu_load_csv(fp, rows, 4, &n, &bad), SC_ERR_PARSE);
    fclose(fp);
    assert_int_equal(bad, 2);
    /* the longest line accepted: 510 bytes before its newline */
    len = snprintf(text, sizeof text, "0,1,2,3,1,0,0,0%*s\n", 510 - 15, "");
    fp = fmemopen(text, (size_t)len, "r");
    assert_int_equal(sc_emu_load_csv(fp, rows, 4, &n, &bad), 0);
    fclose(fp);
    assert_int_equal(n, 1);
    const char with_nul[] = "0,1,2,3,1,0,0,0\n1,1,2,3\0,1,0,0,0\n";
    fp = fmemopen((void *)with_nul, sizeof with_nul - 1u, "r");
    assert_int_equal(sc_emu_load_csv(fp, rows, 4, &n, &bad), SC_ERR_PARSE);
    fclose(fp);
    assert_int_equal(bad, 2);
}

typedef struct sink {
    uint32_t frames;
    uint32_t ids[64];
} sink;

static int collect(void *ctx, const sc_can_frame *f)
{
    sink *k = ctx;
    if (k->frames < 64u) {
        k->ids[k->frames] = f->id;
    }
    k->frames++;
    return 0;
}

/* sc_emu_feed hands over exactly the samples due up to the given time, in order, and says
 * when the script is over. 100 Hz: samples at 0, 10, 20 ms ... */
static void feed_sends_every_due_sample_once(void **state)
{
    (void)state;
    sc_emu_def d = sc_emu_default_def();
    d.duration_s = 0.05; /* samples at 0 .. 40 ms */
    sc_emu e;
    assert_int_equal(sc_emu_init(&e, &d), 0);
    sink k = {0};
    assert_int_equal(sc_emu_next_time_ns(&e), 0u);
    assert_int_equal(sc_emu_feed(&e, 0u, collect, &k), 1); /* the sample at t = 0 */
    const uint32_t per_sample = k.frames;
    assert_true(per_sample >= 1u);
    assert_int_equal(sc_emu_feed(&e, 9999999u, collect, &k), 0); /* nothing due */
    assert_int_equal(sc_emu_next_time_ns(&e), 10000000u);
    assert_int_equal(sc_emu_feed(&e, 30000000u, collect, &k), 3); /* 10, 20, 30 ms */
    assert_int_equal(k.frames, 4u * per_sample);
    assert_int_equal(e.samples_sent, 4u);
    assert_int_equal(sc_emu_feed(&e, UINT64_MAX, collect, &k), 1); /* 40 ms, then the end */
    assert_int_equal(sc_emu_feed(&e, UINT64_MAX, collect, &k), SC_ERR_NOT_FOUND);
    assert_int_equal(k.frames, 5u * per_sample);
    /* the frames came in sample order: the same id sequence each sample */
    for (uint32_t i = per_sample; i < k.frames && i < 64u; i++) {
        assert_int_equal(k.ids[i], k.ids[i % per_sample]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_script_is_accepted_whole_classic_and_fd),
        cmocka_unit_test(press_goes_down_to_the_depth_and_back_with_a_contact_force),
        cmocka_unit_test(every_injected_fault_is_counted_by_the_tracker),
        cmocka_unit_test(csv_rows_load_and_bad_rows_name_their_line),
        cmocka_unit_test(csv_overlong_lines_are_refused_whole),
        cmocka_unit_test(feed_sends_every_due_sample_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
