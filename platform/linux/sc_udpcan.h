/*
 * sc_udpcan.h: CAN frames over UDP, for hosts without SocketCAN (this development host, CI
 * containers): the live host simulator (sc-hostsim --live --can-udp PORT) receives its bus
 * traffic this way from the tracker emulator (sc-tracker-emu --udp HOST:PORT) and the console
 * gateway (tools/gateway --can-udp HOST:PORT). On the appliance the same programs use
 * SocketCAN; this is a transport only: E2E protection and command authentication travel inside
 * the frames unchanged, so the engine checks them exactly as on a real bus.
 *
 * Datagram (little-endian, 76 bytes): u32 magic "SCCN", u32 id, u8 len (0..64, a valid CAN or
 * CAN FD length), u8 flags (SC_CAN_FLAG_*), u16 0, 64 data bytes (bytes past len zero).
 * Not thread-safe; never blocks (MSG_DONTWAIT both ways). The socket is one FIFO: receivers
 * that feed an engine put sc_can_rxmb.h's mailboxes in front of it (commands first, the newest
 * poses win).
 */
#ifndef SC_UDPCAN_H
#define SC_UDPCAN_H

#include <stddef.h>
#include <stdint.h>

#include "sc_hal_can.h"

#define SC_UDPCAN_MAGIC 0x4e434353u /* "SCCN" */
#define SC_UDPCAN_SIZE 76u

/* Encode f into out[SC_UDPCAN_SIZE]. SC_ERR_INVALID_ARG for a bad length. O(1). */
int sc_udpcan_encode(const sc_can_frame *f, uint8_t out[SC_UDPCAN_SIZE]);
/* Decode one datagram; SC_ERR_INVALID_ARG (NULL), SC_ERR_RANGE (size, magic, length, flags,
 * non-zero padding). O(1). */
int sc_udpcan_decode(const uint8_t *p, size_t n, sc_can_frame *out);

typedef struct sc_udpcan {
    int fd;
    int last_errno;
    uint64_t sent, send_failed, received, rejected;
} sc_udpcan;

/* A sender connected to host:port. 0, SC_ERR_NOT_FOUND, SC_ERR_IO. */
int sc_udpcan_open_tx(sc_udpcan *u, const char *host, uint16_t port);
/* A receiver bound to 127.0.0.1:port. 0, SC_ERR_IO (errno in last_errno). */
int sc_udpcan_open_rx(sc_udpcan *u, uint16_t port);
/* The device: send on a sender, recv on a receiver (the other answers SC_ERR_NOT_SUPPORTED). */
sc_can_dev sc_udpcan_dev(sc_udpcan *u);
void sc_udpcan_close(sc_udpcan *u);

#endif /* SC_UDPCAN_H */
