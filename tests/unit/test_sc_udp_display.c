/* test_sc_udp_display.c: the display link sender through a real UDP socket on 127.0.0.1 into
 * the frame assembler: nothing lost when nothing is injected, exactly the injected lines lost
 * otherwise, and a full socket buffer drops and counts instead of blocking. */
#include "sc_test.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "sc_dlink.h"
#include "sc_err.h"
#include "sc_udp_display.h"

static sc_dlink_asm g_rx;

/* A receiving socket on an ephemeral loopback port with a receive buffer large enough for the
 * test's bursts (the sender is not paced). */
static int open_rx(uint16_t *port, int rcvbuf)
{
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    assert_true(fd >= 0);
    (void)setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof a), 0);
    socklen_t len = sizeof a;
    assert_int_equal(getsockname(fd, (struct sockaddr *)&a, &len), 0);
    *port = ntohs(a.sin_port);
    return fd;
}

/* Receive everything queued (waiting up to 10 ms for more) into the assembler. */
static uint32_t drain(int fd)
{
    uint8_t buf[2048];
    uint32_t frames = 0;
    struct pollfd p = {fd, POLLIN, 0};
    while (poll(&p, 1, 10) > 0) { /* loopback queues at send time */
        ssize_t n = recv(fd, buf, sizeof buf, MSG_DONTWAIT);
        if (n < 0) {
            break;
        }
        if (sc_dlink_asm_push(&g_rx, buf, (size_t)n) == 1) {
            frames++;
        }
    }
    return frames;
}

static void send_frame(sc_display_dev *dev, uint32_t frame_no, uint16_t lines, uint16_t samples)
{
    const sc_display_frame_info info = {frame_no, lines, samples, 0u, 1u, 40.0f, 38.0f, 0.0f};
    uint8_t s[SC_MAX_SCAN_SAMPLES];
    (void)sc_display_frame_begin(dev, &info);
    for (uint16_t l = 0; l < lines; l++) {
        memset(s, (int)((frame_no + l) & 0xFFu), samples);
        (void)sc_display_line(dev, frame_no, l, s, samples);
    }
    (void)sc_display_frame_end(dev, frame_no);
}

static void loopback_without_injection_loses_no_line(void **state)
{
    (void)state;
    uint16_t port;
    int rx = open_rx(&port, 4 * 1024 * 1024);
    sc_udp_display u;
    sc_udp_display_def def = sc_udp_display_default_def();
    def.port = port;
    assert_int_equal(sc_udp_display_open(&u, &def), 0);
    sc_display_dev dev = sc_udp_display_dev(&u);
    sc_dlink_asm_init(&g_rx);
    uint32_t frames = 0;
    for (uint32_t f = 0; f < 50u; f++) {
        send_frame(&dev, f, 128u, 256u); /* 130 datagrams, 37 KiB: fits the socket buffers */
        frames += drain(rx);
    }
    assert_int_equal(frames, 50u);
    assert_int_equal(g_rx.stats.lines_received, 50u * 128u);
    assert_int_equal(g_rx.stats.lines_lost, 0u);
    assert_int_equal(g_rx.stats.frames_complete, 50u);
    assert_int_equal(g_rx.stats.rejected, 0u);
    assert_int_equal(u.lines_dropped, 0u);
    assert_int_equal(u.lines_sent, 50u * 128u);
    const sc_dlink_done *d = sc_dlink_asm_done(&g_rx);
    assert_int_equal(d->frame.frame_no, 49u);
    assert_int_equal(d->image[5u * SC_MAX_SCAN_SAMPLES + 7u], (49u + 5u) & 0xFFu);
    sc_display_link_state st;
    assert_int_equal(sc_display_get_link_state(&dev, &st), 0);
    assert_true(st.up);
    sc_udp_display_close(&u);
    close(rx);
}

static void injected_losses_are_counted_exactly_by_the_receiver(void **state)
{
    (void)state;
    uint16_t port;
    int rx = open_rx(&port, 4 * 1024 * 1024);
    sc_udp_display u;
    sc_udp_display_def def = sc_udp_display_default_def();
    def.port = port;
    def.inject_drop_permille = 37u;
    def.inject_seed = 12345u;
    assert_int_equal(sc_udp_display_open(&u, &def), 0);
    sc_display_dev dev = sc_udp_display_dev(&u);
    sc_dlink_asm_init(&g_rx);
    for (uint32_t f = 100; f < 160u; f++) {
        send_frame(&dev, f, 200u, 128u);
        drain(rx);
    }
    sc_dlink_asm_flush(&g_rx);
    /* about 3.7% of 12,000 lines: the count must be non-trivial and exactly what was injected */
    assert_true(u.lines_injected > 200u && u.lines_injected < 700u);
    assert_int_equal(u.lines_dropped, 0u);
    assert_int_equal(g_rx.stats.lines_lost, u.lines_injected);
    assert_int_equal(g_rx.stats.lines_received + g_rx.stats.lines_lost, 60u * 200u);
    assert_int_equal(g_rx.stats.frames_complete + g_rx.stats.frames_incomplete, 60u);
    sc_udp_display_close(&u);
    close(rx);
}

static void full_socket_buffer_drops_and_counts_instead_of_blocking(void **state)
{
    (void)state;
    uint16_t port;
    int rx = open_rx(&port, 4096); /* tiny receive buffer, never read: the path fills up */
    sc_udp_display u;
    sc_udp_display_def def = sc_udp_display_default_def();
    def.port = port;
    def.sndbuf_bytes = 4096u;
    assert_int_equal(sc_udp_display_open(&u, &def), 0);
    sc_display_dev dev = sc_udp_display_dev(&u);
    /* 20 frames of 512 x 512: 10 MiB offered at once. On loopback the kernel drops datagrams
     * that do not fit the receiver (not counted by the sender) or refuses them with EAGAIN or
     * ENOBUFS when the send buffer is full (counted); either way, every call returns. */
    for (uint32_t f = 0; f < 20u; f++) {
        send_frame(&dev, f, 512u, 512u);
    }
    assert_int_equal(u.lines_sent + u.lines_dropped, 20u * 512u);
    assert_int_equal(u.frames, 20u);
    assert_int_equal(u.protocol_errors, 0u);
    sc_udp_display_close(&u);
    close(rx);
}

static void calls_out_of_order_are_refused_and_counted(void **state)
{
    (void)state;
    uint16_t port;
    int rx = open_rx(&port, 65536);
    sc_udp_display u;
    sc_udp_display_def def = sc_udp_display_default_def();
    def.port = port;
    assert_int_equal(sc_udp_display_open(&u, &def), 0);
    sc_display_dev dev = sc_udp_display_dev(&u);
    uint8_t s[16] = {0};
    assert_int_equal(sc_display_line(&dev, 1u, 0u, s, 16u), SC_ERR_STATE);
    assert_int_equal(sc_display_frame_end(&dev, 1u), SC_ERR_STATE);
    const sc_display_frame_info info = {1u, 4u, 16u, 0u, 0u, 40.0f, 38.0f, 0.0f};
    assert_int_equal(sc_display_frame_begin(&dev, &info), 0);
    assert_int_equal(sc_display_line(&dev, 1u, 4u, s, 16u), SC_ERR_DLINK_FIELD);
    assert_int_equal(sc_display_line(&dev, 1u, 0u, s, 15u), SC_ERR_DLINK_FIELD);
    assert_int_equal(sc_display_line(&dev, 2u, 0u, s, 16u), SC_ERR_STATE);
    assert_int_equal(u.protocol_errors, 5u);
    def.inject_drop_permille = 1001u;
    sc_udp_display u2;
    assert_int_equal(sc_udp_display_open(&u2, &def), SC_ERR_RANGE);
    sc_udp_display_close(&u);
    close(rx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(loopback_without_injection_loses_no_line),
        cmocka_unit_test(injected_losses_are_counted_exactly_by_the_receiver),
        cmocka_unit_test(full_socket_buffer_drops_and_counts_instead_of_blocking),
        cmocka_unit_test(calls_out_of_order_are_refused_and_counted),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
