/*
 * sc_udp_display.h: hal display (sc_hal_display.h) over the UDP display link
 * (docs/display-link.md): FRAME_BEGIN, one datagram per LINE, FRAME_END, to one destination.
 *
 * Every send is non-blocking (MSG_DONTWAIT on a connected datagram socket with a large send
 * buffer): one encode (O(samples)) and one sendto system call per line, nothing else, so a
 * line costs a bounded time however the network behaves. A full socket buffer drops the line
 * and counts it (lines_dropped, reported to the receiver in FRAME_END) and line() answers
 * SC_ERR_WOULD_BLOCK; a refused destination (ICMP port unreachable: no receiver yet) or
 * another socket error drops and counts too and answers SC_ERR_IO; the link reads "down"
 * until a send succeeds again.
 *
 * Loss injection (tests, bench): with inject_drop_permille > 0, that share of lines (chosen by
 * a deterministic xorshift32 from inject_seed) is not sent but reported as sent, exactly as if
 * the network had lost it; lines_injected counts them, so a receiver's lost-line count can be
 * checked against it.
 *
 * Allocation: none (the packet buffer is inside the struct). Threads: one caller.
 */
#ifndef SC_UDP_DISPLAY_H
#define SC_UDP_DISPLAY_H

#include <stdint.h>

#include "sc_dlink.h"
#include "sc_hal_display.h"

typedef struct sc_udp_display_def {
    const char *host; /* name or IPv4 address */
    uint16_t port;
    uint32_t sndbuf_bytes;         /* SO_SNDBUF request; 0: 1 MiB (room for a few whole frames) */
    uint32_t inject_drop_permille; /* 0..1000 */
    uint32_t inject_seed;          /* non-zero */
} sc_udp_display_def;

typedef struct sc_udp_display {
    int fd;
    int last_errno;
    uint8_t in_frame;
    uint8_t up;
    sc_dlink_frame frame;
    uint16_t frame_sent;
    uint16_t frame_dropped;
    uint16_t compression_pm; /* carried in FRAME_BEGIN */
    uint32_t inject_drop_permille;
    uint32_t rng;
    uint64_t frames;
    uint64_t lines_sent;     /* handed to the socket (including injected losses) */
    uint64_t lines_dropped;  /* socket full or error */
    uint64_t lines_injected; /* injected losses */
    uint64_t packets_sent;
    uint64_t send_errors;     /* sends that failed (any packet type) */
    uint64_t protocol_errors; /* calls out of order or with bad arguments */
    uint8_t pkt[SC_DLINK_MAX_PACKET];
} sc_udp_display;

sc_udp_display_def sc_udp_display_default_def(void);
/* Resolve, create and connect the socket. 0, SC_ERR_NOT_FOUND (host does not resolve),
 * SC_ERR_IO (socket error; errno in last_errno), SC_ERR_RANGE (drop permille above 1000). */
int sc_udp_display_open(sc_udp_display *u, const sc_udp_display_def *def);
sc_display_dev sc_udp_display_dev(sc_udp_display *u);
/* The vessels' compression measure (permille, or SC_DLINK_COMPRESSION_UNKNOWN) for the next
 * FRAME_BEGINs: hal frame info does not carry it. */
void sc_udp_display_set_compression(sc_udp_display *u, uint16_t compression_pm);
void sc_udp_display_close(sc_udp_display *u);

#endif /* SC_UDP_DISPLAY_H */
