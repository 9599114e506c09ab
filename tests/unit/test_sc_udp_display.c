/* test_sc_udp_display.c: the display link sender through a real UDP socket on 127.0.0.1 into
 * the frame assembler: nothing lost when nothing is injected, exactly the injected lines lost
 * otherwise, and a full socket buffer drops and counts instead of blocking. Batching: packets
 * arrive in call order (BEGIN, lines, END) for every batch size, frames larger than a batch and
 * ending mid-batch, with the expected number of system calls; with a datagram socket pair whose
 * reader never reads (a socket that really refuses with EAGAIN, which UDP on loopback never
 * does: it drops at the receiver) the sender's counts are exactly what the reader got; a
 * refused destination takes the link down and a receiver brings it up again. */
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
    const sc_display_frame_info info = {.frame_no = frame_no,
                                        .lines = lines,
                                        .samples = samples,
                                        .geometry_id = 0u,
                                        .flags = 1u,
                                        .depth_mm = 40.0f,
                                        .width_mm = 38.0f,
                                        .radius_mm = 0.0f};
    uint8_t s[SC_MAX_SCAN_SAMPLES];
    (void)sc_display_frame_begin(dev, &info);
    for (uint16_t l = 0; l < lines; l++) {
        memset(s, (int)((frame_no + l) & 0xFFu), samples);
        (void)sc_display_line(dev, frame_no, l, s, samples);
    }
    (void)sc_display_frame_end(dev, SC_DISPLAY_END_PLAIN(frame_no));
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
    assert_int_equal(sc_display_frame_end(&dev, SC_DISPLAY_END_PLAIN(1u)), SC_ERR_STATE);
    const sc_display_frame_info info = {.frame_no = 1u,
                                        .lines = 4u,
                                        .samples = 16u,
                                        .geometry_id = 0u,
                                        .flags = 0u,
                                        .depth_mm = 40.0f,
                                        .width_mm = 38.0f,
                                        .radius_mm = 0.0f};
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

/* Every datagram queued at fd, decoded, in order: type, frame, line index, and FRAME_END's
 * counts. Returns how many (up to cap). */
typedef struct rx_pkt {
    uint8_t type;
    uint32_t frame_no;
    uint16_t line_index;
    sc_dlink_end end;
} rx_pkt;

static uint32_t read_all(int fd, rx_pkt *out, uint32_t cap)
{
    uint8_t buf[2048];
    uint32_t n = 0;
    struct pollfd p = {fd, POLLIN, 0};
    while (n < cap && poll(&p, 1, 10) > 0) {
        ssize_t len = recv(fd, buf, sizeof buf, MSG_DONTWAIT);
        if (len < 0) {
            break;
        }
        sc_dlink_header h;
        const uint8_t *pl = NULL;
        assert_int_equal(sc_dlink_decode(buf, (size_t)len, &h, &pl), 0);
        out[n].type = h.type;
        out[n].frame_no = h.frame_no;
        out[n].line_index = h.line_index;
        memset(&out[n].end, 0, sizeof out[n].end);
        if (h.type == SC_DLINK_FRAME_END) {
            sc_dlink_parse_end(pl, &out[n].end);
        }
        n++;
    }
    return n;
}

static rx_pkt g_pkts[4096];

static void packets_arrive_in_call_order_for_every_batch_size(void **state)
{
    (void)state;
    static const uint32_t batches[] = {1u, 2u, 8u, 32u, 64u};
    /* 100 lines: larger than most batches, the frame ends mid-batch; 31 lines: BEGIN and the
     * lines fill a batch of 32 exactly, FRAME_END goes alone; 1 line. */
    static const uint16_t frame_lines[] = {100u, 31u, 1u};
    for (uint32_t bi = 0; bi < sizeof batches / sizeof batches[0]; bi++) {
        uint16_t port;
        int rx = open_rx(&port, 4 * 1024 * 1024);
        sc_udp_display u;
        sc_udp_display_def def = sc_udp_display_default_def();
        def.port = port;
        def.batch_packets = batches[bi];
        assert_int_equal(sc_udp_display_open(&u, &def), 0);
        sc_display_dev dev = sc_udp_display_dev(&u);
        for (uint32_t fi = 0; fi < sizeof frame_lines / sizeof frame_lines[0]; fi++) {
            const uint16_t n = frame_lines[fi];
            const uint64_t calls0 = u.send_calls;
            send_frame(&dev, 7u + fi, n, 64u);
            /* BEGIN and the lines fill floor((n + 1) / b) batches; the last one takes the rest
             * with FRAME_END */
            assert_int_equal(u.send_calls - calls0, (n + 1u) / batches[bi] + 1u);
            const uint32_t got = read_all(rx, g_pkts, 4096u);
            assert_int_equal(got, n + 2u);
            assert_int_equal(g_pkts[0].type, SC_DLINK_FRAME_BEGIN);
            for (uint16_t l = 0; l < n; l++) {
                assert_int_equal(g_pkts[1u + l].type, SC_DLINK_LINE);
                assert_int_equal(g_pkts[1u + l].line_index, l);
                assert_int_equal(g_pkts[1u + l].frame_no, 7u + fi);
            }
            assert_int_equal(g_pkts[n + 1u].type, SC_DLINK_FRAME_END);
            assert_int_equal(g_pkts[n + 1u].end.lines_sent, n);
            assert_int_equal(g_pkts[n + 1u].end.lines_dropped, 0u);
        }
        assert_int_equal(u.lines_sent, 132u);
        assert_int_equal(u.lines_dropped, 0u);
        assert_int_equal(u.send_errors, 0u);
        assert_true(u.up);
        sc_udp_display_close(&u);
        close(rx);
    }
}

static void lines_wait_in_the_batch_until_it_is_full_or_the_frame_ends(void **state)
{
    (void)state;
    uint16_t port;
    int rx = open_rx(&port, 4 * 1024 * 1024);
    sc_udp_display u;
    sc_udp_display_def def = sc_udp_display_default_def();
    def.port = port;
    def.batch_packets = 8u;
    assert_int_equal(sc_udp_display_open(&u, &def), 0);
    sc_display_dev dev = sc_udp_display_dev(&u);
    const sc_display_frame_info info = {.frame_no = 3u,
                                        .lines = 20u,
                                        .samples = 16u,
                                        .geometry_id = 0u,
                                        .flags = 0u,
                                        .depth_mm = 40.0f,
                                        .width_mm = 38.0f,
                                        .radius_mm = 0.0f};
    uint8_t s[16] = {0};
    assert_int_equal(sc_display_frame_begin(&dev, &info), 0);
    for (uint16_t l = 0; l < 6u; l++) {
        assert_int_equal(sc_display_line(&dev, 3u, l, s, 16u), 0);
    }
    /* 7 packets queued: nothing has left, nothing is counted yet */
    assert_int_equal(u.send_calls, 0u);
    assert_int_equal(read_all(rx, g_pkts, 4096u), 0u);
    assert_int_equal(u.lines_sent + u.lines_dropped, 0u);
    assert_int_equal(sc_display_line(&dev, 3u, 6u, s, 16u), 0); /* the 8th fills the batch */
    assert_int_equal(u.send_calls, 1u);
    assert_int_equal(u.lines_sent, 7u);
    assert_int_equal(read_all(rx, g_pkts, 4096u), 8u);
    /* a frame left open: close counts its queued lines dropped, they never reach the socket */
    assert_int_equal(sc_display_line(&dev, 3u, 7u, s, 16u), 0);
    assert_int_equal(sc_display_line(&dev, 3u, 8u, s, 16u), 0);
    sc_udp_display_close(&u);
    assert_int_equal(u.lines_sent, 7u);
    assert_int_equal(u.lines_dropped, 2u);
    assert_int_equal(read_all(rx, g_pkts, 4096u), 0u);
    close(rx);
}

/* The sender's socket replaced by one end of a datagram socket pair (a test reaching into the
 * struct): with a tiny send buffer and nobody reading, it refuses with EAGAIN after a few
 * packets, and what was taken is exactly what the reader finds afterwards. */
static void full_socket_counts_exactly_what_the_reader_gets(void **state)
{
    (void)state;
    static const uint32_t batches[] = {1u, 8u, 32u, 64u};
    static const uint32_t drops[] = {0u, 100u};
    for (uint32_t bi = 0; bi < sizeof batches / sizeof batches[0]; bi++) {
        for (uint32_t di = 0; di < 2u; di++) {
            uint16_t port;
            int rx = open_rx(&port, 65536);
            sc_udp_display u;
            sc_udp_display_def def = sc_udp_display_default_def();
            def.port = port;
            def.batch_packets = batches[bi];
            def.inject_drop_permille = drops[di];
            assert_int_equal(sc_udp_display_open(&u, &def), 0);
            int sv[2];
            assert_int_equal(socketpair(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0, sv), 0);
            int sndbuf = 4096;
            assert_int_equal(setsockopt(sv[0], SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf), 0);
            assert_true(dup2(sv[0], u.fd) == u.fd);
            close(sv[0]);
            sc_display_dev dev = sc_udp_display_dev(&u);
            send_frame(&dev, 40u, 100u, 256u);
            send_frame(&dev, 41u, 100u, 256u);
            /* every line ends sent or dropped, dropped ones are refused sends */
            assert_int_equal(u.lines_sent + u.lines_dropped, 200u);
            assert_true(u.lines_dropped > 100u);
            assert_true(u.send_errors >= u.lines_dropped);
            /* a full buffer refusing a packet at once leaves the link state as it was (the
             * per-packet path); a batch taken only in part reads as down */
            assert_int_equal(u.up, batches[bi] == 1u);
            assert_true(u.last_errno == EAGAIN || u.last_errno == EWOULDBLOCK);
            if (drops[di] == 0u) {
                assert_int_equal(u.lines_injected, 0u);
            } else {
                assert_true(u.lines_injected > 0u);
            }
            /* the reader gets exactly the lines counted sent and not injected, in order */
            const uint32_t got = read_all(sv[1], g_pkts, 4096u);
            uint32_t lines = 0;
            int prev = -1;
            for (uint32_t i = 0; i < got; i++) {
                if (g_pkts[i].type == SC_DLINK_LINE) {
                    lines++;
                    assert_int_equal(g_pkts[i].frame_no, 40u);
                    assert_true((int)g_pkts[i].line_index > prev);
                    prev = g_pkts[i].line_index;
                }
            }
            assert_int_equal(lines, u.lines_sent - u.lines_injected);
            assert_true(got >= 1u && g_pkts[0].type == SC_DLINK_FRAME_BEGIN);
            assert_int_equal(u.packets_sent, got);
            /* with the reader drained the link takes a whole (small: the buffer holds a few
             * datagrams) frame and reads up again; its FRAME_END counts are exact */
            const uint64_t sent0 = u.lines_sent, inj0 = u.lines_injected;
            send_frame(&dev, 42u, 3u, 256u);
            assert_true(u.up);
            const uint32_t got2 = read_all(sv[1], g_pkts, 4096u);
            const uint32_t inj = (uint32_t)(u.lines_injected - inj0);
            assert_int_equal(got2, 3u - inj + 2u);
            assert_int_equal(g_pkts[got2 - 1u].type, SC_DLINK_FRAME_END);
            assert_int_equal(g_pkts[got2 - 1u].end.lines_sent, 3u);
            assert_int_equal(g_pkts[got2 - 1u].end.lines_dropped, 0u);
            assert_int_equal(u.lines_sent - sent0, 3u);
            sc_udp_display_close(&u);
            close(sv[1]);
            close(rx);
        }
    }
}

/* A full buffer at frame_end: FRAME_END, last in the batch, is not taken; it is re-encoded
 * with the exact counts and tried once more alone (here the buffer is still full, so that try
 * fails too and is counted: at most two system calls). */
static void frame_end_is_tried_once_more_alone_when_its_batch_did_not_all_go(void **state)
{
    (void)state;
    uint16_t port;
    int rx = open_rx(&port, 65536);
    sc_udp_display u;
    sc_udp_display_def def = sc_udp_display_default_def();
    def.port = port;
    def.batch_packets = 64u;
    assert_int_equal(sc_udp_display_open(&u, &def), 0);
    int sv[2];
    assert_int_equal(socketpair(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0, sv), 0);
    int sndbuf = 4096; /* a few datagrams until the reader reads */
    assert_int_equal(setsockopt(sv[0], SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf), 0);
    assert_true(dup2(sv[0], u.fd) == u.fd);
    close(sv[0]);
    sc_display_dev dev = sc_udp_display_dev(&u);
    const sc_display_frame_info info = {.frame_no = 9u,
                                        .lines = 40u,
                                        .samples = 64u,
                                        .geometry_id = 0u,
                                        .flags = 0u,
                                        .depth_mm = 40.0f,
                                        .width_mm = 38.0f,
                                        .radius_mm = 0.0f};
    uint8_t s[64] = {0};
    assert_int_equal(sc_display_frame_begin(&dev, &info), 0);
    for (uint16_t l = 0; l < 40u; l++) {
        assert_int_equal(sc_display_line(&dev, 9u, l, s, 64u), 0); /* all queued (batch 64) */
    }
    assert_int_equal(sc_display_frame_end(&dev, SC_DISPLAY_END_PLAIN(9u)), SC_ERR_IO); /* part of the batch taken */
    assert_false(u.up);
    assert_int_equal(u.send_calls, 2u);
    const uint32_t got = read_all(sv[1], g_pkts, 4096u);
    assert_true(got >= 2u && got < 40u);
    assert_int_equal(g_pkts[0].type, SC_DLINK_FRAME_BEGIN);
    for (uint32_t i = 1; i < got; i++) {
        assert_int_equal(g_pkts[i].type, SC_DLINK_LINE);
        assert_int_equal(g_pkts[i].line_index, i - 1u);
    }
    assert_int_equal(u.lines_sent, got - 1u);
    assert_int_equal(u.lines_dropped, 40u - (got - 1u));
    assert_int_equal(u.packets_sent, got);
    assert_int_equal(u.send_errors, 42u - got + 1u); /* the batch's rest, FRAME_END again */
    sc_udp_display_close(&u);
    close(sv[1]);
    close(rx);
}

/* No receiver: ICMP port unreachable refuses the sends (on loopback while a batch goes out, so
 * sendmmsg takes only its start); the link reads down, every line is counted; once a receiver
 * binds the port, a whole frame goes and the link reads up. */
static void refused_destination_takes_the_link_down_until_a_receiver_appears(void **state)
{
    (void)state;
    uint16_t port;
    int rx = open_rx(&port, 4 * 1024 * 1024);
    close(rx); /* the port is free now: nobody listens */
    sc_udp_display u;
    sc_udp_display_def def = sc_udp_display_default_def();
    def.port = port;
    def.batch_packets = 64u;
    assert_int_equal(sc_udp_display_open(&u, &def), 0);
    sc_display_dev dev = sc_udp_display_dev(&u);
    /* one batch: BEGIN goes, its ICMP error refuses the next packet and sendmmsg stops there;
     * the error is consumed, so FRAME_END sent again alone goes (to nobody) */
    const sc_display_frame_info info = {.frame_no = 0u,
                                        .lines = 40u,
                                        .samples = 64u,
                                        .geometry_id = 0u,
                                        .flags = 0u,
                                        .depth_mm = 40.0f,
                                        .width_mm = 38.0f,
                                        .radius_mm = 0.0f};
    uint8_t s[64] = {0};
    assert_int_equal(sc_display_frame_begin(&dev, &info), 0);
    for (uint16_t l = 0; l < 40u; l++) {
        assert_int_equal(sc_display_line(&dev, 0u, l, s, 64u), 0);
    }
    assert_int_equal(sc_display_frame_end(&dev, SC_DISPLAY_END_PLAIN(0u)), SC_ERR_IO);
    assert_false(u.up);
    assert_int_equal(u.send_calls, 2u);
    assert_int_equal(u.packets_sent, 2u);
    assert_int_equal(u.lines_sent, 0u);
    assert_int_equal(u.lines_dropped, 40u);
    for (uint32_t f = 1; f < 3u; f++) {
        send_frame(&dev, f, 100u, 64u);
    }
    assert_int_equal(u.lines_sent + u.lines_dropped, 240u);
    assert_false(u.up);
    sc_display_link_state st;
    assert_int_equal(sc_display_get_link_state(&dev, &st), 0);
    assert_false(st.up);
    assert_int_equal(st.lines_sent + st.lines_dropped, 240u);

    rx = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(port);
    assert_int_equal(bind(rx, (struct sockaddr *)&a, sizeof a), 0);
    /* a refusal may still be pending from the last frame: it costs at most the next batch */
    send_frame(&dev, 3u, 100u, 64u);
    (void)read_all(rx, g_pkts, 4096u);
    const uint64_t dropped = u.lines_dropped;
    send_frame(&dev, 4u, 100u, 64u);
    assert_int_equal(u.lines_dropped, dropped);
    assert_true(u.up);
    const uint32_t got = read_all(rx, g_pkts, 4096u);
    assert_int_equal(got, 102u);
    assert_int_equal(g_pkts[0].type, SC_DLINK_FRAME_BEGIN);
    assert_int_equal(g_pkts[101].type, SC_DLINK_FRAME_END);
    assert_int_equal(g_pkts[101].end.lines_sent, 100u);
    sc_udp_display_close(&u);
    close(rx);
}

static void batch_above_the_limit_is_refused(void **state)
{
    (void)state;
    sc_udp_display u;
    sc_udp_display_def def = sc_udp_display_default_def();
    assert_int_equal(def.batch_packets, SC_UDP_DISPLAY_DEFAULT_BATCH);
    def.batch_packets = SC_UDP_DISPLAY_MAX_BATCH + 1u;
    assert_int_equal(sc_udp_display_open(&u, &def), SC_ERR_RANGE);
    def.batch_packets = 0u; /* the default */
    assert_int_equal(sc_udp_display_open(&u, &def), 0);
    assert_int_equal(u.batch, SC_UDP_DISPLAY_DEFAULT_BATCH);
    sc_udp_display_close(&u);
}

/* Colour Doppler over UDP: the colour lines and the frame's Doppler record arrive with their
 * frame (display link version 3) and the B-mode lines are counted as before. */
static void colour_lines_and_the_doppler_record_arrive_with_their_frame(void **state)
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
    const sc_display_frame_info info = {.frame_no = 3u, .lines = 64u, .samples = 128u, .geometry_id = 0u,
                                        .flags = 1u, .depth_mm = 40.0f, .width_mm = 38.0f};
    uint8_t s[128];
    int8_t c[100];
    uint8_t spec[128];
    for (int k = 0; k < 100; k++) {
        c[k] = (int8_t)(k - 50);
    }
    for (int k = 0; k < 128; k++) {
        spec[k] = (uint8_t)(2 * k);
    }
    assert_int_equal(sc_display_frame_begin(&dev, &info), 0);
    for (uint16_t l = 0; l < 64u; l++) {
        memset(s, l, sizeof s);
        assert_int_equal(sc_display_line(&dev, 3u, l, s, 128u), 0);
        if (l >= 10u && l < 50u) {
            assert_int_equal(sc_display_colour_line(&dev, 3u, l, 20u, c, 100u), 0);
        }
    }
    const sc_display_doppler_info di = {.frame_no = 3u, .box_line_lo = 10u, .box_line_hi = 50u,
                                        .box_sample_lo = 20u, .box_sample_hi = 120u,
                                        .nyquist_mm_s = 308.0f, .steer_deg = -20.0f,
                                        .gate_velocity_mm_s = 250.0f, .gate_line = 30u,
                                        .gate_sample_lo = 60u, .gate_sample_hi = 66u,
                                        .spectrum_bins = 128u, .spectrum = spec};
    assert_int_equal(sc_display_doppler(&dev, &di), 0);
    assert_int_equal(sc_display_frame_end(&dev, SC_DISPLAY_END_PLAIN(3u)), 0);
    assert_int_equal(drain(rx), 1u);
    const sc_dlink_done *d = sc_dlink_asm_done(&g_rx);
    assert_int_equal(d->lines_lost, 0u);
    assert_non_null(d->colour);
    assert_memory_equal(d->colour + 30u * SC_MAX_SCAN_SAMPLES + 20u, c, 100u);
    assert_int_equal(d->colour[9u * SC_MAX_SCAN_SAMPLES + 50u], 0);
    assert_int_equal(d->doppler_seen, 1u);
    assert_int_equal(d->doppler.gate_line, 30u);
    assert_memory_equal(d->doppler.spectrum, spec, 128u);
    assert_int_equal(g_rx.stats.colour_lines, 40u);
    assert_int_equal(g_rx.stats.rejected, 0u);
    assert_int_equal(u.lines_sent, 64u); /* B-mode lines only */
    assert_int_equal(u.protocol_errors, 0u);
    sc_udp_display_close(&u);
    close(rx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(packets_arrive_in_call_order_for_every_batch_size),
        cmocka_unit_test(lines_wait_in_the_batch_until_it_is_full_or_the_frame_ends),
        cmocka_unit_test(full_socket_counts_exactly_what_the_reader_gets),
        cmocka_unit_test(frame_end_is_tried_once_more_alone_when_its_batch_did_not_all_go),
        cmocka_unit_test(refused_destination_takes_the_link_down_until_a_receiver_appears),
        cmocka_unit_test(batch_above_the_limit_is_refused),
        cmocka_unit_test(loopback_without_injection_loses_no_line),
        cmocka_unit_test(injected_losses_are_counted_exactly_by_the_receiver),
        cmocka_unit_test(full_socket_buffer_drops_and_counts_instead_of_blocking),
        cmocka_unit_test(calls_out_of_order_are_refused_and_counted),
        cmocka_unit_test(colour_lines_and_the_doppler_record_arrive_with_their_frame),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
