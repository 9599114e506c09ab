/*
 * sc_udp_state.h: the state stream's Linux sink (hal/sc_hal_state.h): each record the engine
 * hands over leaves as one UDP datagram (MSG_DONTWAIT) to the console gateway, localhost by
 * default, like the display link. Never blocks: a datagram the kernel does not take is
 * dropped and counted. Not thread-safe (the engine's thread owns it).
 */
#ifndef SC_UDP_STATE_H
#define SC_UDP_STATE_H

#include <stdint.h>

#include "sc_hal_state.h"

typedef struct sc_udp_state {
    int fd;
    int last_errno;
    uint64_t sent;
    uint64_t dropped;
} sc_udp_state;

/* Resolve host (name or IPv4) and connect a UDP socket to host:port. 0, SC_ERR_INVALID_ARG
 * (NULL, port 0), SC_ERR_NOT_FOUND (host does not resolve), SC_ERR_IO (socket). */
int sc_udp_state_open(sc_udp_state *u, const char *host, uint16_t port);
sc_state_dev sc_udp_state_dev(sc_udp_state *u);
void sc_udp_state_close(sc_udp_state *u);

/* "HOST:PORT" or "PORT" (host 127.0.0.1) into host (cap bytes) and *port. 0 or -1. */
int sc_udp_parse_target(const char *s, char *host, unsigned cap, uint16_t *port);

#endif /* SC_UDP_STATE_H */
