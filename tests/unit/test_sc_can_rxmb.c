/* test_sc_can_rxmb.c: the receive mailboxes (platform/linux/sc_can_rxmb.h): commands before
 * stream frames, order within each class, the newest stream frames kept when the ring is full,
 * a full command mailbox refusing the newest, and every frame accounted for
 * (put = taken + dropped + overwritten + waiting); the drain and the port device over a fake
 * transport. */
#include "sc_test.h"

#include <string.h>

#include "sc_can_rxmb.h"
#include "sc_config.h"
#include "sc_err.h"

static sc_can_rxmb mb;

static sc_can_frame frame(uint32_t id, uint8_t tag)
{
    sc_can_frame f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.len = 8;
    f.data[7] = tag;
    return f;
}

static void accounted(const sc_can_rxmb *m)
{
    const sc_can_rxmb_counters *c = &m->c;
    assert_int_equal(c->put, c->prio_taken + c->stream_taken + c->prio_dropped +
                                 c->stream_overwritten + sc_can_rxmb_depth(m));
}

static void init_refuses_a_stream_ring_of_zero_or_above_the_limit(void **state)
{
    (void)state;
    sc_can_rxmb_def d = sc_can_rxmb_default_def();
    assert_int_equal(d.stream_cap, SC_CAN_RX_BURST_MAX);
    d.stream_cap = 0;
    assert_int_equal(sc_can_rxmb_init(&mb, &d), SC_ERR_RANGE);
    d.stream_cap = SC_CAN_RXMB_STREAM_MAX + 1u;
    assert_int_equal(sc_can_rxmb_init(&mb, &d), SC_ERR_RANGE);
    d.stream_cap = SC_CAN_RXMB_STREAM_MAX;
    assert_int_equal(sc_can_rxmb_init(&mb, &d), SC_OK);
}

static void the_command_block_and_error_frames_are_priority_poses_are_not(void **state)
{
    (void)state;
    sc_can_frame f = frame(0x080, 0);
    assert_true(sc_can_rxmb_is_priority(&f));
    f.id = 0x09F;
    assert_true(sc_can_rxmb_is_priority(&f));
    f.id = 0x07F;
    assert_false(sc_can_rxmb_is_priority(&f));
    f.id = 0x0A0;
    assert_false(sc_can_rxmb_is_priority(&f));
    f.id = 0x100;
    assert_false(sc_can_rxmb_is_priority(&f));
    f.id = 0x084;
    f.flags = SC_CAN_FLAG_EXT; /* an extended id 0x084 is not the command block */
    assert_false(sc_can_rxmb_is_priority(&f));
    f.id = SC_CAN_ERRF_BUS_OFF;
    f.flags = SC_CAN_FLAG_ERR;
    assert_true(sc_can_rxmb_is_priority(&f));
}

static void a_command_behind_poses_is_taken_first_and_each_class_keeps_its_order(void **state)
{
    (void)state;
    const sc_can_rxmb_def d = sc_can_rxmb_default_def();
    assert_int_equal(sc_can_rxmb_init(&mb, &d), SC_OK);
    for (uint8_t i = 0; i < 30; i++) {
        const sc_can_frame p = frame(0x100u + i % 3u, i);
        assert_int_equal(sc_can_rxmb_put(&mb, &p), SC_OK);
    }
    const sc_can_frame sync = frame(0x084, 200), sync_mac = frame(0x08C, 201);
    const sc_can_frame cmd = frame(0x087, 202), cmd_mac = frame(0x08F, 203);
    assert_int_equal(sc_can_rxmb_put(&mb, &sync), SC_OK);
    assert_int_equal(sc_can_rxmb_put(&mb, &sync_mac), SC_OK);
    const sc_can_frame p30 = frame(0x100, 30);
    assert_int_equal(sc_can_rxmb_put(&mb, &p30), SC_OK);
    assert_int_equal(sc_can_rxmb_put(&mb, &cmd), SC_OK);
    assert_int_equal(sc_can_rxmb_put(&mb, &cmd_mac), SC_OK);
    assert_int_equal(sc_can_rxmb_depth(&mb), 35u);
    sc_can_frame out;
    /* the four command frames first, in their order */
    const uint8_t want[4] = {200, 201, 202, 203};
    for (int k = 0; k < 4; k++) {
        assert_int_equal(sc_can_rxmb_take(&mb, &out), SC_OK);
        assert_int_equal(out.data[7], want[k]);
    }
    /* then the 31 poses in their order */
    for (uint8_t i = 0; i <= 30; i++) {
        assert_int_equal(sc_can_rxmb_take(&mb, &out), SC_OK);
        assert_int_equal(out.data[7], i);
    }
    assert_int_equal(sc_can_rxmb_take(&mb, &out), SC_ERR_WOULD_BLOCK);
    assert_int_equal(mb.c.stream_overwritten, 0u);
    accounted(&mb);
}

static void a_full_stream_ring_keeps_the_newest_frames_and_counts_the_overwritten(void **state)
{
    (void)state;
    sc_can_rxmb_def d = sc_can_rxmb_default_def();
    d.stream_cap = 48;
    assert_int_equal(sc_can_rxmb_init(&mb, &d), SC_OK);
    for (uint32_t i = 0; i < 200; i++) {
        const sc_can_frame p = frame(0x100u + i % 3u, (uint8_t)i);
        assert_int_equal(sc_can_rxmb_put(&mb, &p), SC_OK);
    }
    assert_int_equal(mb.c.stream_overwritten, 200u - 48u);
    assert_int_equal(mb.c.stream_depth_max, 48u);
    accounted(&mb);
    sc_can_frame out;
    for (uint32_t i = 200u - 48u; i < 200u; i++) { /* the newest 48, oldest first */
        assert_int_equal(sc_can_rxmb_take(&mb, &out), SC_OK);
        assert_int_equal(out.data[7], (uint8_t)i);
        assert_int_equal(out.id, 0x100u + i % 3u);
    }
    assert_int_equal(sc_can_rxmb_take(&mb, &out), SC_ERR_WOULD_BLOCK);
    accounted(&mb);
}

static void a_full_command_mailbox_refuses_the_newest_and_never_overwrites(void **state)
{
    (void)state;
    const sc_can_rxmb_def d = sc_can_rxmb_default_def();
    assert_int_equal(sc_can_rxmb_init(&mb, &d), SC_OK);
    for (uint32_t i = 0; i < SC_CAN_RXMB_PRIO_MAX + 5u; i++) {
        const sc_can_frame c = frame(0x081, (uint8_t)i);
        assert_int_equal(sc_can_rxmb_put(&mb, &c),
                         i < SC_CAN_RXMB_PRIO_MAX ? SC_OK : SC_ERR_NO_SPACE);
    }
    assert_int_equal(mb.c.prio_dropped, 5u);
    accounted(&mb);
    sc_can_frame out;
    for (uint32_t i = 0; i < SC_CAN_RXMB_PRIO_MAX; i++) {
        assert_int_equal(sc_can_rxmb_take(&mb, &out), SC_OK);
        assert_int_equal(out.data[7], (uint8_t)i); /* the first ones, none replaced */
    }
    accounted(&mb);
}

/* a transport holding n frames: poses, with a command pair at position cmd_at */
typedef struct fake_src {
    uint32_t n, next, cmd_at;
} fake_src;

static int fake_recv(void *ctx, sc_can_frame *out)
{
    fake_src *s = ctx;
    if (s->next == s->n) {
        return SC_ERR_WOULD_BLOCK;
    }
    const uint32_t i = s->next++;
    *out = frame(i == s->cmd_at ? 0x083u : 0x100u + i % 3u, (uint8_t)i);
    return SC_OK;
}

static int fake_send(void *ctx, const sc_can_frame *f)
{
    (void)ctx;
    (void)f;
    return SC_OK;
}

static void the_drain_empties_the_transport_up_to_its_bound_and_stamps_the_frames(void **state)
{
    (void)state;
    static const sc_can_ops ops = {.send = fake_send, .recv = fake_recv};
    fake_src src = {.n = 300, .cmd_at = 250};
    const sc_can_dev dev = {.ops = &ops, .ctx = &src};
    const sc_can_rxmb_def d = sc_can_rxmb_default_def();
    assert_int_equal(sc_can_rxmb_init(&mb, &d), SC_OK);
    assert_int_equal(sc_can_rxmb_drain(&mb, &dev, 100, 12345u), 100u);
    assert_int_equal(sc_can_rxmb_drain(&mb, &dev, 1000, 12345u), 200u);
    assert_int_equal(sc_can_rxmb_drain(&mb, &dev, 1000, 12345u), 0u);
    sc_can_frame out;
    assert_int_equal(sc_can_rxmb_take(&mb, &out), SC_OK);
    assert_int_equal(out.id, 0x083u); /* the command, though 250 poses came before it */
    assert_int_equal(out.ts_ns, 12345u);
    assert_int_equal(mb.c.stream_overwritten, 299u - SC_CAN_RX_BURST_MAX);
    accounted(&mb);
}

static void the_port_device_takes_the_command_first_in_one_recv(void **state)
{
    (void)state;
    static const sc_can_ops ops = {.send = fake_send, .recv = fake_recv};
    fake_src src = {.n = 500, .cmd_at = 480};
    static sc_can_rxmb_port port;
    const sc_can_rxmb_def d = sc_can_rxmb_default_def();
    assert_int_equal(sc_can_rxmb_port_init(&port, &d, (sc_can_dev){.ops = &ops, .ctx = &src}, 0),
                     SC_ERR_INVALID_ARG);
    assert_int_equal(sc_can_rxmb_port_init(&port, &d, (sc_can_dev){.ops = &ops, .ctx = &src}, 4096),
                     SC_OK);
    const sc_can_dev dev = sc_can_rxmb_port_dev(&port);
    sc_can_frame out;
    assert_int_equal(sc_can_recv(&dev, &out), SC_OK);
    assert_int_equal(out.id, 0x083u);
    assert_int_equal(src.next, 500u); /* the transport drained whole */
    uint32_t poses = 0;
    uint8_t last = 0;
    while (sc_can_recv(&dev, &out) == SC_OK) {
        poses++;
        last = out.data[7];
    }
    assert_int_equal(poses, SC_CAN_RX_BURST_MAX);
    assert_int_equal(last, (uint8_t)499u); /* the newest pose frame is the last taken */
    assert_int_equal(sc_can_send(&dev, &out), SC_OK);
    sc_can_state st;
    assert_int_equal(sc_can_get_state(&dev, &st, NULL), SC_ERR_NOT_SUPPORTED);
    accounted(&port.mb);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(init_refuses_a_stream_ring_of_zero_or_above_the_limit),
        cmocka_unit_test(the_command_block_and_error_frames_are_priority_poses_are_not),
        cmocka_unit_test(a_command_behind_poses_is_taken_first_and_each_class_keeps_its_order),
        cmocka_unit_test(a_full_stream_ring_keeps_the_newest_frames_and_counts_the_overwritten),
        cmocka_unit_test(a_full_command_mailbox_refuses_the_newest_and_never_overwrites),
        cmocka_unit_test(the_drain_empties_the_transport_up_to_its_bound_and_stamps_the_frames),
        cmocka_unit_test(the_port_device_takes_the_command_first_in_one_recv),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
