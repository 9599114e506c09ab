/* sc_udpcan.c: CAN frames over UDP, see sc_udpcan.h. */
#include "sc_udpcan.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netdb.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "sc_err.h"

static int valid_len(uint8_t len, uint8_t flags)
{
    if (!(flags & SC_CAN_FLAG_FD)) {
        return len <= 8u;
    }
    static const uint8_t fd[] = {12, 16, 20, 24, 32, 48, 64};
    if (len <= 8u) {
        return 1;
    }
    for (size_t i = 0; i < sizeof fd; i++) {
        if (len == fd[i]) {
            return 1;
        }
    }
    return 0;
}

int sc_udpcan_encode(const sc_can_frame *f, uint8_t out[SC_UDPCAN_SIZE])
{
    if (f == NULL || out == NULL || !valid_len(f->len, f->flags)) {
        return SC_ERR_INVALID_ARG;
    }
    memset(out, 0, SC_UDPCAN_SIZE);
    const uint32_t m = SC_UDPCAN_MAGIC;
    for (int i = 0; i < 4; i++) {
        out[i] = (uint8_t)(m >> (8 * i));
        out[4 + i] = (uint8_t)(f->id >> (8 * i));
    }
    out[8] = f->len;
    out[9] = f->flags;
    memcpy(out + 12, f->data, f->len);
    return SC_OK;
}

int sc_udpcan_decode(const uint8_t *p, size_t n, sc_can_frame *out)
{
    if (p == NULL || out == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    if (n != SC_UDPCAN_SIZE) {
        return SC_ERR_RANGE;
    }
    uint32_t m = 0, id = 0;
    for (int i = 0; i < 4; i++) {
        m |= (uint32_t)p[i] << (8 * i);
        id |= (uint32_t)p[4 + i] << (8 * i);
    }
    const uint8_t len = p[8], flags = p[9];
    const uint8_t known = SC_CAN_FLAG_EXT | SC_CAN_FLAG_FD | SC_CAN_FLAG_BRS;
    if (m != SC_UDPCAN_MAGIC || (flags & (uint8_t)~known) != 0u || !valid_len(len, flags) ||
        p[10] != 0u || p[11] != 0u || id > ((flags & SC_CAN_FLAG_EXT) ? 0x1fffffffu : 0x7ffu)) {
        return SC_ERR_RANGE;
    }
    for (size_t i = 12u + len; i < SC_UDPCAN_SIZE; i++) {
        if (p[i] != 0u) {
            return SC_ERR_RANGE;
        }
    }
    memset(out, 0, sizeof *out);
    out->id = id;
    out->len = len;
    out->flags = flags;
    memcpy(out->data, p + 12, len);
    return SC_OK;
}

int sc_udpcan_open_tx(sc_udpcan *u, const char *host, uint16_t port)
{
    memset(u, 0, sizeof *u);
    u->fd = -1;
    char ps[8];
    snprintf(ps, sizeof ps, "%u", (unsigned)port);
    struct addrinfo hints = {.ai_family = AF_INET, .ai_socktype = SOCK_DGRAM}, *ai = NULL;
    if (host == NULL || port == 0u || getaddrinfo(host, ps, &hints, &ai) != 0 || ai == NULL) {
        return SC_ERR_NOT_FOUND;
    }
    u->fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    const int ok = u->fd >= 0 && connect(u->fd, ai->ai_addr, ai->ai_addrlen) == 0;
    u->last_errno = errno;
    freeaddrinfo(ai);
    return ok ? SC_OK : SC_ERR_IO;
}

int sc_udpcan_open_rx(sc_udpcan *u, uint16_t port)
{
    memset(u, 0, sizeof *u);
    u->fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons(port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (u->fd < 0 || bind(u->fd, (struct sockaddr *)&a, sizeof a) != 0) {
        u->last_errno = errno;
        return SC_ERR_IO;
    }
    int rcvbuf = 1 << 20;
    (void)setsockopt(u->fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    return SC_OK;
}

static int udpcan_send(void *ctx, const sc_can_frame *f)
{
    sc_udpcan *u = ctx;
    uint8_t b[SC_UDPCAN_SIZE];
    if (sc_udpcan_encode(f, b) != SC_OK) {
        return SC_ERR_INVALID_ARG;
    }
    if (send(u->fd, b, sizeof b, MSG_DONTWAIT | MSG_NOSIGNAL) != (ssize_t)sizeof b) {
        u->last_errno = errno;
        u->send_failed++;
        return (errno == EAGAIN || errno == EWOULDBLOCK) ? SC_ERR_WOULD_BLOCK : SC_ERR_IO;
    }
    u->sent++;
    return SC_OK;
}

static int udpcan_recv(void *ctx, sc_can_frame *out)
{
    sc_udpcan *u = ctx;
    for (int tries = 0; tries < 64; tries++) { /* bounded: malformed ones are skipped */
        uint8_t b[SC_UDPCAN_SIZE + 1u];
        const ssize_t n = recv(u->fd, b, sizeof b, MSG_DONTWAIT);
        if (n < 0) {
            return SC_ERR_WOULD_BLOCK;
        }
        if (sc_udpcan_decode(b, (size_t)n, out) == SC_OK) {
            u->received++;
            return SC_OK;
        }
        u->rejected++; /* malformed datagram: counted, skipped */
    }
    return SC_ERR_WOULD_BLOCK;
}

sc_can_dev sc_udpcan_dev(sc_udpcan *u)
{
    static const sc_can_ops ops = {.send = udpcan_send, .recv = udpcan_recv};
    return (sc_can_dev){.ops = &ops, .ctx = u};
}

void sc_udpcan_close(sc_udpcan *u)
{
    if (u != NULL && u->fd >= 0) {
        close(u->fd);
        u->fd = -1;
    }
}
