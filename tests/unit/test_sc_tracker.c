/* test_sc_tracker.c: pose assembly, every E2E and plausibility rejection, timeout -> lifted,
 * newest pose with a slow tracker, commands, error frames, status encoding. */
#include "sc_test.h"

#include <math.h>
#include <string.h>

#include "sc_err.h"
#include "sc_status_tx.h"
#include "sc_tracker.h"
#include "sc_cmdsign.h"

#define MS UINT64_C(1000000)

static sc_tracker trk;

static int setup(void **state)
{
    (void)state;
    sc_tracker_def d = sc_tracker_default_def();
    return sc_tracker_init(&trk, &d);
}

static sc_pose_msg pose_at(float x, float y, float z)
{
    return (sc_pose_msg){.pos_mm = {x, y, z}, .q = {1.0f, 0.0f, 0.0f, 0.0f}};
}

/* Sends one sample; returns the outcome of its last frame and checks the earlier ones. */
static sc_trk_outcome send_pose(const sc_pose_msg *p, uint8_t counter, uint64_t t_ns, int fd)
{
    sc_can_frame f[3];
    size_t n = 0;
    assert_int_equal(sc_canproto_encode_pose(p, counter, fd, f, 3, &n), 0);
    sc_trk_outcome o = SC_TRK_OUTCOME_COUNT;
    for (size_t i = 0; i < n; i++) {
        f[i].ts_ns = t_ns;
        o = sc_tracker_on_frame(&trk, &f[i], t_ns);
        if (i + 1 < n) {
            assert_int_equal(o, SC_TRK_POSE_PART);
        }
    }
    return o;
}

static void classic_pose_is_assembled_from_three_frames_and_normalised(void **state)
{
    (void)state;
    sc_pose_msg p = pose_at(10.0f, -20.0f, 30.0f);
    /* 90 degrees about z, scaled by 1.01 (inside the 0.02 norm tolerance) */
    p.q[0] = 0.70710678f * 1.01f;
    p.q[3] = 0.70710678f * 1.01f;
    p.force_valid = 1;
    p.force_n = 4.5f;
    sc_pose out;
    int contact = -1;
    assert_int_equal(sc_tracker_poll(&trk, 0, &out, &contact), SC_ERR_TIMEOUT);
    assert_int_equal(contact, 0);
    assert_int_equal(send_pose(&p, 0, 1 * MS, 0), SC_TRK_POSE_ACCEPTED);
    assert_int_equal(sc_tracker_poll(&trk, 2 * MS, &out, &contact), 0);
    assert_int_equal(contact, 1);
    /* position within half a 0.05 mm step; unit quaternion within Q14 rounding */
    assert_true(fabsf(out.pos_mm[0] - 10.0f) <= 0.025f);
    assert_true(fabsf(out.pos_mm[1] + 20.0f) <= 0.025f);
    assert_true(fabsf(out.pos_mm[2] - 30.0f) <= 0.025f);
    assert_true(fabsf(sc_quat_norm2(out.q) - 1.0f) <= 1e-5f);
    assert_true(fabsf(out.q[0] - 0.70710678f) <= 1e-4f);
    assert_true(fabsf(out.q[3] - 0.70710678f) <= 1e-4f);
    const sc_trk_sample *s = sc_tracker_sample(&trk);
    assert_non_null(s);
    assert_int_equal(s->force_valid, 1);
    assert_true(fabsf(s->force_n - 4.5f) <= 0.005f);
    assert_int_equal(sc_tracker_counters(&trk)->outcome[SC_TRK_POSE_ACCEPTED], 1);
    assert_int_equal(sc_tracker_counters(&trk)->outcome[SC_TRK_POSE_PART], 2);
}

static void parts_of_consecutive_samples_may_interleave(void **state)
{
    (void)state;
    sc_pose_msg a = pose_at(0.0f, 0.0f, 0.0f), b = pose_at(1.0f, 0.0f, 0.0f);
    sc_can_frame fa[3], fb[3];
    size_t n;
    assert_int_equal(sc_canproto_encode_pose(&a, 4, 0, fa, 3, &n), 0);
    assert_int_equal(sc_canproto_encode_pose(&b, 5, 0, fb, 3, &n), 0);
    /* order on the bus: A.pos B.pos A.quat B.quat A.aux B.aux */
    const sc_can_frame *order[6] = {&fa[0], &fb[0], &fa[1], &fb[1], &fa[2], &fb[2]};
    const sc_trk_outcome want[6] = {SC_TRK_POSE_PART, SC_TRK_POSE_PART,     SC_TRK_POSE_PART,
                                    SC_TRK_POSE_PART, SC_TRK_POSE_ACCEPTED, SC_TRK_POSE_ACCEPTED};
    for (int i = 0; i < 6; i++) {
        assert_int_equal(sc_tracker_on_frame(&trk, order[i], (uint64_t)(10 + i) * MS), want[i]);
    }
    sc_pose out;
    int c;
    assert_int_equal(sc_tracker_poll(&trk, 20 * MS, &out, &c), 0);
    assert_true(fabsf(out.pos_mm[0] - 1.0f) <= 0.025f); /* newest sample */
    assert_int_equal(sc_tracker_counters(&trk)->incomplete, 0);
}

static void a_lost_part_drops_its_sample_and_is_counted(void **state)
{
    (void)state;
    sc_can_frame f[3];
    size_t n;
    sc_pose_msg p = pose_at(0.0f, 0.0f, 0.0f);
    /* sample 0 loses its quaternion frame; samples 1 and 2 arrive whole */
    assert_int_equal(sc_canproto_encode_pose(&p, 0, 0, f, 3, &n), 0);
    assert_int_equal(sc_tracker_on_frame(&trk, &f[0], 1 * MS), SC_TRK_POSE_PART);
    assert_int_equal(sc_tracker_on_frame(&trk, &f[2], 1 * MS), SC_TRK_POSE_PART);
    assert_int_equal(send_pose(&p, 1, 11 * MS, 0), SC_TRK_POSE_ACCEPTED); /* drops sample 0 */
    assert_int_equal(sc_tracker_counters(&trk)->incomplete, 1);
    assert_int_equal(send_pose(&p, 2, 21 * MS, 0), SC_TRK_POSE_ACCEPTED);
    assert_int_equal(sc_tracker_counters(&trk)->incomplete, 1);
    /* the quaternion stream lost counter 0 only: its E2E receiver saw 1 first (INITIAL) */
    assert_int_equal(sc_tracker_e2e(&trk, SC_MSG_POSE_QUAT)->count[SC_E2E_INITIAL], 1);
}

static void a_sample_completed_after_a_newer_one_is_stale_and_never_used(void **state)
{
    (void)state;
    sc_pose_msg a = pose_at(5.0f, 0.0f, 0.0f), b = pose_at(6.0f, 0.0f, 0.0f);
    sc_can_frame fa[3], fb[3];
    size_t n;
    assert_int_equal(sc_canproto_encode_pose(&a, 3, 0, fa, 3, &n), 0);
    assert_int_equal(sc_canproto_encode_pose(&b, 4, 0, fb, 3, &n), 0);
    /* the aux frame of sample 3 is delayed behind all of sample 4 */
    assert_int_equal(sc_tracker_on_frame(&trk, &fa[0], 1 * MS), SC_TRK_POSE_PART);
    assert_int_equal(sc_tracker_on_frame(&trk, &fa[1], 1 * MS), SC_TRK_POSE_PART);
    assert_int_equal(sc_tracker_on_frame(&trk, &fb[0], 11 * MS), SC_TRK_POSE_PART);
    assert_int_equal(sc_tracker_on_frame(&trk, &fb[1], 11 * MS), SC_TRK_POSE_PART);
    assert_int_equal(sc_tracker_on_frame(&trk, &fb[2], 11 * MS), SC_TRK_POSE_ACCEPTED);
    /* sc_e2e on the aux stream: counter 3 after 4 goes back: rejected before assembly */
    assert_int_equal(sc_tracker_on_frame(&trk, &fa[2], 12 * MS), SC_TRK_E2E_WRONG_SEQUENCE);
    sc_pose out;
    int c;
    assert_int_equal(sc_tracker_poll(&trk, 13 * MS, &out, &c), 0);
    assert_true(fabsf(out.pos_mm[0] - 6.0f) <= 0.025f);
}

static void fd_pose_is_accepted_unless_disabled(void **state)
{
    (void)state;
    sc_pose_msg p = pose_at(1.0f, 2.0f, 3.0f);
    assert_int_equal(send_pose(&p, 0, 1 * MS, 1), SC_TRK_POSE_ACCEPTED);
    sc_tracker_def d = sc_tracker_default_def();
    d.accept_fd = 0;
    assert_int_equal(sc_tracker_init(&trk, &d), 0);
    assert_int_equal(send_pose(&p, 0, 1 * MS, 1), SC_TRK_FD_DISABLED);
    sc_pose out;
    int c;
    assert_int_equal(sc_tracker_poll(&trk, 2 * MS, &out, &c), SC_ERR_TIMEOUT);
}

static void every_e2e_fault_is_rejected_counted_and_never_used(void **state)
{
    (void)state;
    sc_pose_msg p = pose_at(0.0f, 0.0f, 0.0f);
    assert_int_equal(send_pose(&p, 0, 1 * MS, 1), SC_TRK_POSE_ACCEPTED);
    /* the same frame again (a bus duplicate): counted as such, not as a reject */
    assert_int_equal(send_pose(&p, 0, 2 * MS, 1), SC_TRK_DUPLICATE);
    sc_can_frame f[3];
    size_t n;
    sc_pose_msg q = pose_at(0.5f, 0.0f, 0.0f);
    /* wrong CRC */
    assert_int_equal(sc_canproto_encode_pose(&q, 1, 1, f, 3, &n), 0);
    f[0].data[4] ^= 0x01u;
    assert_int_equal(sc_tracker_on_frame(&trk, &f[0], 11 * MS), SC_TRK_E2E_WRONG_CRC);
    /* repeated */
    assert_int_equal(send_pose(&q, 0, 21 * MS, 1), SC_TRK_E2E_REPEATED);
    /* counter jump beyond max delta (3): 0 -> 5 */
    assert_int_equal(send_pose(&q, 5, 31 * MS, 1), SC_TRK_E2E_WRONG_SEQUENCE);
    sc_pose out;
    int c;
    assert_int_equal(sc_tracker_poll(&trk, 32 * MS, &out, &c), 0);
    assert_true(fabsf(out.pos_mm[0]) <= 0.025f); /* still the first pose */
    /* re-anchored: 6 follows 5 */
    assert_int_equal(send_pose(&q, 6, 41 * MS, 1), SC_TRK_POSE_ACCEPTED);
    /* some lost (6 -> 8) is usable and the loss counted */
    assert_int_equal(send_pose(&q, 8, 51 * MS, 1), SC_TRK_POSE_ACCEPTED);
    const sc_trk_counters *k = sc_tracker_counters(&trk);
    assert_int_equal(k->outcome[SC_TRK_E2E_WRONG_CRC], 1);
    assert_int_equal(k->outcome[SC_TRK_E2E_REPEATED], 1);
    assert_int_equal(k->outcome[SC_TRK_E2E_WRONG_SEQUENCE], 1);
    assert_int_equal(k->e2e_lost, 1);
    assert_int_equal(k->outcome[SC_TRK_DUPLICATE], 1);
    assert_int_equal(sc_tracker_rejected_e2e(&trk), 3);
}

static void every_plausibility_rejection_is_named_counted_and_never_used(void **state)
{
    (void)state;
    const sc_tracker_def d = sc_tracker_default_def();
    sc_pose_msg ok = pose_at(0.0f, 0.0f, 100.0f);
    uint8_t ctr = 0;
    uint64_t t = 0;
    assert_int_equal(send_pose(&ok, ctr++, t += 10 * MS, 0), SC_TRK_POSE_ACCEPTED);

    struct {
        sc_pose_msg p;
        sc_trk_outcome want;
    } bad[9];
    size_t nb = 0;
    bad[nb].p = ok; /* norm 1.03 > 1 + 0.02 */
    bad[nb].p.q[0] = 1.03f;
    bad[nb++].want = SC_TRK_REJ_QUAT_NORM;
    bad[nb].p = ok; /* norm 0.97 */
    bad[nb].p.q[0] = 0.97f;
    bad[nb++].want = SC_TRK_REJ_QUAT_NORM;
    for (int axis = 0; axis < 3; axis++) { /* just outside the box on each axis */
        bad[nb].p = ok;
        bad[nb].p.pos_mm[axis] = d.ws_max_mm[axis] + 1.0f;
        bad[nb++].want = SC_TRK_REJ_WORKSPACE;
    }
    bad[nb].p = ok;
    bad[nb].p.pos_mm[2] = d.ws_min_mm[2] - 1.0f;
    bad[nb++].want = SC_TRK_REJ_WORKSPACE;
    bad[nb].p = ok;
    bad[nb].p.force_valid = 1;
    bad[nb].p.force_n = d.max_force_n + 1.0f;
    bad[nb++].want = SC_TRK_REJ_FORCE;
    /* 10 ms after the last pose: 3000 mm/s allows 30 mm; 40 mm is too fast */
    bad[nb].p = ok;
    bad[nb].p.pos_mm[0] = 40.0f;
    bad[nb++].want = SC_TRK_REJ_SPEED;
    /* 4 pi rad/s allows 0.126 rad in 10 ms; 90 degrees about x is too fast */
    bad[nb].p = ok;
    bad[nb].p.q[0] = 0.70710678f;
    bad[nb].p.q[1] = 0.70710678f;
    bad[nb++].want = SC_TRK_REJ_ANG_SPEED;

    for (size_t i = 0; i < nb; i++) {
        /* accept a good pose between rejections so the speed reference is 10 ms old */
        assert_int_equal(send_pose(&bad[i].p, ctr++, t += 10 * MS, 0), bad[i].want);
        sc_pose out;
        int c;
        assert_int_equal(sc_tracker_poll(&trk, t, &out, &c), 0);
        assert_true(fabsf(out.pos_mm[0]) <= 0.025f && fabsf(out.pos_mm[2] - 100.0f) <= 0.025f);
        assert_true(fabsf(out.q[0] - 1.0f) <= 1e-4f);
        assert_int_equal(send_pose(&ok, ctr++, t += 10 * MS, 0), SC_TRK_POSE_ACCEPTED);
        ctr %= 16u;
    }
    /* not tracking: ignored, not an implausibility */
    sc_pose_msg nt = ok;
    nt.tracking = SC_TRACKING_LOST;
    assert_int_equal(send_pose(&nt, ctr++, t += 10 * MS, 0), SC_TRK_NOT_TRACKING);

    const sc_trk_counters *k = sc_tracker_counters(&trk);
    assert_int_equal(k->outcome[SC_TRK_REJ_QUAT_NORM], 2);
    assert_int_equal(k->outcome[SC_TRK_REJ_WORKSPACE], 4);
    assert_int_equal(k->outcome[SC_TRK_REJ_FORCE], 1);
    assert_int_equal(k->outcome[SC_TRK_REJ_SPEED], 1);
    assert_int_equal(k->outcome[SC_TRK_REJ_ANG_SPEED], 1);
    assert_int_equal(k->outcome[SC_TRK_NOT_TRACKING], 1);
    assert_int_equal(sc_tracker_rejected_implausible(&trk), 9);
    assert_int_equal(k->outcome[SC_TRK_POSE_ACCEPTED], 1 + nb);
}

static void a_fast_move_becomes_plausible_when_enough_time_passed(void **state)
{
    (void)state;
    sc_pose_msg a = pose_at(0.0f, 0.0f, 0.0f), b = pose_at(60.0f, 0.0f, 0.0f);
    assert_int_equal(send_pose(&a, 0, 0, 0), SC_TRK_POSE_ACCEPTED);
    assert_int_equal(send_pose(&b, 1, 10 * MS, 0), SC_TRK_REJ_SPEED);
    /* 60 mm in 30 ms = 2000 mm/s < 3000 mm/s, measured from the last accepted pose */
    assert_int_equal(send_pose(&b, 2, 30 * MS, 0), SC_TRK_POSE_ACCEPTED);
}

static void silence_past_the_timeout_lifts_the_probe_and_return_skips_the_speed_check(void **s)
{
    (void)s;
    sc_pose_msg a = pose_at(0.0f, 0.0f, 0.0f), far = pose_at(300.0f, 0.0f, 0.0f);
    sc_pose out;
    int c;
    assert_int_equal(send_pose(&a, 0, 10 * MS, 0), SC_TRK_POSE_ACCEPTED);
    assert_int_equal(sc_tracker_poll(&trk, 110 * MS, &out, &c), 0); /* exactly at the limit */
    assert_int_equal(c, 1);
    assert_int_equal(sc_tracker_poll(&trk, 111 * MS, &out, &c), SC_ERR_TIMEOUT);
    assert_int_equal(c, 0);
    assert_null(sc_tracker_sample(&trk));
    assert_int_equal(sc_tracker_poll(&trk, 200 * MS, &out, &c), SC_ERR_TIMEOUT);
    assert_int_equal(sc_tracker_counters(&trk)->lift_events, 1); /* counted once */
    /* the E2E receivers timed out too: the next frame is INITIAL whatever its counter */
    assert_int_equal(send_pose(&far, 9, 210 * MS, 0), SC_TRK_POSE_ACCEPTED);
    assert_int_equal(sc_tracker_poll(&trk, 211 * MS, &out, &c), 0);
    assert_int_equal(c, 1);
    assert_true(fabsf(out.pos_mm[0] - 300.0f) <= 0.025f);
}

static void a_tracker_slower_than_the_frame_rate_never_stalls_and_gives_the_newest_pose(void **s)
{
    (void)s;
    /* 30 Hz tracker, 60 Hz engine polls for 2 s: every poll has a pose, the newest one. */
    uint64_t next_pose = 0;
    uint8_t ctr = 0;
    float x = 0.0f, last_x = -1.0f;
    for (uint64_t frame = 0; frame < 120u; frame++) {
        const uint64_t now = frame * 16666667u + 1u;
        while (next_pose <= now) {
            sc_pose_msg p = pose_at(x, 0.0f, 0.0f);
            assert_int_equal(send_pose(&p, ctr, next_pose, 0), SC_TRK_POSE_ACCEPTED);
            ctr = (uint8_t)((ctr + 1u) % 16u);
            last_x = x;
            x += 1.0f; /* 30 mm/s */
            next_pose += 33333333u;
        }
        sc_pose out;
        int c;
        assert_int_equal(sc_tracker_poll(&trk, now, &out, &c), 0);
        assert_true(fabsf(out.pos_mm[0] - last_x) <= 0.025f);
    }
    assert_int_equal(sc_tracker_counters(&trk)->lift_events, 0);
}

static void commands_are_queued_in_order_and_overflow_and_bad_values_are_counted(void **s)
{
    (void)s;
    /* authenticated commands (sc_secoc.h): a sync, then each command and its MAC */
    sc_cmdsign snd;
    assert_int_equal(sc_cmdsign_init(&snd, sc_secoc_bench_key, 0u, 1u, 0), SC_OK);
    sc_can_frame f[2];
    assert_int_equal(sc_cmdsign_sync(&snd, f), SC_OK);
    assert_int_equal(sc_tracker_on_frame(&trk, &f[0], 1), SC_TRK_CMD_PENDING);
    assert_int_equal(sc_tracker_on_frame(&trk, &f[1], 2), SC_TRK_AUTH_SYNCED);
    for (unsigned i = 0; i < SC_CAN_CMD_QUEUE_MAX + 2u; i++) {
        sc_cmd c = {.kind = SC_CMD_SELECT_CASE, .case_id = (uint8_t)i};
        assert_int_equal(sc_cmdsign_command(&snd, &c, f), 0);
        assert_int_equal(sc_tracker_on_frame(&trk, &f[0], i * MS), SC_TRK_CMD_PENDING);
        assert_int_equal(sc_tracker_on_frame(&trk, &f[1], i * MS),
                         i < SC_CAN_CMD_QUEUE_MAX ? SC_TRK_COMMAND : SC_TRK_CMD_QUEUE_FULL);
    }
    sc_cmd m = {.kind = SC_CMD_SET_METHOD, .method = SC_METHOD_FEM};
    assert_int_equal(sc_cmdsign_command(&snd, &m, f), 0);
    for (unsigned i = 0; i < SC_CAN_CMD_QUEUE_MAX; i++) {
        sc_cmd c;
        assert_int_equal(sc_tracker_take_command(&trk, &c), 0);
        assert_int_equal(c.kind, SC_CMD_SELECT_CASE);
        assert_int_equal(c.case_id, i);
    }
    sc_cmd c;
    assert_int_equal(sc_tracker_take_command(&trk, &c), SC_ERR_WOULD_BLOCK);
    assert_int_equal(sc_tracker_on_frame(&trk, &f[0], 20 * MS), SC_TRK_CMD_PENDING);
    assert_int_equal(sc_tracker_on_frame(&trk, &f[1], 20 * MS), SC_TRK_COMMAND);
    assert_int_equal(sc_tracker_take_command(&trk, &c), 0);
    assert_int_equal(c.kind, SC_CMD_SET_METHOD);
    assert_int_equal(c.method, SC_METHOD_FEM);
    /* a method value 3 from a foreign sender, correctly protected: refused before any MAC */
    f[0].data[2] = 3;
    sc_e2e_protect_with(SC_CANID_CMD_METHOD, 1, f[0].data, f[0].len);
    assert_int_equal(sc_tracker_on_frame(&trk, &f[0], 21 * MS), SC_TRK_CMD_REJECTED);
    assert_int_equal(sc_tracker_take_command(&trk, &c), SC_ERR_WOULD_BLOCK);
    assert_int_equal(sc_tracker_counters(&trk)->outcome[SC_TRK_CMD_QUEUE_FULL], 2);
    assert_int_equal(sc_tracker_counters(&trk)->outcome[SC_TRK_CMD_REJECTED], 1);
    assert_int_equal(sc_tracker_rejected_auth(&trk), 0);
}

static void error_frames_are_reported_to_health_and_foreign_frames_are_ignored(void **s)
{
    (void)s;
    sc_can_frame e = {.id = SC_CAN_ERRF_PASSIVE | SC_CAN_ERRF_CTRL, .flags = SC_CAN_FLAG_ERR};
    assert_int_equal(sc_tracker_on_frame(&trk, &e, 1), SC_TRK_BUS_ERROR);
    e.id = SC_CAN_ERRF_BUS_OFF;
    assert_int_equal(sc_tracker_on_frame(&trk, &e, 2), SC_TRK_BUS_ERROR);
    assert_int_equal(sc_tracker_take_bus_errors(&trk),
                     SC_CAN_ERRF_PASSIVE | SC_CAN_ERRF_CTRL | SC_CAN_ERRF_BUS_OFF);
    assert_int_equal(sc_tracker_take_bus_errors(&trk), 0);
    assert_int_equal(sc_tracker_counters(&trk)->bus_err_class[0], 1);
    assert_int_equal(sc_tracker_counters(&trk)->bus_err_class[1], 1);
    assert_int_equal(sc_tracker_counters(&trk)->bus_err_class[3], 1);

    sc_can_frame f = {.id = 0x555, .len = 8};
    assert_int_equal(sc_tracker_on_frame(&trk, &f, 3), SC_TRK_NOT_OURS);
    f.id = SC_CANID_STATUS; /* our own status looped back */
    assert_int_equal(sc_tracker_on_frame(&trk, &f, 3), SC_TRK_NOT_OURS);
    f.id = SC_CANID_POSE_POS;
    f.len = 6;
    assert_int_equal(sc_tracker_on_frame(&trk, &f, 3), SC_TRK_BAD_LENGTH);
    assert_int_equal(sc_tracker_counters(&trk)->frames, 5);
}

static void status_frames_carry_the_tracker_counters(void **s)
{
    (void)s;
    sc_pose_msg p = pose_at(0.0f, 0.0f, 0.0f);
    assert_int_equal(send_pose(&p, 0, 1 * MS, 1), SC_TRK_POSE_ACCEPTED);
    sc_pose_msg q = pose_at(1.0f, 0.0f, 0.0f); /* same counter, other data: repeated */
    assert_int_equal(send_pose(&q, 0, 11 * MS, 1), SC_TRK_E2E_REPEATED);
    assert_int_equal(send_pose(&q, 0, 12 * MS, 1), SC_TRK_E2E_REPEATED);
    sc_status_msg st = {
        .state = 1, .case_id = 3, .vein_area_ratio = 1.0f, .artery_area_ratio = 1.0f};
    sc_can_frame f[SC_STATUS_FRAMES];
    sc_status_tx stx;
    sc_status_tx_init(&stx);
    assert_int_equal(sc_status_tx_encode(&stx, &trk, &st, f), 0);
    sc_status_msg d = {0};
    for (int i = 0; i < (int)SC_STATUS_FRAMES; i++) {
        assert_int_equal(sc_canproto_decode_status_part(&f[i], &d), 0);
    }
    assert_int_equal(d.poses_accepted, 1);
    assert_int_equal(d.rejected_e2e, 2);
    assert_int_equal(d.auth_rejected, 0);
    assert_int_equal(d.probe_lifted, 0);
    assert_int_equal(d.case_id, 3);
}

static void invalid_definitions_are_refused(void **s)
{
    (void)s;
    sc_tracker_def d = sc_tracker_default_def();
    assert_int_equal(sc_tracker_def_validate(&d), 0);
    d.ws_min_mm[1] = d.ws_max_mm[1];
    assert_int_equal(sc_tracker_init(&trk, &d), SC_ERR_RANGE);
    d = sc_tracker_default_def();
    d.max_speed_mm_s = NAN;
    assert_int_equal(sc_tracker_def_validate(&d), SC_ERR_NOT_FINITE);
    d = sc_tracker_default_def();
    d.pose_timeout_ms = 5u;
    assert_int_equal(sc_tracker_def_validate(&d), SC_ERR_RANGE);
    d = sc_tracker_default_def();
    d.max_delta_counter = 15u;
    assert_int_equal(sc_tracker_def_validate(&d), SC_ERR_RANGE);
    d = sc_tracker_default_def();
    d.quat_norm_tol = 0.0f;
    assert_int_equal(sc_tracker_def_validate(&d), SC_ERR_RANGE);
    for (int o = 0; o < (int)SC_TRK_OUTCOME_COUNT; o++) {
        assert_string_not_equal(sc_trk_outcome_name((sc_trk_outcome)o), "?");
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(classic_pose_is_assembled_from_three_frames_and_normalised, setup),
        cmocka_unit_test_setup(parts_of_consecutive_samples_may_interleave, setup),
        cmocka_unit_test_setup(a_lost_part_drops_its_sample_and_is_counted, setup),
        cmocka_unit_test_setup(a_sample_completed_after_a_newer_one_is_stale_and_never_used, setup),
        cmocka_unit_test_setup(fd_pose_is_accepted_unless_disabled, setup),
        cmocka_unit_test_setup(every_e2e_fault_is_rejected_counted_and_never_used, setup),
        cmocka_unit_test_setup(every_plausibility_rejection_is_named_counted_and_never_used, setup),
        cmocka_unit_test_setup(a_fast_move_becomes_plausible_when_enough_time_passed, setup),
        cmocka_unit_test_setup(
            silence_past_the_timeout_lifts_the_probe_and_return_skips_the_speed_check, setup),
        cmocka_unit_test_setup(
            a_tracker_slower_than_the_frame_rate_never_stalls_and_gives_the_newest_pose, setup),
        cmocka_unit_test_setup(commands_are_queued_in_order_and_overflow_and_bad_values_are_counted,
                               setup),
        cmocka_unit_test_setup(error_frames_are_reported_to_health_and_foreign_frames_are_ignored,
                               setup),
        cmocka_unit_test_setup(status_frames_carry_the_tracker_counters, setup),
        cmocka_unit_test_setup(invalid_definitions_are_refused, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
