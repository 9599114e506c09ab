/* sc_udp_display.c: the display link sender (see sc_udp_display.h). */
#include "sc_udp_display.h"

#include <errno.h>
#include <netdb.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "sc_err.h"

sc_udp_display_def sc_udp_display_default_def(void)
{
    sc_udp_display_def d = {.host = "127.0.0.1",
                            .port = 5600u,
                            .sndbuf_bytes = 0u,
                            .inject_drop_permille = 0u,
                            .inject_seed = 0x9E3779B9u};
    return d;
}

int sc_udp_display_open(sc_udp_display *u, const sc_udp_display_def *def)
{
    memset(u, 0, sizeof *u);
    u->fd = -1;
    u->compression_pm = SC_DLINK_COMPRESSION_UNKNOWN;
    if (!def || !def->host || def->port == 0u) {
        return SC_ERR_INVALID_ARG;
    }
    if (def->inject_drop_permille > 1000u) {
        return SC_ERR_RANGE;
    }
    u->inject_drop_permille = def->inject_drop_permille;
    u->rng = def->inject_seed ? def->inject_seed : 0x9E3779B9u;
    struct addrinfo hints;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_DGRAM;
    char port[8];
    snprintf(port, sizeof port, "%u", (unsigned)def->port);
    struct addrinfo *res = NULL;
    if (getaddrinfo(def->host, port, &hints, &res) != 0 || !res) {
        return SC_ERR_NOT_FOUND;
    }
    u->fd = socket(res->ai_family, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (u->fd < 0) {
        u->last_errno = errno;
        freeaddrinfo(res);
        return SC_ERR_IO;
    }
    int sndbuf = (int)(def->sndbuf_bytes ? def->sndbuf_bytes : 1024u * 1024u);
    (void)setsockopt(u->fd, SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf); /* best effort */
    if (connect(u->fd, res->ai_addr, res->ai_addrlen) != 0) {
        u->last_errno = errno;
        freeaddrinfo(res);
        close(u->fd);
        u->fd = -1;
        return SC_ERR_IO;
    }
    freeaddrinfo(res);
    u->up = 1;
    return 0;
}

/* Send one packet without blocking. 0, SC_ERR_WOULD_BLOCK or SC_ERR_IO. */
static int send_pkt(sc_udp_display *u, int len)
{
    ssize_t n = send(u->fd, u->pkt, (size_t)len, MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n == (ssize_t)len) {
        u->packets_sent++;
        u->up = 1;
        return 0;
    }
    u->send_errors++;
    u->last_errno = n < 0 ? errno : EMSGSIZE;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) {
        return SC_ERR_WOULD_BLOCK;
    }
    u->up = 0;
    return SC_ERR_IO;
}

static int udp_frame_begin(void *ctx, const sc_display_frame_info *info)
{
    sc_udp_display *u = ctx;
    if (u->in_frame) {
        u->protocol_errors++; /* previous frame never ended: start over */
    }
    u->frame.frame_no = info->frame_no;
    u->frame.flags = info->flags;
    u->frame.line_count = info->lines;
    u->frame.samples = info->samples;
    u->frame.geometry_id = info->geometry_id;
    u->frame_sent = 0;
    u->frame_dropped = 0;
    const sc_dlink_begin b = {info->depth_mm, info->width_mm,
                              info->geometry_id == 1u ? info->radius_mm : 0.0f, u->compression_pm};
    int len = sc_dlink_encode_begin(u->pkt, sizeof u->pkt, &u->frame, &b);
    if (len < 0) {
        u->protocol_errors++;
        u->in_frame = 0;
        return len;
    }
    u->in_frame = 1;
    u->frames++;
    return send_pkt(u, len);
}

static uint32_t xorshift32(uint32_t *s)
{
    uint32_t x = *s;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *s = x;
    return x;
}

static int udp_line(void *ctx, uint32_t frame_no, uint16_t line_index, const uint8_t *samples,
                    uint16_t count)
{
    sc_udp_display *u = ctx;
    if (!u->in_frame || frame_no != u->frame.frame_no) {
        u->protocol_errors++;
        return SC_ERR_STATE;
    }
    int len = sc_dlink_encode_line(u->pkt, sizeof u->pkt, &u->frame, line_index, samples, count);
    if (len < 0) {
        u->protocol_errors++;
        return len;
    }
    if (u->inject_drop_permille && xorshift32(&u->rng) % 1000u < u->inject_drop_permille) {
        u->lines_injected++;
        u->lines_sent++;
        u->frame_sent++;
        return 0;
    }
    int rc = send_pkt(u, len);
    if (rc == 0) {
        u->lines_sent++;
        u->frame_sent++;
    } else {
        u->lines_dropped++;
        u->frame_dropped++;
    }
    return rc;
}

static int udp_frame_end(void *ctx, uint32_t frame_no)
{
    sc_udp_display *u = ctx;
    if (!u->in_frame || frame_no != u->frame.frame_no) {
        u->protocol_errors++;
        return SC_ERR_STATE;
    }
    u->in_frame = 0;
    const sc_dlink_end e = {u->frame_sent, u->frame_dropped};
    int len = sc_dlink_encode_end(u->pkt, sizeof u->pkt, &u->frame, &e);
    if (len < 0) {
        u->protocol_errors++;
        return len;
    }
    return send_pkt(u, len);
}

static int udp_link_state(void *ctx, sc_display_link_state *st)
{
    sc_udp_display *u = ctx;
    st->up = u->up;
    st->lines_sent = (uint32_t)u->lines_sent;
    st->lines_dropped = (uint32_t)u->lines_dropped;
    return 0;
}

static const sc_display_ops k_udp_ops = {udp_frame_begin, udp_line, udp_frame_end, udp_link_state};

sc_display_dev sc_udp_display_dev(sc_udp_display *u)
{
    sc_display_dev d = {&k_udp_ops, u};
    return d;
}

void sc_udp_display_set_compression(sc_udp_display *u, uint16_t compression_pm)
{
    u->compression_pm = compression_pm;
}

void sc_udp_display_close(sc_udp_display *u)
{
    if (u->fd >= 0) {
        close(u->fd);
        u->fd = -1;
    }
    u->up = 0;
}
