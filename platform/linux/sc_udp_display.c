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
                            .inject_seed = 0x9E3779B9u,
                            .batch_packets = SC_UDP_DISPLAY_DEFAULT_BATCH};
    return d;
}

int sc_udp_display_open(sc_udp_display *u, const sc_udp_display_def *def)
{
    memset(u, 0, sizeof *u);
    u->fd = -1;
    if (!def || !def->host || def->port == 0u) {
        return SC_ERR_INVALID_ARG;
    }
    if (def->inject_drop_permille > 1000u || def->batch_packets > SC_UDP_DISPLAY_MAX_BATCH) {
        return SC_ERR_RANGE;
    }
    u->inject_drop_permille = def->inject_drop_permille;
    u->batch = def->batch_packets ? def->batch_packets : SC_UDP_DISPLAY_DEFAULT_BATCH;
    /* Each slot's message points at its own packet for good: queueing only sets a length. The
     * socket is connected, so no msg_name. */
    for (uint32_t i = 0; i < SC_UDP_DISPLAY_MAX_BATCH; i++) {
        u->q_iov[i].iov_base = u->q_pkt[i];
        u->q_msg[i].msg_hdr.msg_iov = &u->q_iov[i];
        u->q_msg[i].msg_hdr.msg_iovlen = 1;
    }
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

/* Every send: never block the frame loop, never raise SIGPIPE. */
#define SEND_FLAGS (MSG_DONTWAIT | MSG_NOSIGNAL)

/* Account one packet the kernel took (ok) or did not. Every queued line is of the open frame:
 * the batch is emptied before a frame starts. */
static void account(sc_udp_display *u, uint8_t type, int ok)
{
    if (ok) {
        u->packets_sent++;
    } else {
        u->send_errors++;
    }
    if (type == SC_DLINK_LINE) {
        if (ok) {
            u->lines_sent++;
            u->frame_sent++;
        } else {
            u->lines_dropped++;
            u->frame_dropped++;
        }
    }
}

/* Hand the batch to the kernel in one system call (send() for a single packet, sendmmsg()
 * otherwise) and empty it; what the kernel did not take is dropped, never retried. 0 (all
 * taken: link up), SC_ERR_WOULD_BLOCK (refused at once for a full socket buffer: link state
 * kept) or SC_ERR_IO (refused at once for another reason, or only the first part taken: link
 * down). */
static int flush(sc_udp_display *u)
{
    const uint32_t q = u->queued;
    if (q == 0u) {
        return 0;
    }
    u->queued = 0;
    u->q_lines = 0;
    u->send_calls++;
    int taken; /* packets taken, from the first; -1: none, the reason in err */
    int err = 0;
    if (q == 1u) {
        const ssize_t n = send(u->fd, u->q_pkt[0], u->q_iov[0].iov_len, SEND_FLAGS);
        taken = n == (ssize_t)u->q_iov[0].iov_len ? 1 : -1;
        if (taken < 0) {
            err = n < 0 ? errno : EMSGSIZE; /* a short datagram cannot happen: say so if it does */
        }
    } else {
        taken = sendmmsg(u->fd, u->q_msg, q, SEND_FLAGS);
        if (taken < 0) {
            err = errno;
        }
    }
    const uint32_t ok = taken > 0 ? (uint32_t)taken : 0u;
    for (uint32_t i = 0; i < q; i++) {
        account(u, u->q_type[i], i < ok);
    }
    if (ok == q) {
        u->up = 1;
        return 0;
    }
    if (taken < 0) {
        u->last_errno = err;
        if (err == EAGAIN || err == EWOULDBLOCK || err == ENOBUFS) {
            return SC_ERR_WOULD_BLOCK;
        }
    }
    /* A partial sendmmsg drops the error of the packet that failed: on loopback that is how a
     * refused destination shows (its ICMP error arrives while the batch goes out), so it must
     * read as down like any other error. */
    u->up = 0;
    return SC_ERR_IO;
}

/* Add the packet encoded in the next slot (len bytes) to the batch. */
static void push(sc_udp_display *u, uint8_t type, int len)
{
    const uint32_t i = u->queued;
    u->q_type[i] = type;
    u->q_iov[i].iov_len = (size_t)len;
    u->queued = i + 1u;
    if (type == SC_DLINK_LINE) {
        u->q_lines++;
    }
}

/* Add it and send the batch if it is now full. */
static int queue(sc_udp_display *u, uint8_t type, int len)
{
    push(u, type, len);
    return u->queued >= u->batch ? flush(u) : 0;
}

static int udp_frame_begin(void *ctx, const sc_display_frame_info *info)
{
    sc_udp_display *u = ctx;
    int rc = 0;
    if (u->in_frame) {
        u->protocol_errors++; /* previous frame never ended: send what it queued, start over */
        rc = flush(u);
    }
    u->frame.frame_no = info->frame_no;
    u->frame.flags = info->flags;
    u->frame.line_count = info->lines;
    u->frame.samples = info->samples;
    u->frame.geometry_id = info->geometry_id;
    u->frame_sent = 0;
    u->frame_dropped = 0;
    const sc_dlink_begin b = {info->depth_mm, info->width_mm,
                              info->geometry_id == 1u ? info->radius_mm : 0.0f};
    int len = sc_dlink_encode_begin(u->q_pkt[u->queued], SC_DLINK_MAX_PACKET, &u->frame, &b);
    if (len < 0) {
        u->protocol_errors++;
        u->in_frame = 0;
        return len;
    }
    u->in_frame = 1;
    u->frames++;
    int rq = queue(u, SC_DLINK_FRAME_BEGIN, len);
    if (info->dynamic_range_db > 0.0f) {
        /* the display's imaging parameters (FRAME_PARAMS, an additive extension) */
        sc_dlink_params p = {.gain_db = info->gain_db,
                             .dynamic_range_db = info->dynamic_range_db,
                             .focus_mm = info->focus_mm,
                             .frequency_mhz = info->frequency_mhz};
        for (uint32_t i = 0; i < SC_DLINK_PARAMS_TGC; i++) {
            p.tgc_db[i] = info->tgc_db[i];
        }
        len = sc_dlink_encode_params(u->q_pkt[u->queued], SC_DLINK_MAX_PACKET, &u->frame, &p);
        if (len > 0) {
            const int rp = queue(u, SC_DLINK_FRAME_PARAMS, len);
            rq = rq != 0 ? rq : rp;
        } else {
            u->protocol_errors++;
        }
    }
    return rq != 0 ? rq : rc;
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
    /* encoded straight into the next slot: queueing is not a copy */
    int len = sc_dlink_encode_line(u->q_pkt[u->queued], SC_DLINK_MAX_PACKET, &u->frame, line_index,
                                   samples, count);
    if (len < 0) {
        u->protocol_errors++;
        return len;
    }
    if (u->inject_drop_permille && xorshift32(&u->rng) % 1000u < u->inject_drop_permille) {
        u->lines_injected++; /* never queued: the slot is reused by the next packet */
        u->lines_sent++;
        u->frame_sent++;
        return 0;
    }
    return queue(u, SC_DLINK_LINE, len);
}

static int udp_frame_end(void *ctx, const sc_display_end_info *end)
{
    sc_udp_display *u = ctx;
    if (!end || !u->in_frame || end->frame_no != u->frame.frame_no) {
        u->protocol_errors++;
        return SC_ERR_STATE;
    }
    u->in_frame = 0;
    /* The counts as they will be if the batch goes whole. There is room: between calls the
     * batch holds at most batch - 1 packets. */
    const uint16_t vein_pm = sc_dlink_compression_pm(end->vein_area_ratio);
    const uint16_t artery_pm = sc_dlink_compression_pm(end->artery_area_ratio);
    const sc_dlink_end e = {(uint16_t)(u->frame_sent + u->q_lines), u->frame_dropped, vein_pm,
                            artery_pm};
    int len = sc_dlink_encode_end(u->q_pkt[u->queued], SC_DLINK_MAX_PACKET, &u->frame, &e);
    if (len < 0) {
        u->protocol_errors++;
        (void)flush(u); /* the lines still go: every line ends sent or dropped */
        return len;
    }
    push(u, SC_DLINK_FRAME_END, len);
    const int rc = flush(u);
    if (rc == 0) {
        return 0;
    }
    /* FRAME_END, last in the batch, was not taken: the receiver wants the frame's drop count
     * most when there were drops, so send it once more alone, with the exact counts. That
     * send only counts: the batch already set the link state. */
    const sc_dlink_end ex = {u->frame_sent, u->frame_dropped, vein_pm, artery_pm};
    len = sc_dlink_encode_end(u->q_pkt[0], SC_DLINK_MAX_PACKET, &u->frame, &ex);
    if (len < 0) {
        u->protocol_errors++;
        return rc;
    }
    u->send_calls++;
    const ssize_t n = send(u->fd, u->q_pkt[0], (size_t)len, SEND_FLAGS);
    if (n == (ssize_t)len) {
        u->packets_sent++;
    } else {
        u->send_errors++;
        u->last_errno = n < 0 ? errno : EMSGSIZE;
    }
    return rc;
}

static int udp_link_state(void *ctx, sc_display_link_state *st)
{
    sc_udp_display *u = ctx;
    st->up = u->up;
    st->lines_sent = (uint32_t)u->lines_sent;
    st->lines_dropped = (uint32_t)u->lines_dropped;
    return 0;
}

/* Colour Doppler (display link version 3): a colour line and the frame's record are queued
 * like lines; a version-2 receiver refuses them by name and keeps the B-scan. */
static int udp_colour_line(void *ctx, uint32_t frame_no, uint16_t line_index, uint16_t first,
                           const int8_t *values, uint16_t count)
{
    sc_udp_display *u = ctx;
    if (!u->in_frame || frame_no != u->frame.frame_no) {
        u->protocol_errors++;
        return SC_ERR_STATE;
    }
    int len = sc_dlink_encode_colour(u->q_pkt[u->queued], SC_DLINK_MAX_PACKET, &u->frame,
                                     line_index, first, values, count);
    if (len < 0) {
        u->protocol_errors++;
        return len;
    }
    return queue(u, SC_DLINK_COLOUR_LINE, len);
}

static int udp_doppler(void *ctx, const sc_display_doppler_info *info)
{
    sc_udp_display *u = ctx;
    if (!info || !u->in_frame || info->frame_no != u->frame.frame_no ||
        info->spectrum_bins > SC_DLINK_SPECTRUM_MAX ||
        (info->spectrum_bins > 0u && info->spectrum == NULL)) {
        u->protocol_errors++;
        return SC_ERR_STATE;
    }
    sc_dlink_doppler d = {
        .box_line_lo = info->box_line_lo,
        .box_line_hi = info->box_line_hi,
        .box_sample_lo = info->box_sample_lo,
        .box_sample_hi = info->box_sample_hi,
        .nyquist_mm_s = info->nyquist_mm_s,
        .steer_deg = info->steer_deg,
        .gate_velocity_mm_s = info->gate_velocity_mm_s,
        .gate_line = info->gate_line,
        .gate_sample_lo = info->gate_sample_lo,
        .gate_sample_hi = info->gate_sample_hi,
        .bins = info->spectrum_bins,
    };
    if (info->spectrum_bins > 0u) {
        memcpy(d.spectrum, info->spectrum, info->spectrum_bins);
    }
    int len = sc_dlink_encode_doppler(u->q_pkt[u->queued], SC_DLINK_MAX_PACKET, &u->frame, &d);
    if (len < 0) {
        u->protocol_errors++;
        return len;
    }
    return queue(u, SC_DLINK_DOPPLER, len);
}

static const sc_display_ops k_udp_ops = {udp_frame_begin, udp_line,        udp_frame_end,
                                         udp_link_state,  udp_colour_line, udp_doppler};

sc_display_dev sc_udp_display_dev(sc_udp_display *u)
{
    sc_display_dev d = {&k_udp_ops, u};
    return d;
}

void sc_udp_display_close(sc_udp_display *u)
{
    /* A frame left open: its queued lines never reach the socket, so they count as dropped. */
    for (uint32_t i = 0; i < u->queued; i++) {
        if (u->q_type[i] == SC_DLINK_LINE) {
            u->lines_dropped++;
            u->frame_dropped++;
        }
    }
    u->queued = 0;
    u->q_lines = 0;
    u->in_frame = 0;
    if (u->fd >= 0) {
        close(u->fd);
        u->fd = -1;
    }
    u->up = 0;
}
