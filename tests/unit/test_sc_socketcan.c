/* test_sc_socketcan.c: the SocketCAN node's logic over a fake syscall adapter (this host's
 * kernel has no CAN): frame conversion both ways, error frames -> classes and bus state,
 * kernel filters, FD gating, drop counting, bus-off refusal. The real adapter runs in the VM. */
#include "sc_test.h"

#include <string.h>

#include <linux/can.h>
#include <linux/can/error.h>

#include "sc_err.h"
#include "sc_socketcan.h"

typedef struct fake {
    int open_rc;
    int fd_capable;
    sc_socketcan_raw rxq[8];
    int rx_fd[8];
    uint64_t rx_ts[8];
    uint32_t rx_drops[8];
    int rx_n, rx_i;
    sc_socketcan_raw tx[8];
    int tx_fd[8];
    int tx_n;
    int send_rc;
    sc_socketcan_rawfilter filt[SC_CAN_MAX_FILTERS];
    size_t filt_n;
    int closed;
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
static const sc_socketcan_sys fake_sys = {f_open, f_set_filters, f_recv, f_send, f_close};

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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(frames_error_frames_and_drops_are_received_with_state_and_time),
        cmocka_unit_test(sending_converts_frames_and_gates_fd_on_the_interface),
        cmocka_unit_test(filters_become_kernel_filters_that_separate_standard_and_extended),
        cmocka_unit_test(error_classes_survive_linux_form_and_back),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
