/*
 * sc_udp_display.h: hal display (sc_hal_display.h) over the UDP display link
 * (docs/display-link.md): FRAME_BEGIN, one datagram per LINE, FRAME_END, to one destination.
 *
 * Batching: the packets of a frame are encoded into a batch inside the struct (batch_packets
 * of them, at most SC_UDP_DISPLAY_MAX_BATCH) and handed to the kernel by one sendmmsg system
 * call when the batch is full and at frame_end (FRAME_END travels in the last batch), so a
 * frame of 256 lines costs 9 system calls at batch 32 instead of 258: the system call, not the
 * encode, was the cost of a line. The price is latency within the frame: a line leaves when
 * its batch does, at most batch_packets - 1 packets after it was given to line(); the frame as
 * a whole (FRAME_END, which the viewer waits for) leaves at frame_end as before. Packets leave
 * in call order (BEGIN, lines as given, END). batch_packets 1 sends each packet at its call
 * with one send(), the link before batching.
 *
 * Every send is non-blocking (MSG_DONTWAIT on a connected datagram socket with a large send
 * buffer), so each call costs a bounded time however the network behaves: frame_begin and
 * line encode one packet (O(samples)) and make at most one system call (a full batch);
 * frame_end at most two (the last batch, and FRAME_END again alone if the batch did not all
 * go). Packets the kernel does not take are dropped, never retried; dropped lines are counted
 * exactly (lines_dropped, reported to the receiver in FRAME_END):
 * - the send fails at once with a full socket buffer (EAGAIN, ENOBUFS): the batch is dropped,
 *   the call answers SC_ERR_WOULD_BLOCK, the link state is unchanged;
 * - it fails with another error, e.g. a refused destination (ICMP port unreachable: no
 *   receiver yet): the batch is dropped, the call answers SC_ERR_IO, the link reads "down";
 * - sendmmsg takes only the first part of the batch: it does not say why (the error of the
 *   first packet it could not send is lost), and on loopback a refused destination shows only
 *   this way (the ICMP error arrives while the batch is being sent), so the rest is dropped,
 *   the call answers SC_ERR_IO and the link reads "down" (the health fault it feeds means
 *   "down or dropping lines");
 * the link reads "up" again after a batch the kernel took whole. A call's error may be about
 * lines given in earlier calls of the frame (those in its batch). Between frame_begin and
 * frame_end, lines still in the batch are in neither lines_sent nor lines_dropped yet; after
 * frame_end every line is in one of them. FRAME_END carries the frame's counts as they will be
 * if its batch goes whole; when it does not, FRAME_END is re-encoded with the exact counts and
 * sent once more alone (that resend leaves the link state as the batch set it).
 *
 * Loss injection (tests, bench): with inject_drop_permille > 0, that share of lines (chosen by
 * a deterministic xorshift32 from inject_seed) is not sent (never queued) but reported as
 * sent, exactly as if the network had lost it; lines_injected counts them, so a receiver's
 * lost-line count can be checked against it.
 *
 * Allocation: none (the batch, its iovecs and mmsghdrs are inside the struct: about 40 KiB at
 * SC_UDP_DISPLAY_MAX_BATCH 64; make it static or part of a larger object). Threads: one
 * caller.
 */
#ifndef SC_UDP_DISPLAY_H
#define SC_UDP_DISPLAY_H

#ifndef _GNU_SOURCE
#error "sc_udp_display.h needs _GNU_SOURCE (struct mmsghdr): define it for the whole target"
#endif

#include <stdint.h>
#include <sys/socket.h>
#include <sys/uio.h>

#include "sc_dlink.h"
#include "sc_hal_display.h"

/* Packets per sendmmsg at most (the batch storage in sc_udp_display). */
#ifndef SC_UDP_DISPLAY_MAX_BATCH
#define SC_UDP_DISPLAY_MAX_BATCH 64u
#endif
#define SC_UDP_DISPLAY_DEFAULT_BATCH 32u
_Static_assert(SC_UDP_DISPLAY_MAX_BATCH >= 1u && SC_UDP_DISPLAY_MAX_BATCH <= 1024u,
               "sendmmsg takes at most UIO_MAXIOV (1024) messages");
_Static_assert(SC_UDP_DISPLAY_DEFAULT_BATCH <= SC_UDP_DISPLAY_MAX_BATCH, "default batch");

typedef struct sc_udp_display_def {
    const char *host; /* name or IPv4 address */
    uint16_t port;
    uint32_t sndbuf_bytes;         /* SO_SNDBUF request; 0: 1 MiB (room for a few whole frames) */
    uint32_t inject_drop_permille; /* 0..1000 */
    uint32_t inject_seed;          /* non-zero */
    uint32_t batch_packets;        /* packets per sendmmsg, 1 .. SC_UDP_DISPLAY_MAX_BATCH; 1: one
                                    * send() per packet; 0: SC_UDP_DISPLAY_DEFAULT_BATCH */
} sc_udp_display_def;

typedef struct sc_udp_display {
    int fd;
    int last_errno; /* of the last send that failed with a known error */
    uint8_t in_frame;
    uint8_t up;
    sc_dlink_frame frame;
    uint16_t frame_sent;
    uint16_t frame_dropped;
    uint32_t inject_drop_permille;
    uint32_t rng;
    uint32_t batch;   /* packets per system call */
    uint32_t queued;  /* packets in the batch, 0 .. batch - 1 between calls */
    uint32_t q_lines; /* of them LINE packets (all of the open frame) */
    uint64_t frames;
    uint64_t lines_sent;     /* taken by the kernel, plus injected losses */
    uint64_t lines_dropped;  /* not taken by the kernel (socket full or error), or discarded */
    uint64_t lines_injected; /* injected losses */
    uint64_t packets_sent;
    uint64_t send_errors;     /* packets the kernel did not take (any packet type) */
    uint64_t send_calls;      /* send / sendmmsg system calls */
    uint64_t protocol_errors; /* calls out of order or with bad arguments */
    uint8_t q_type[SC_UDP_DISPLAY_MAX_BATCH]; /* sc_dlink_type of each queued packet */
    struct iovec q_iov[SC_UDP_DISPLAY_MAX_BATCH];
    struct mmsghdr q_msg[SC_UDP_DISPLAY_MAX_BATCH];
    uint8_t q_pkt[SC_UDP_DISPLAY_MAX_BATCH][SC_DLINK_MAX_PACKET];
} sc_udp_display;

sc_udp_display_def sc_udp_display_default_def(void);
/* Resolve, create and connect the socket. 0, SC_ERR_INVALID_ARG (no def, host or port),
 * SC_ERR_NOT_FOUND (host does not resolve), SC_ERR_IO (socket error; errno in last_errno),
 * SC_ERR_RANGE (drop permille above 1000, batch above SC_UDP_DISPLAY_MAX_BATCH). */
int sc_udp_display_open(sc_udp_display *u, const sc_udp_display_def *def);
sc_display_dev sc_udp_display_dev(sc_udp_display *u);
/* Close the socket. Lines still in the batch (a frame left open) are counted dropped, not sent. */
void sc_udp_display_close(sc_udp_display *u);

#endif /* SC_UDP_DISPLAY_H */
