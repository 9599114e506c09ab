/* sc_udp_state.c: the state stream over UDP, see sc_udp_state.h. */
#include "sc_udp_state.h"

#include <errno.h>
#include <netdb.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "sc_err.h"
#include "sc_state.h"

int sc_udp_parse_target(const char *s, char *host, unsigned cap, uint16_t *port)
{
    if (s == NULL || host == NULL || port == NULL || cap < 2u) {
        return -1;
    }
    const char *colon = strrchr(s, ':');
    const char *ps = colon ? colon + 1 : s;
    size_t hl = colon ? (size_t)(colon - s) : 0u;
    if (colon == NULL) {
        snprintf(host, cap, "127.0.0.1");
    } else {
        if (hl == 0u || hl >= cap) {
            return -1;
        }
        memcpy(host, s, hl);
        host[hl] = '\0';
    }
    char *end;
    errno = 0;
    const unsigned long v = strtoul(ps, &end, 10);
    if (errno || end == ps || *end || v == 0u || v > 65535u || ps[0] == '-' || ps[0] == '+') {
        return -1;
    }
    *port = (uint16_t)v;
    return 0;
}

int sc_udp_state_open(sc_udp_state *u, const char *host, uint16_t port)
{
    if (u == NULL || host == NULL || port == 0u) {
        return SC_ERR_INVALID_ARG;
    }
    memset(u, 0, sizeof *u);
    u->fd = -1;
    char ps[8];
    snprintf(ps, sizeof ps, "%u", (unsigned)port);
    struct addrinfo hints = {.ai_family = AF_INET, .ai_socktype = SOCK_DGRAM}, *ai = NULL;
    if (getaddrinfo(host, ps, &hints, &ai) != 0 || ai == NULL) {
        return SC_ERR_NOT_FOUND;
    }
    u->fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (u->fd < 0 || connect(u->fd, ai->ai_addr, ai->ai_addrlen) != 0) {
        u->last_errno = errno;
        freeaddrinfo(ai);
        if (u->fd >= 0) {
            close(u->fd);
            u->fd = -1;
        }
        return SC_ERR_IO;
    }
    freeaddrinfo(ai);
    return SC_OK;
}

static int state_send(void *ctx, const uint8_t *rec, uint16_t len)
{
    sc_udp_state *u = ctx;
    if (u == NULL || rec == NULL || len == 0u || len > SC_STATE_RECORD_MAX) {
        return SC_ERR_INVALID_ARG;
    }
    /* a connected UDP socket with no listener reports ECONNREFUSED on a later send: that is
     * "no console right now", a drop like any other */
    if (send(u->fd, rec, len, MSG_DONTWAIT | MSG_NOSIGNAL) != (ssize_t)len) {
        u->last_errno = errno;
        u->dropped++;
        return (errno == EAGAIN || errno == EWOULDBLOCK) ? SC_ERR_WOULD_BLOCK : SC_ERR_IO;
    }
    u->sent++;
    return SC_OK;
}

sc_state_dev sc_udp_state_dev(sc_udp_state *u)
{
    static const sc_state_ops ops = {.send = state_send};
    return (sc_state_dev){.ops = &ops, .ctx = u};
}

void sc_udp_state_close(sc_udp_state *u)
{
    if (u != NULL && u->fd >= 0) {
        close(u->fd);
        u->fd = -1;
    }
}
