/* test_sc_sched.c: frame scheduler on the virtual clock: periods, stage timing, misses and
 * resynchronisation (never queued), statistics. */
#include "sc_test.h"

#include "sc_err.h"
#include "sc_hs_clock.h"
#include "sc_sched.h"

typedef struct fixture {
    sc_hs_clock clock;
    sc_clock_dev dev;
    sc_sched sched;
    uint64_t cost_a_ns; /* virtual time each stage "takes" */
    uint64_t cost_b_ns;
    uint32_t calls_a, calls_b;
} fixture;

static void stage_a(void *user)
{
    fixture *f = user;
    f->calls_a++;
    sc_hs_clock_advance_ns(&f->clock, f->cost_a_ns);
}

static void stage_b(void *user)
{
    fixture *f = user;
    f->calls_b++;
    sc_hs_clock_advance_ns(&f->clock, f->cost_b_ns);
}

/* One frame as the engine runs it: begin, the stages in order with a mark after each, end. */
static void run_frame(fixture *f, sc_frame_result *r)
{
    sc_sched_begin_frame(&f->sched);
    stage_a(f);
    sc_sched_stage_done(&f->sched, 0);
    stage_b(f);
    sc_sched_stage_done(&f->sched, 1);
    sc_sched_end_frame(&f->sched, r);
}

static int setup(void **state)
{
    static fixture f;
    f = (fixture){0};
    sc_hs_clock_init(&f.clock, 1000000000u);
    f.dev = sc_hs_clock_dev(&f.clock);
    sc_sched_def def = sc_sched_default_def();
    assert_int_equal(sc_sched_init(&f.sched, &def, &f.dev), SC_OK);
    assert_int_equal(sc_sched_add_stage(&f.sched, "a"), 0);
    assert_int_equal(sc_sched_add_stage(&f.sched, "b"), 1);
    *state = &f;
    return 0;
}

static void default_period_is_60_hz(void **state)
{
    fixture *f = *state;
    assert_int_equal(f->sched.period_ns, 1000000000u / 60u);
}

static void frames_release_on_fixed_period_without_drift(void **state)
{
    fixture *f = *state;
    f->cost_a_ns = 3000000u; /* 3 ms + 2 ms of 16.67 ms */
    f->cost_b_ns = 2000000u;
    sc_frame_result r;
    uint64_t first = 0;
    for (uint32_t i = 0; i < 600; i++) {
        run_frame(f, &r);
        if (i == 0) {
            first = r.release_ns;
        }
        assert_int_equal(r.release_ns, first + (uint64_t)i * f->sched.period_ns);
        assert_false(r.missed);
    }
    assert_int_equal(f->calls_a, 600);
    assert_int_equal(f->calls_b, 600);
    assert_int_equal(f->sched.misses, 0);
    /* per-stage times measured through the HAL clock */
    assert_int_equal(f->sched.stages[0].stats.worst_ns, 3000000u);
    assert_int_equal(f->sched.stages[1].stats.best_ns, 2000000u);
    assert_int_equal(f->sched.frame_stats.worst_ns, 5000000u);
}

static void miss_is_counted_and_schedule_resynchronises_without_queueing(void **state)
{
    fixture *f = *state;
    const uint64_t p = f->sched.period_ns;
    f->cost_a_ns = 1000000u;
    sc_frame_result r;
    run_frame(f, &r);
    const uint64_t r0 = r.release_ns;
    /* one frame takes 2.5 periods */
    f->cost_a_ns = p * 5u / 2u;
    run_frame(f, &r);
    assert_true(r.missed);
    assert_int_equal(r.release_ns, r0 + p);
    assert_int_equal(r.periods_skipped, 2);
    assert_int_equal(f->sched.misses, 1);
    /* the next frame starts at the first boundary after the end: r0 + 4p, not r0 + 2p */
    f->cost_a_ns = 1000000u;
    run_frame(f, &r);
    assert_false(r.missed);
    assert_int_equal(r.release_ns, r0 + 4u * p);
    assert_int_equal(r.start_ns, r0 + 4u * p);
    assert_int_equal(f->sched.periods_skipped, 2);
    assert_int_equal(sc_sched_recent_misses(&f->sched, 64), 1);
}

static void frame_ending_exactly_on_deadline_is_not_a_miss(void **state)
{
    fixture *f = *state;
    f->cost_a_ns = f->sched.period_ns;
    sc_frame_result r;
    run_frame(f, &r);
    assert_false(r.missed);
    f->cost_a_ns = f->sched.period_ns + 1u;
    run_frame(f, &r);
    assert_true(r.missed);
}

static void stage_limit_and_rate_range_are_enforced(void **state)
{
    fixture *f = *state;
    for (uint32_t i = 2; i < SC_SCHED_MAX_STAGES; i++) {
        assert_true(sc_sched_add_stage(&f->sched, "x") >= 0);
    }
    assert_int_equal(sc_sched_add_stage(&f->sched, "x"), SC_ERR_NO_SPACE);
    assert_int_equal(sc_sched_set_rate(&f->sched, 0), SC_ERR_RANGE);
    assert_int_equal(sc_sched_set_rate(&f->sched, SC_FRAME_RATE_MAX_HZ + 1u), SC_ERR_RANGE);
    sc_sched_def bad = {.rate_hz = 0};
    sc_sched s2;
    assert_int_equal(sc_sched_init(&s2, &bad, &f->dev), SC_ERR_RANGE);
    sc_frame_result r;
    run_frame(f, &r);
    assert_int_equal(sc_sched_add_stage(&f->sched, "late"), SC_ERR_STATE);
}

static void recent_misses_window_forgets_old_frames(void **state)
{
    fixture *f = *state;
    sc_frame_result r;
    f->cost_a_ns = f->sched.period_ns * 2u;
    run_frame(f, &r);
    assert_int_equal(sc_sched_recent_misses(&f->sched, 64), 1);
    f->cost_a_ns = 1000u;
    for (int i = 0; i < 64; i++) {
        run_frame(f, &r);
    }
    assert_int_equal(sc_sched_recent_misses(&f->sched, 64), 0);
    assert_int_equal(f->sched.misses, 1);
}

/* Each stage's time in the last frame (sc_sched_stage.last_ns, the frame trace's columns):
 * the time since the previous mark; a stage the frame does not mark reads 0. */
static void stage_last_times_are_the_frame_s_own(void **state)
{
    fixture *f = *state;
    sc_frame_result r;
    f->cost_a_ns = 3000u;
    f->cost_b_ns = 5000u;
    run_frame(f, &r);
    assert_int_equal(f->sched.stages[0].last_ns, 3000u);
    assert_int_equal(f->sched.stages[1].last_ns, 5000u);
    assert_int_equal(r.end_ns - r.start_ns, 8000u);
    /* a frame that marks only stage 0 */
    sc_sched_begin_frame(&f->sched);
    sc_hs_clock_advance_ns(&f->clock, 700u);
    sc_sched_stage_done(&f->sched, 0);
    sc_sched_end_frame(&f->sched, &r);
    assert_int_equal(f->sched.stages[0].last_ns, 700u);
    assert_int_equal(f->sched.stages[1].last_ns, 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(default_period_is_60_hz, setup),
        cmocka_unit_test_setup(frames_release_on_fixed_period_without_drift, setup),
        cmocka_unit_test_setup(miss_is_counted_and_schedule_resynchronises_without_queueing,
                               setup),
        cmocka_unit_test_setup(frame_ending_exactly_on_deadline_is_not_a_miss, setup),
        cmocka_unit_test_setup(stage_limit_and_rate_range_are_enforced, setup),
        cmocka_unit_test_setup(recent_misses_window_forgets_old_frames, setup),
        cmocka_unit_test_setup(stage_last_times_are_the_frame_s_own, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
