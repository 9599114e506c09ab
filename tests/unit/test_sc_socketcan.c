/* test_sc_socketcan.c: the SocketCAN node's logic over a fake syscall adapter (this host's
 * kernel has no CAN): frame conversion both ways, error frames -> classes and bus state,
 * kernel filters, FD gating, drop counting, bus-off refusal, and the conversion of the kernel's
 * REALTIME stamps to the MONOTONIC base (order kept, steps found), and the node behind the
 * receive mailboxes as sonocomp runs it (a command queued behind a stall's pose frames comes
 * first, the newest poses win, everything counted). The real adapter runs in the VM. */
#include "sc_test.h"

#include <string.h>

#include <linux/can.h>
#include <linux/can/error.h>

#include "sc_can_rxmb.h"
#include "sc_err.h"
#include "sc_socketcan.h"

#define FAKE_RXQ 320 /* a stall's worth of queued tracker frames */

typedef struct fake {
    int open_rc;
    int fd_capable;
    sc_socketcan_raw rxq[FAKE_RXQ];
    int rx_fd[FAKE_RXQ];
    uint64_t rx_ts[FAKE_RXQ];
    uint32_t rx_drops[FAKE_RXQ];
    int rx_n, rx_i;
    sc_socketcan_raw tx[8];
    int tx_fd[8];
    int tx_n;
    int send_rc;
    sc_socketcan_rawfilter filt[SC_CAN_MAX_FILTERS];
    size_t filt_n;
    int closed;
    /* clocks: MONOTONIC advances 1 us between readings; REALTIME (= MONOTONIC +
     * real_minus_mono_ns) is read 100 ns after the first MONOTONIC read, the second MONOTONIC
     * read follows after gap_ns[reading] (0 -> 100 ns): a preemption there */
    uint64_t mono_ns;
    int64_t real_minus_mono_ns;
    uint64_t gap_ns[16];
    int readings;
    int clocks_rc;
} fake;

static int f_open(void *u, const char *ifname, int *fd_capable)
{
    fake *f = u;
    (void)ifname;
    *fd_capable = f->fd_capable;
    return f->open_rc;
}
static int f_set_filters(void *u, int h, const sc_socketcan_rawfilter *fl, size_t n)
{
    fake *f = u;
    (void)h;
    memcpy(f->filt, fl, n * sizeof *fl);
    f->filt_n = n;
    return 0;
}
static int f_recv(void *u, int h, sc_socketcan_raw *out, int *is_fd, uint64_t *ts, uint32_t *drops)
{
    fake *f = u;
    (void)h;
    if (f->rx_i >= f->rx_n) {
        return 0;
    }
    *out = f->rxq[f->rx_i];
    *is_fd = f->rx_fd[f->rx_i];
    *ts = f->rx_ts[f->rx_i];
    if (f->rx_drops[f->rx_i]) {
        *drops = f->rx_drops[f->rx_i];
    }
    f->rx_i++;
    return 1;
}
static int f_send(void *u, int h, const sc_socketcan_raw *fr, int is_fd)
{
    fake *f = u;
    (void)h;
    if (f->send_rc) {
        return f->send_rc;
    }
    f->tx[f->tx_n] = *fr;
    f->tx_fd[f->tx_n++] = is_fd;
    return 0;
}
static void f_close(void *u, int h)
{
    (void)h;
    ((fake *)u)->closed = 1;
}
static int f_read_clocks(void *u, sc_socketcan_clocks *c)
{
    fake *f = u;
    if (f->clocks_rc) {
        return f->clocks_rc;
    }
    const int i = f->readings++;
    const uint64_t gap = i < 16 && f->gap_ns[i] ? f->gap_ns[i] : 100u;
    f->mono_ns += 1000u;
    c->mono_before_ns = f->mono_ns;
    c->real_ns = (uint64_t)((int64_t)(f->mono_ns + 100u) + f->real_minus_mono_ns);
    c->mono_after_ns = f->mono_ns + 100u + gap;
    f->mono_ns = c->mono_after_ns;
    return 0;
}
static const sc_socketcan_sys fake_sys = {f_open, f_set_filters, f_recv,
                                          f_send, f_close,       f_read_clocks};

static void push_rx(fake *f, uint32_t can_id, uint8_t len, int is_fd, uint64_t ts, uint32_t drops)
{
    sc_socketcan_raw r = {.can_id = can_id, .len = len};
    for (int i = 0; i < len; i++) {
        r.data[i] = (uint8_t)(0x10 + i);
    }
    f->rxq[f->rx_n] = r;
    f->rx_fd[f->rx_n] = is_fd;
    f->rx_ts[f->rx_n] = ts;
    f->rx_drops[f->rx_n] = drops;
    f->rx_n++;
}

static void frames_error_frames_and_drops_are_received_with_state_and_time(void **state)
{
    (void)state;
    fake fk = {.open_rc = 5, .fd_capable = 1};
    sc_socketcan s;
    assert_int_equal(sc_socketcan_open(&s, &fake_sys, &fk, "vcan0"), 0);
    sc_can_dev dev = sc_socketcan_dev(&s);
    push_rx(&fk, 0x100, 8, 0, 111, 0);
    push_rx(&fk, 0x1ABCDEF0 | CAN_EFF_FLAG, 3, 0, 112, 0);
    push_rx(&fk, 0x110, 20, 1, 113, 4); /* the kernel dropped 4 frames before this one */
    sc_socketcan_raw e = {.can_id = CAN_ERR_FLAG | CAN_ERR_CRTL | CAN_ERR_CNT, .len = 8};
    e.data[1] = CAN_ERR_CRTL_RX_PASSIVE;
    e.data[6] = 130;
    e.data[7] = 140;
    fk.rxq[fk.rx_n] = e;
    fk.rx_ts[fk.rx_n++] = 114;
    push_rx(&fk, CAN_ERR_FLAG | CAN_ERR_BUSOFF, 8, 0, 115, 0);
    push_rx(&fk, 0x123, 9, 0, 116, 0); /* unrepresentable: skipped and counted */

    sc_can_frame fr;
    assert_int_equal(sc_can_recv(&dev, &fr), 0);
    assert_int_equal(fr.id, 0x100);
    assert_int_equal(fr.flags, 0);
    assert_int_equal(fr.ts_ns, 111);
    assert_int_equal(fr.data[7], 0x17);
    assert_int_equal(sc_can_recv(&dev, &fr), 0);
    assert_int_equal(fr.id, 0x1ABCDEF0);
    assert_int_equal(fr.flags, SC_CAN_FLAG_EXT);
    assert_int_equal(sc_can_recv(&dev, &fr), 0);
    assert_int_equal(fr.flags & SC_CAN_FLAG_FD, SC_CAN_FLAG_FD);
    assert_int_equal(fr.len, 20);
    sc_can_state st;
    sc_can_counters cnt;
    assert_int_equal(sc_can_get_state(&dev, &st, &cnt), 0);
    assert_int_equal(cnt.rx_dropped, 4);
    assert_int_equal(st, SC_CAN_STATE_ERROR_ACTIVE);
    assert_int_equal(sc_can_recv(&dev, &fr), 0);
    assert_int_equal(fr.flags, SC_CAN_FLAG_ERR);
    assert_int_equal(fr.id, SC_CAN_ERRF_PASSIVE);
    assert_int_equal(sc_can_get_state(&dev, &st, &cnt), 0);
    assert_int_equal(st, SC_CAN_STATE_ERROR_PASSIVE);
    assert_int_equal(cnt.tx_err, 130);
    assert_int_equal(cnt.rx_err, 140);
    assert_int_equal(sc_can_recv(&dev, &fr), 0);
    assert_int_equal(fr.id, SC_CAN_ERRF_BUS_OFF);
    assert_int_equal(sc_can_get_state(&dev, &st, NULL), 0);
    assert_int_equal(st, SC_CAN_STATE_BUS_OFF);
    assert_int_equal(sc_can_recv(&dev, &fr), SC_ERR_WOULD_BLOCK);
    assert_int_equal(s.rx_unconvertible, 1);
    /* bus-off: sending is refused and counted */
    sc_can_frame tx = {.id = 0x200, .len = 8};
    assert_int_equal(sc_can_send(&dev, &tx), SC_ERR_CAN_BUS_OFF);
    assert_int_equal(sc_can_get_state(&dev, NULL, &cnt), 0);
    assert_int_equal(cnt.tx_dropped, 1);
    sc_socketcan_close(&s);
    assert_int_equal(fk.closed, 1);
}

static void sending_converts_frames_and_gates_fd_on_the_interface(void **state)
{
    (void)state;
    fake fk = {.open_rc = 3, .fd_capable = 0};
    sc_socketcan s;
    assert_int_equal(sc_socketcan_open(&s, &fake_sys, &fk, "can0"), 0);
    sc_can_dev dev = sc_socketcan_dev(&s);
    sc_can_frame f = {.id = 0x100, .len = 8, .data = {1, 2, 3, 4, 5, 6, 7, 8}};
    assert_int_equal(sc_can_send(&dev, &f), 0);
    assert_int_equal(fk.tx[0].can_id, 0x100);
    assert_int_equal(fk.tx_fd[0], 0);
    assert_memory_equal(fk.tx[0].data, f.data, 8);
    f = (sc_can_frame){.id = 0x110, .len = 20, .flags = SC_CAN_FLAG_FD | SC_CAN_FLAG_BRS};
    assert_int_equal(sc_can_send(&dev, &f), SC_ERR_NOT_SUPPORTED); /* classic interface */
    f = (sc_can_frame){.id = 0x100, .len = 9};
    assert_int_equal(sc_can_send(&dev, &f), SC_ERR_INVALID_ARG);
    f = (sc_can_frame){.id = 0x800, .len = 1};
    assert_int_equal(sc_can_send(&dev, &f), SC_ERR_INVALID_ARG);
    f = (sc_can_frame){.id = 1, .flags = SC_CAN_FLAG_ERR};
    assert_int_equal(sc_can_send(&dev, &f), SC_ERR_INVALID_ARG);
    fk.send_rc = SC_ERR_WOULD_BLOCK;
    f = (sc_can_frame){.id = 0x1FFFFFFF, .len = 0, .flags = SC_CAN_FLAG_EXT | SC_CAN_FLAG_RTR};
    assert_int_equal(sc_can_send(&dev, &f), SC_ERR_WOULD_BLOCK);
    fk.send_rc = 0;
    assert_int_equal(sc_can_send(&dev, &f), 0);
    assert_int_equal(fk.tx[1].can_id, 0x1FFFFFFFu | CAN_EFF_FLAG | CAN_RTR_FLAG);

    fake fd = {.open_rc = 4, .fd_capable = 1};
    assert_int_equal(sc_socketcan_open(&s, &fake_sys, &fd, "vcan0"), 0);
    dev = sc_socketcan_dev(&s);
    f = (sc_can_frame){.id = 0x110, .len = 20, .flags = SC_CAN_FLAG_FD | SC_CAN_FLAG_BRS};
    assert_int_equal(sc_can_send(&dev, &f), 0);
    assert_int_equal(fd.tx_fd[0], 1);
    assert_int_equal(fd.tx[0].flags, CANFD_BRS);
    assert_int_equal(fd.tx[0].len, 20);

    fake bad = {.open_rc = SC_ERR_IO};
    assert_int_equal(sc_socketcan_open(&s, &fake_sys, &bad, "nocan0"), SC_ERR_IO);
    assert_int_equal(sc_socketcan_open(&s, &fake_sys, &fd, "a_name_that_is_too_long"),
                     SC_ERR_INVALID_ARG);
    assert_int_equal(sc_socketcan_open(&s, &fake_sys, &fd, ""), SC_ERR_INVALID_ARG);
}

static void filters_become_kernel_filters_that_separate_standard_and_extended(void **state)
{
    (void)state;
    fake fk = {.open_rc = 3};
    sc_socketcan s;
    assert_int_equal(sc_socketcan_open(&s, &fake_sys, &fk, "vcan0"), 0);
    sc_can_dev dev = sc_socketcan_dev(&s);
    const sc_can_filter fl[2] = {{.id = 0x100, .mask = 0x7F0},
                                 {.id = 0x18DA00F1, .mask = 0x1FFFFFFF, .flags = SC_CAN_FLAG_EXT}};
    assert_int_equal(sc_can_set_filters(&dev, fl, 2), 0);
    assert_int_equal(fk.filt_n, 2);
    assert_int_equal(fk.filt[0].can_id, 0x100);
    assert_int_equal(fk.filt[0].can_mask, 0x7F0u | CAN_EFF_FLAG | CAN_RTR_FLAG);
    assert_int_equal(fk.filt[1].can_id, 0x18DA00F1u | CAN_EFF_FLAG);
    assert_int_equal(fk.filt[1].can_mask, 0x1FFFFFFFu | CAN_EFF_FLAG | CAN_RTR_FLAG);
    assert_int_equal(sc_can_set_filters(&dev, NULL, 0), 0); /* accept all */
    assert_int_equal(fk.filt_n, 1);
    assert_int_equal(fk.filt[0].can_mask, 0);
    sc_can_filter many[SC_CAN_MAX_FILTERS + 1];
    memset(many, 0, sizeof many);
    assert_int_equal(sc_can_set_filters(&dev, many, SC_CAN_MAX_FILTERS + 1), SC_ERR_NO_SPACE);
}

static void error_classes_survive_linux_form_and_back(void **state)
{
    (void)state;
    for (uint32_t e = 0; e < 64u; e++) {
        sc_can_frame f = {.id = e, .flags = SC_CAN_FLAG_ERR, .len = 8};
        sc_socketcan_raw r;
        int is_fd;
        assert_int_equal(sc_socketcan_to_raw(&f, &r, &is_fd), 0);
        assert_true(r.can_id & CAN_ERR_FLAG);
        assert_int_equal(sc_socketcan_errf_from_linux(r.can_id, r.data), e);
    }
    const uint8_t z[8] = {0};
    assert_int_equal(sc_socketcan_errf_from_linux(CAN_ERR_PROT | CAN_ERR_ACK, z),
                     SC_CAN_ERRF_PROTOCOL);
    assert_int_equal(sc_socketcan_errf_from_linux(CAN_ERR_CRTL, z), SC_CAN_ERRF_CTRL);
    assert_int_equal(sc_socketcan_errf_from_linux(CAN_ERR_TX_TIMEOUT, z), SC_CAN_ERRF_CTRL);
}

/* the REALTIME epoch of a 2026 clock, in ns: the offset the conversion has to remove */
#define REAL_MINUS_MONO_NS 1795000000000000000LL

static void tsconv_estimate_takes_the_narrowest_bracket_midpoint(void **state)
{
    (void)state;
    const sc_socketcan_clocks r[4] = {
        {.mono_before_ns = 1000, .real_ns = 500000, .mono_after_ns = 6000},   /* 5 us wide */
        {.mono_before_ns = 9000, .real_ns = 508100, .mono_after_ns = 9300},   /* 300 ns */
        {.mono_before_ns = 20000, .real_ns = 519000, .mono_after_ns = 90000}, /* 70 us */
        {.mono_before_ns = 95000, .real_ns = 594000, .mono_after_ns = 94000}, /* runs backwards */
    };
    sc_socketcan_tsconv c = {0};
    assert_int_equal(sc_socketcan_tsconv_estimate(&c, r, 4), 0);
    assert_true(c.valid);
    assert_int_equal(c.offset_ns, 9150 - 508100);
    assert_int_equal(c.uncertainty_ns, 150);
    /* nothing usable: an error, and the held estimate stays */
    assert_int_equal(sc_socketcan_tsconv_estimate(&c, &r[3], 1), SC_ERR_INVALID_ARG);
    assert_int_equal(c.offset_ns, 9150 - 508100);
}

static void tsconv_conversion_keeps_the_order_of_ordered_stamps(void **state)
{
    (void)state;
    const int64_t offsets[] = {-REAL_MINUS_MONO_NS, -1000, 0, 123456789};
    for (size_t k = 0; k < sizeof offsets / sizeof offsets[0]; k++) {
        const sc_socketcan_tsconv c = {.offset_ns = offsets[k], .valid = 1};
        uint64_t prev = 0;
        uint64_t real = (uint64_t)REAL_MINUS_MONO_NS + 5000000000u;
        for (int i = 0; i < 1000; i++) {
            real += (uint64_t)(i % 7) * 13u; /* ties and small steps: back-to-back frames */
            const uint64_t mono = sc_socketcan_tsconv_to_mono(&c, real);
            assert_true(mono >= prev);
            assert_true(mono > 0u);
            prev = mono;
        }
    }
    const sc_socketcan_tsconv c = {.offset_ns = -REAL_MINUS_MONO_NS, .valid = 1};
    assert_int_equal(sc_socketcan_tsconv_to_mono(&c, 0), 0);           /* no stamp */
    assert_int_equal(sc_socketcan_tsconv_to_mono(&c, 1000000000u), 0); /* before boot */
    const sc_socketcan_tsconv none = {0};
    assert_int_equal(sc_socketcan_tsconv_to_mono(&none, 1000000000u), 0);
}

static void tsconv_finds_realtime_steps_but_not_in_delayed_readings(void **state)
{
    (void)state;
    const sc_socketcan_clocks est = {
        .mono_before_ns = 1000, .real_ns = 2000, .mono_after_ns = 1200};
    sc_socketcan_tsconv c = {0};
    assert_int_equal(sc_socketcan_tsconv_estimate(&c, &est, 1), 0);
    assert_int_equal(c.offset_ns, -900); /* true offset in [-1000, -800] */
    /* consistent readings, narrow or 1 ms wide (preempted anywhere): no step */
    const sc_socketcan_clocks ok[] = {
        {.mono_before_ns = 50000, .real_ns = 50900, .mono_after_ns = 50950},
        {.mono_before_ns = 60000, .real_ns = 60800, .mono_after_ns = 1060000},
        {.mono_before_ns = 70000, .real_ns = 1070800, .mono_after_ns = 1070900},
    };
    for (size_t i = 0; i < 3; i++) {
        assert_int_equal(sc_socketcan_tsconv_stepped(&c, &ok[i]), 0);
    }
    /* REALTIME stepped 5 us forward, or back: no bracket can explain it */
    const sc_socketcan_clocks fwd = {
        .mono_before_ns = 80000, .real_ns = 85900, .mono_after_ns = 81000};
    const sc_socketcan_clocks back = {
        .mono_before_ns = 90000, .real_ns = 85900, .mono_after_ns = 90100};
    assert_int_equal(sc_socketcan_tsconv_stepped(&c, &fwd), 1);
    assert_int_equal(sc_socketcan_tsconv_stepped(&c, &back), 1);
    const sc_socketcan_tsconv none = {0};
    assert_int_equal(sc_socketcan_tsconv_stepped(&none, &fwd), 0);
}

/* Issue #19 as measured in the HIL VM: the clock reading at one frame was preempted for
 * 138.8 us between its REALTIME and MONOTONIC reads, the next frame's took 250 ns, and the two
 * frames were stamped 96.2 us apart. An offset per frame from those reads put them 42 us out of
 * order; the held offset keeps their order and their distance. */
static void kernel_stamps_keep_order_and_distance_when_a_clock_reading_is_preempted(void **state)
{
    (void)state;
    fake fk = {.open_rc = 3, .real_minus_mono_ns = REAL_MINUS_MONO_NS};
    fk.gap_ns[SC_SOCKETCAN_CLOCK_READINGS] = 138807u;   /* the reading at the first frame */
    fk.gap_ns[SC_SOCKETCAN_CLOCK_READINGS + 1u] = 250u; /* at the second */
    sc_socketcan s;
    assert_int_equal(sc_socketcan_open(&s, &fake_sys, &fk, "vcan0"), 0);
    sc_can_dev dev = sc_socketcan_dev(&s);
    const uint64_t t1 = (uint64_t)REAL_MINUS_MONO_NS + 5000000000u;
    push_rx(&fk, 0x100, 8, 0, t1, 0);
    push_rx(&fk, 0x101, 8, 0, t1 + 96203u, 0);
    push_rx(&fk, 0x102, 8, 0, t1 + 96203u, 0); /* a tie stays a tie */
    sc_can_frame a, b, c;
    assert_int_equal(sc_can_recv(&dev, &a), 0);
    assert_int_equal(sc_can_recv(&dev, &b), 0);
    assert_int_equal(sc_can_recv(&dev, &c), 0);
    assert_int_equal(a.ts_ns, 5000000000u); /* the exact MONOTONIC time */
    assert_int_equal(b.ts_ns - a.ts_ns, 96203u);
    assert_int_equal(c.ts_ns, b.ts_ns);
    assert_int_equal(s.tsconv.steps, 0);
}

static void a_realtime_step_reestimates_the_offset_and_is_counted(void **state)
{
    (void)state;
    fake fk = {.open_rc = 3, .real_minus_mono_ns = REAL_MINUS_MONO_NS};
    sc_socketcan s;
    assert_int_equal(sc_socketcan_open(&s, &fake_sys, &fk, "vcan0"), 0);
    sc_can_dev dev = sc_socketcan_dev(&s);
    const uint64_t t1 = (uint64_t)REAL_MINUS_MONO_NS + 5000000000u;
    push_rx(&fk, 0x100, 8, 0, t1, 0);
    sc_can_frame f;
    assert_int_equal(sc_can_recv(&dev, &f), 0);
    assert_int_equal(f.ts_ns, 5000000000u);
    /* REALTIME stepped 2 s forward (settimeofday); the next frame is stamped after it */
    fk.real_minus_mono_ns += 2000000000;
    push_rx(&fk, 0x101, 8, 0, t1 + 2000000000u + 1000u, 0);
    assert_int_equal(sc_can_recv(&dev, &f), 0);
    assert_int_equal(f.ts_ns, 5000001000u);
    assert_int_equal(s.tsconv.steps, 1);
    /* frames without a kernel stamp stay unknown */
    push_rx(&fk, 0x102, 8, 0, 0, 0);
    assert_int_equal(sc_can_recv(&dev, &f), 0);
    assert_int_equal(f.ts_ns, 0);
}

static void open_fails_and_closes_when_the_clocks_cannot_be_read(void **state)
{
    (void)state;
    fake fk = {.open_rc = 3, .clocks_rc = SC_ERR_IO};
    sc_socketcan s;
    assert_int_equal(sc_socketcan_open(&s, &fake_sys, &fk, "vcan0"), SC_ERR_IO);
    assert_int_equal(fk.closed, 1);
    assert_int_equal(s.handle, -1);
}

/* sonocomp's SocketCAN device: the node behind the receive mailboxes (sc_can_rxmb_port). The
 * kernel queue holds a stall's worth of pose frames (300, 3 s of one 100 Hz stream) with a
 * command, its MAC and an error frame queued behind them: one receive drains the socket, the
 * command block and the error frame come out first in their order, then the newest 64 poses
 * in order with their kernel stamps; every frame is counted and the kernel filters still reach
 * the socket. Without the mailboxes the command would come 300 frames (5 engine frames) late. */
static void a_command_behind_a_stall_of_poses_is_taken_first_through_the_mailboxes(void **state)
{
    (void)state;
    fake fk = {.open_rc = 5};
    sc_socketcan s;
    assert_int_equal(sc_socketcan_open(&s, &fake_sys, &fk, "vcan0"), 0);
    static sc_can_rxmb_port port;
    const sc_can_rxmb_def def = sc_can_rxmb_default_def();
    assert_int_equal(sc_can_rxmb_port_init(&port, &def, sc_socketcan_dev(&s), 4096u), 0);
    const sc_can_dev dev = sc_can_rxmb_port_dev(&port);

    const sc_can_filter flt = {.id = 0x100, .mask = 0x7FE, .flags = 0};
    assert_int_equal(sc_can_set_filters(&dev, &flt, 1), 0);
    assert_int_equal(fk.filt_n, 1);
    assert_int_equal(fk.filt[0].can_id, 0x100);

    const uint64_t t0 = 1700000000000000000ull; /* REALTIME ns */
    for (int i = 0; i < 300; i++) {
        push_rx(&fk, (uint32_t)(0x100 + (i & 1)), 8, 0, t0 + (uint64_t)i * 10000000u, 0);
        fk.rxq[fk.rx_n - 1].data[0] = (uint8_t)i;
    }
    push_rx(&fk, 0x081, 8, 0, t0 + 3000000000ull, 0); /* a command */
    push_rx(&fk, 0x100, 8, 0, t0 + 3000500000ull, 2); /* a pose; the kernel dropped 2 */
    push_rx(&fk, 0x089, 8, 0, t0 + 3001000000ull, 0); /* its MAC */
    push_rx(&fk, CAN_ERR_FLAG | CAN_ERR_CRTL, 8, 0, t0 + 3002000000ull, 0);
    fk.rxq[fk.rx_n - 1].data[1] = CAN_ERR_CRTL_RX_WARNING;

    sc_can_frame fr;
    assert_int_equal(sc_can_recv(&dev, &fr), 0);
    assert_int_equal(fr.id, 0x081);
    assert_int_equal(fk.rx_i, fk.rx_n); /* the socket drained in one receive */
    const uint64_t t_cmd = fr.ts_ns;
    assert_true(t_cmd != 0u);
    assert_int_equal(sc_can_recv(&dev, &fr), 0);
    assert_int_equal(fr.id, 0x089);
    assert_int_equal(fr.ts_ns - t_cmd, 1000000u); /* kernel stamps kept, on one base */
    assert_int_equal(sc_can_recv(&dev, &fr), 0);
    assert_true(fr.flags & SC_CAN_FLAG_ERR);
    assert_true(fr.id & SC_CAN_ERRF_WARNING);
    /* then the newest 64 stream frames, oldest first: poses 237..299 and the one after the
     * command */
    uint64_t prev = 0;
    for (int i = 0; i < 64; i++) {
        assert_int_equal(sc_can_recv(&dev, &fr), 0);
        assert_true(fr.id == 0x100 || fr.id == 0x101);
        if (i < 63) {
            assert_int_equal(fr.data[0], (uint8_t)(237 + i));
        } else {
            assert_int_equal(fr.ts_ns - t_cmd, 500000u);
        }
        assert_true(fr.ts_ns > prev);
        prev = fr.ts_ns;
    }
    assert_int_equal(sc_can_recv(&dev, &fr), SC_ERR_WOULD_BLOCK);

    const sc_can_rxmb_counters *c = &port.mb.c;
    assert_int_equal(c->put, 304);
    assert_int_equal(c->prio_taken, 3);
    assert_int_equal(c->stream_taken, 64);
    assert_int_equal(c->stream_overwritten, 301 - 64);
    assert_int_equal(c->prio_dropped, 0);
    assert_int_equal(c->put, c->prio_taken + c->stream_taken + c->stream_overwritten);
    assert_int_equal(s.rx_frames, 303);
    assert_int_equal(s.rx_error_frames, 1);
    sc_can_state st;
    sc_can_counters cc;
    assert_int_equal(sc_can_get_state(&dev, &st, &cc), 0);
    assert_int_equal(st, SC_CAN_STATE_ERROR_WARNING);
    assert_int_equal(cc.rx_dropped, 2u + (301u - 64u)); /* the kernel's and the mailboxes' */

    /* a bounded drain: 10 frames at most per receive, the rest stays in the socket */
    fake fk2 = {.open_rc = 6};
    sc_socketcan s2;
    assert_int_equal(sc_socketcan_open(&s2, &fake_sys, &fk2, "vcan0"), 0);
    static sc_can_rxmb_port port2;
    assert_int_equal(sc_can_rxmb_port_init(&port2, &def, sc_socketcan_dev(&s2), 10u), 0);
    const sc_can_dev dev2 = sc_can_rxmb_port_dev(&port2);
    for (int i = 0; i < 25; i++) {
        push_rx(&fk2, 0x100, 8, 0, t0 + (uint64_t)i, 0);
    }
    assert_int_equal(sc_can_recv(&dev2, &fr), 0);
    assert_int_equal(fk2.rx_i, 10);
    assert_int_equal(port2.drain_limited, 1);
    sc_socketcan_close(&s);
    sc_socketcan_close(&s2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(frames_error_frames_and_drops_are_received_with_state_and_time),
        cmocka_unit_test(sending_converts_frames_and_gates_fd_on_the_interface),
        cmocka_unit_test(filters_become_kernel_filters_that_separate_standard_and_extended),
        cmocka_unit_test(error_classes_survive_linux_form_and_back),
        cmocka_unit_test(tsconv_estimate_takes_the_narrowest_bracket_midpoint),
        cmocka_unit_test(tsconv_conversion_keeps_the_order_of_ordered_stamps),
        cmocka_unit_test(tsconv_finds_realtime_steps_but_not_in_delayed_readings),
        cmocka_unit_test(kernel_stamps_keep_order_and_distance_when_a_clock_reading_is_preempted),
        cmocka_unit_test(a_realtime_step_reestimates_the_offset_and_is_counted),
        cmocka_unit_test(open_fails_and_closes_when_the_clocks_cannot_be_read),
        cmocka_unit_test(a_command_behind_a_stall_of_poses_is_taken_first_through_the_mailboxes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
