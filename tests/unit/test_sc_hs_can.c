/* test_sc_hs_can.c: the host simulator's CAN bus: delivery, filters, bounded queues, and each
 * injected fault (drop, corrupt, duplicate, delay, reorder, bus-off) happening and counted. */
#include "sc_test.h"

#include <string.h>

#include "sc_err.h"
#include "sc_hs_can.h"
#include "sc_hs_can_tap.h"
#include "sc_hs_clock.h"

static sc_hs_clock clk;
static sc_clock_dev clk_dev;
static sc_hs_can_bus bus;
static sc_can_dev a, b, c;

static int setup(void **state)
{
    (void)state;
    sc_hs_clock_init(&clk, 0);
    clk_dev = sc_hs_clock_dev(&clk);
    sc_hs_can_bus_init(&bus, &clk_dev, 42u);
    assert_int_equal(sc_hs_can_add_node(&bus), 0);
    assert_int_equal(sc_hs_can_add_node(&bus), 1);
    assert_int_equal(sc_hs_can_add_node(&bus), 2);
    a = sc_hs_can_dev(&bus, 0);
    b = sc_hs_can_dev(&bus, 1);
    c = sc_hs_can_dev(&bus, 2);
    return 0;
}

static sc_can_frame mk(uint32_t id, uint8_t seq)
{
    sc_can_frame f = {.id = id, .len = 8};
    memset(f.data, seq, 8);
    return f;
}

static void frame_reaches_every_other_node_in_order(void **state)
{
    (void)state;
    for (uint8_t i = 0; i < 10; i++) {
        sc_can_frame f = mk(0x100, i);
        assert_int_equal(sc_can_send(&a, &f), SC_OK);
    }
    sc_can_frame r;
    for (uint8_t i = 0; i < 10; i++) {
        assert_int_equal(sc_can_recv(&b, &r), SC_OK);
        assert_int_equal(r.data[0], i);
        assert_int_equal(sc_can_recv(&c, &r), SC_OK);
        assert_int_equal(r.data[0], i);
    }
    assert_int_equal(sc_can_recv(&b, &r), SC_ERR_WOULD_BLOCK);
    assert_int_equal(sc_can_recv(&a, &r), SC_ERR_WOULD_BLOCK); /* no echo to the sender */
}

static void filters_select_ids_and_capacity_is_enforced(void **state)
{
    (void)state;
    sc_can_filter flt = {.id = 0x100, .mask = 0x7F0};
    assert_int_equal(sc_can_set_filters(&b, &flt, 1), SC_OK);
    sc_can_frame f1 = mk(0x105, 1), f2 = mk(0x200, 2);
    sc_can_send(&a, &f1);
    sc_can_send(&a, &f2);
    sc_can_frame r;
    assert_int_equal(sc_can_recv(&b, &r), SC_OK);
    assert_int_equal(r.id, 0x105);
    assert_int_equal(sc_can_recv(&b, &r), SC_ERR_WOULD_BLOCK);
    sc_can_filter many[SC_HS_CAN_MAX_FILTERS + 1u] = {0};
    assert_int_equal(sc_can_set_filters(&b, many, SC_HS_CAN_MAX_FILTERS + 1u), SC_ERR_NO_SPACE);
}

static void full_queue_drops_and_counts(void **state)
{
    (void)state;
    for (uint32_t i = 0; i < SC_HS_CAN_QUEUE + 10u; i++) {
        sc_can_frame f = mk(0x100, (uint8_t)i);
        sc_can_send(&a, &f);
    }
    assert_int_equal(bus.nodes[1].rx_overruns, 10);
    sc_can_counters cnt;
    sc_can_state st;
    assert_int_equal(sc_can_get_state(&b, &st, &cnt), SC_OK);
    assert_int_equal(cnt.rx_dropped, 10);
}

static void injected_faults_happen_at_their_rates_and_are_counted(void **state)
{
    (void)state;
    sc_hs_can_faults flt = {
        .drop_ppm = 100000u, .corrupt_ppm = 10000u, .duplicate_ppm = 10000u,
        .reorder_ppm = 10000u};
    sc_hs_can_set_faults(&bus, &flt);
    uint32_t got = 0, corrupt = 0, out_of_order = 0;
    int last = -1;
    for (uint32_t i = 0; i < 20000u; i++) {
        sc_can_frame f = mk(0x100, 0);
        f.data[0] = (uint8_t)(i & 0xFFu);
        f.data[1] = (uint8_t)(i >> 8);
        f.data[2] = (uint8_t)~f.data[0]; /* redundancy to detect corruption */
        f.data[3] = (uint8_t)~f.data[1];
        sc_can_send(&a, &f);
        sc_can_frame r;
        while (sc_can_recv(&b, &r) == SC_OK) {
            got++;
            if (r.data[0] + r.data[2] != 255 || r.data[1] + r.data[3] != 255 ||
                r.data[4] | r.data[5] | r.data[6] | r.data[7]) {
                corrupt++;
                continue;
            }
            int seq = r.data[0] | (r.data[1] << 8);
            if (seq < last) {
                out_of_order++;
            }
            last = seq;
        }
    }
    sc_hs_can_flush(&bus);
    const sc_hs_can_injected *inj = &bus.injected;
    assert_int_equal(inj->sent, 20000);
    /* 10% drops: 2000 expected; binomial sd ~ 42, allow 5 sd */
    assert_in_range(inj->dropped, 1790, 2210);
    assert_in_range(inj->corrupted, 100, 300);
    assert_in_range(inj->duplicated, 100, 300);
    assert_in_range(inj->reordered, 100, 300);
    /* every corrupted frame was seen as corrupt (a single bit flip always breaks the check);
     * a corrupted frame that was also duplicated is seen twice */
    assert_true(corrupt >= inj->corrupted);
    assert_true(corrupt <= inj->corrupted + inj->duplicated);
    assert_true(out_of_order > 0u);
    /* receiver got sent - dropped + duplicated, minus the reordered frame still held (flushed
     * after the loop, not read) */
    assert_true(got + 1u >= inj->sent - inj->dropped + inj->duplicated);
}

static void delay_holds_frames_until_virtual_time_passes(void **state)
{
    (void)state;
    sc_hs_can_faults flt = {.delay_ns = 5000000u};
    sc_hs_can_set_faults(&bus, &flt);
    sc_can_frame f = mk(0x100, 7), r;
    sc_can_send(&a, &f);
    assert_int_equal(sc_can_recv(&b, &r), SC_ERR_WOULD_BLOCK);
    sc_hs_clock_advance_ns(&clk, 4999999u);
    assert_int_equal(sc_can_recv(&b, &r), SC_ERR_WOULD_BLOCK);
    sc_hs_clock_advance_ns(&clk, 1u);
    assert_int_equal(sc_can_recv(&b, &r), SC_OK);
    assert_int_equal(r.ts_ns, 5000000u);
}

static void bus_off_refuses_sends_and_reports_error_frames(void **state)
{
    (void)state;
    sc_hs_can_set_bus_off(&bus, 1);
    sc_can_frame f = mk(0x100, 1), r;
    assert_int_equal(sc_can_send(&a, &f), SC_ERR_CAN_BUS_OFF);
    assert_int_equal(sc_can_recv(&b, &r), SC_OK);
    assert_true(r.flags & SC_CAN_FLAG_ERR);
    assert_true(r.id & SC_CAN_ERRF_BUS_OFF);
    sc_can_state st;
    assert_int_equal(sc_can_get_state(&b, &st, NULL), SC_OK);
    assert_int_equal(st, SC_CAN_STATE_BUS_OFF);
    sc_hs_can_set_bus_off(&bus, 0);
    assert_int_equal(sc_can_recv(&b, &r), SC_OK);
    assert_true(r.id & SC_CAN_ERRF_RESTARTED);
    assert_int_equal(sc_can_send(&a, &f), SC_OK);
}

static void invalid_lengths_are_refused(void **state)
{
    (void)state;
    sc_can_frame f = mk(0x100, 1);
    f.len = 9;
    assert_int_equal(sc_can_send(&a, &f), SC_ERR_INVALID_ARG);
    f.flags = SC_CAN_FLAG_FD;
    f.len = 13;
    assert_int_equal(sc_can_send(&a, &f), SC_ERR_INVALID_ARG);
    f.len = 12;
    assert_int_equal(sc_can_send(&a, &f), SC_OK);
}

static uint32_t tapped;
static uint64_t tapped_ts;

static void on_tap(void *user, const sc_can_frame *f)
{
    (void)user;
    tapped++;
    tapped_ts = f->ts_ns;
}

static void tap_stamps_receive_time_and_reports_each_frame(void **state)
{
    (void)state;
    sc_hs_can_tap tap;
    tapped = 0;
    sc_hs_can_tap_init(&tap, b, &clk_dev, on_tap, NULL);
    sc_can_dev t = sc_hs_can_tap_dev(&tap);
    sc_can_frame f = mk(0x100, 3), r;
    sc_can_send(&a, &f); /* stamped 0 by the bus */
    sc_hs_clock_advance_ns(&clk, 123456u);
    assert_int_equal(sc_can_recv(&t, &r), SC_OK);
    assert_int_equal(r.ts_ns, 123456u); /* the tap's stamp: time of reception */
    assert_int_equal(tapped, 1);
    assert_int_equal(tapped_ts, 123456u);
    assert_int_equal(sc_can_recv(&t, &r), SC_ERR_WOULD_BLOCK);
    assert_int_equal(tapped, 1);
    /* sends pass through */
    assert_int_equal(sc_can_send(&t, &f), SC_OK);
    assert_int_equal(sc_can_recv(&a, &r), SC_OK);
}

static void inject_bypasses_faults_and_is_bounded(void **state)
{
    (void)state;
    sc_hs_can_faults flt = {.drop_ppm = 1000000u};
    sc_hs_can_set_faults(&bus, &flt);
    sc_can_frame f = mk(0x100, 9), r;
    assert_int_equal(sc_hs_can_inject(&bus, 1, &f), SC_OK);
    assert_int_equal(sc_can_recv(&b, &r), SC_OK);
    assert_int_equal(r.data[0], 9);
    for (uint32_t i = 0; i < SC_HS_CAN_QUEUE; i++) {
        assert_int_equal(sc_hs_can_inject(&bus, 1, &f), SC_OK);
    }
    assert_int_equal(sc_hs_can_inject(&bus, 1, &f), SC_ERR_NO_SPACE);
    assert_int_equal(sc_hs_can_inject(&bus, 7, &f), SC_ERR_INVALID_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(frame_reaches_every_other_node_in_order, setup),
        cmocka_unit_test_setup(filters_select_ids_and_capacity_is_enforced, setup),
        cmocka_unit_test_setup(full_queue_drops_and_counts, setup),
        cmocka_unit_test_setup(injected_faults_happen_at_their_rates_and_are_counted, setup),
        cmocka_unit_test_setup(delay_holds_frames_until_virtual_time_passes, setup),
        cmocka_unit_test_setup(bus_off_refuses_sends_and_reports_error_frames, setup),
        cmocka_unit_test_setup(invalid_lengths_are_refused, setup),
        cmocka_unit_test_setup(tap_stamps_receive_time_and_reports_each_frame, setup),
        cmocka_unit_test_setup(inject_bypasses_faults_and_is_bounded, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
