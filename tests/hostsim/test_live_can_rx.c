/*
 * test_live_can_rx.c: commands over CAN over UDP reach the live engine (sc-hostsim --live's
 * path, platform/hostsim/sc_hs_live.h) ahead of a 100 Hz tracker, on the virtual clock:
 *   - steady: the tracker emulator's samples due before each frame and a signed command every
 *     30 frames go into the engine's UDP socket; each command is applied in the frame it was
 *     sent before, every pose is accepted, nothing is overwritten or lost;
 *   - a stalled host: 0.6 s of tracker samples (180 frames) pile up in the socket with a
 *     command behind the first 150 of them (the console's command while the engine's process
 *     was not running); the next frame drains the socket whole, applies the command (a FIFO
 *     drained 64 frames a frame applied it three frames later), and takes the newest pose:
 *     the engine's current sample is the last one sent; the pose frames the mailboxes
 *     overwrote are counted (and the E2E receivers count the gap), and every datagram is
 *     accounted for (taken + overwritten).
 * Real loopback UDP sockets (delivered within send), the engine on the rig's virtual clock.
 */
#define _GNU_SOURCE /* sc_hs_live.h reaches sc_udp_display.h (struct mmsghdr) */
#include "sc_test.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "sc_canproto.h"
#include "sc_err.h"
#include "sc_hs_live.h"
#include "sc_test_block_rig.h"
#include "sc_test_case.h"
#include "sc_test_cmd.h"
#include "sc_trkemu.h"
#include "sc_udpcan.h"

static sc_hs_rig rig;
static sc_hs_live live;
static sc_emu emu;
static sc_udpcan tx;

/* a free loopback UDP port (bound and released: the live layer binds it next) */
static uint16_t free_udp_port(void)
{
    const int fd = socket(AF_INET, SOCK_DGRAM, 0);
    assert_true(fd >= 0);
    struct sockaddr_in a = {.sin_family = AF_INET};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof a), 0);
    socklen_t len = sizeof a;
    assert_int_equal(getsockname(fd, (struct sockaddr *)&a, &len), 0);
    close(fd);
    return ntohs(a.sin_port);
}

static uint64_t applied(void)
{
    return sc_engine_get_counters(&rig.engine)->commands_applied;
}

/* one tracker sample into the socket; its E2E counter */
static uint8_t send_sample(const sc_can_dev *dev)
{
    sc_can_frame f[SC_EMU_MAX_FRAMES];
    uint64_t t;
    const int k = sc_emu_next(&emu, f, SC_EMU_MAX_FRAMES, &t);
    assert_int_equal(k, 3); /* a classic pose: three frames, one counter */
    for (int j = 0; j < k; j++) {
        assert_int_equal(sc_can_send(dev, &f[j]), SC_OK);
    }
    return (uint8_t)(f[0].data[1] & 0x0Fu);
}

static const sc_cmd k_reset = {.kind = SC_CMD_ASSESS,
                               .assess_action = SC_ASSESS_ACTION_RESET,
                               .assess_call = SC_ASSESS_CALL_NONE};

static void a_command_is_applied_in_the_next_frame_however_many_poses_wait(void **state)
{
    (void)state;
    sc_test_block_rig_up(&rig, &sc_test_block, 5, 0);
    const sc_emu_def pd = sc_test_block_probe_def(&sc_test_block, 1.0f, 0.0f); /* 100 Hz */
    assert_int_equal(sc_emu_init(&emu, &pd), SC_OK);
    const uint16_t port = free_udp_port();
    const sc_hs_live_def ld = {.pace = 0, .can_port = port};
    char err[256];
    assert_int_equal(sc_hs_live_open(&live, &ld, &rig, err, sizeof err), SC_OK);
    assert_int_equal(sc_udpcan_open_tx(&tx, "127.0.0.1", port), SC_OK);
    const sc_can_dev dev = sc_udpcan_dev(&tx);

    /* steady: 100 Hz samples as they fall due on the virtual clock, a command every 30 frames */
    const uint64_t t0 = rig.clock.now_ns;
    uint64_t next = 0, samples = 0, commands = 0;
    for (uint32_t i = 0; i < 180; i++) {
        const uint64_t release = sc_engine_next_release_ns(&rig.engine);
        while (t0 + next <= release) {
            (void)send_sample(&dev);
            samples++;
            next = sc_emu_next_time_ns(&emu);
        }
        if (i % 30u == 10u) {
            assert_int_equal(sc_test_send_cmd(&dev, &k_reset), SC_OK);
            commands++;
        }
        const uint64_t before = applied();
        sc_hs_live_before_frame(&live, &rig, release);
        sc_engine_step(&rig.engine, NULL);
        assert_int_equal(applied() - before, i % 30u == 10u ? 1u : 0u);
    }
    const sc_trk_counters *tc = sc_tracker_counters(&rig.engine.tracker);
    print_message("steady: %llu samples, %llu commands; poses accepted %u, overwritten %llu\n",
                  (unsigned long long)samples, (unsigned long long)commands,
                  tc->outcome[SC_TRK_POSE_ACCEPTED],
                  (unsigned long long)live.rxmb.c.stream_overwritten);
    assert_int_equal(live.rxmb.c.stream_overwritten, 0u);
    assert_int_equal(live.rxmb.c.prio_dropped, 0u);
    assert_int_equal(live.rxmb.c.put, 3u * samples + 4u * commands);
    assert_int_equal(tc->outcome[SC_TRK_POSE_ACCEPTED], samples);
    assert_int_equal(sc_tracker_rejected_e2e(&rig.engine.tracker), 0u);
    assert_int_equal(applied(), commands);

    /* a stalled host: 60 samples (180 frames) wait in the socket, the command behind 50 */
    const uint64_t put0 = live.rxmb.c.put, taken0 = live.rxmb.c.stream_taken;
    const uint32_t frames0 = tc->frames;
    uint8_t last_counter = 0;
    for (int s = 0; s < 60; s++) {
        last_counter = send_sample(&dev);
        if (s == 49) {
            assert_int_equal(sc_test_send_cmd(&dev, &k_reset), SC_OK);
        }
    }
    const uint64_t before = applied();
    uint64_t release = sc_engine_next_release_ns(&rig.engine);
    sc_hs_live_before_frame(&live, &rig, release);
    sc_engine_step(&rig.engine, NULL);
    assert_int_equal(applied() - before, 1u);       /* the command: in the next frame */
    assert_int_equal(live.rxmb.c.put - put0, 184u); /* the socket drained whole */
    /* the newest pose frames win: 64 taken this frame (4 of them the command's), 116 older
     * ones overwritten, the 4 left taken the frame after */
    assert_int_equal(live.rxmb.c.stream_overwritten, 180u - SC_CAN_RX_BURST_MAX);
    release = sc_engine_next_release_ns(&rig.engine);
    sc_hs_live_before_frame(&live, &rig, release);
    sc_engine_step(&rig.engine, NULL);
    assert_int_equal(live.rxmb.c.stream_taken - taken0, SC_CAN_RX_BURST_MAX);
    assert_int_equal(sc_can_rxmb_depth(&live.rxmb), 0u);
    assert_int_equal(tc->frames - frames0, SC_CAN_RX_BURST_MAX + 4u); /* all the engine got */
    const sc_trk_sample *cur = sc_tracker_sample(&rig.engine.tracker);
    assert_non_null(cur);
    print_message("stalled: command applied in the next frame; %llu pose frames overwritten, "
                  "current sample counter %u (last sent %u), E2E rejects %u, incomplete %u\n",
                  (unsigned long long)live.rxmb.c.stream_overwritten, cur->counter, last_counter,
                  sc_tracker_rejected_e2e(&rig.engine.tracker), tc->incomplete);
    assert_int_equal(cur->counter, last_counter); /* the newest sample is the engine's pose */
    /* the gap the overwritten frames left, counted as on a bus that lost them: each pose
     * message's E2E receiver (0x100, 0x101, 0x102) refuses the first frame after its counter
     * jumped (at most 3), at most one partial sample */
    assert_true(sc_tracker_rejected_e2e(&rig.engine.tracker) <= 3u);
    assert_true(tc->incomplete <= 1u);
    sc_udpcan_close(&tx);
    sc_hs_live_close(&live);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_command_is_applied_in_the_next_frame_however_many_poses_wait),
    };
    return cmocka_run_group_tests(tests, sc_test_block_group_setup, sc_test_block_group_teardown);
}
