/*
 * sc_secoc.h: authentication of command frames in the manner of AUTOSAR SecOC (Secure Onboard
 * Communication): a truncated AES-CMAC (sc_aes_cmac.h) over the command and a freshness value.
 *
 * Frame layout (docs/can-protocol.md, config/sonocomp.dbc): classic CAN has no room beside a
 * command's signals, so every command travels as a "secured PDU collection": the command frame
 * itself (the authentic PDU, unchanged, E2E-protected, ids 0x080..0x084) followed by its
 * cryptographic PDU (id + 8: 0x088..0x08C), 8 bytes, Intel order:
 *   byte 0 [3:0]  SenderId    0..15 (the engine keeps freshness for ids < SC_SECOC_SENDERS)
 *   byte 0 [7:4]  Link        the authentic PDU's E2E counter: ties the two frames
 *   bytes 1..2    Freshness   the sender's freshness value, low 16 bits
 *   bytes 3..7    Mac         the first 40 bits of AES-CMAC(key, DataID (2 bytes, big-endian)
 *                             || authentic PDU (8 bytes, with its E2E header) || SenderId
 *                             (1 byte) || full freshness value (8 bytes, big-endian))
 *
 * Freshness: each sender keeps a 64-bit counter, +1 per secured command (never reused; the
 * Linux senders start it from the wall clock so that it also grows across their restarts).
 * The receiver keeps the full value of the last accepted command per sender and rebuilds the
 * sent value as the smallest value above it whose low 16 bits match; it accepts a command
 * when that step is 1..window (window - 1 commands of the sender may have been lost) and the
 * MAC verifies, and then stores the new value. A replayed or older value lands a whole 2^16
 * (or more) ahead: "stale". Resynchronisation: a sender that starts, or whose commands come
 * back stale or not synced, sends CmdFreshnessSync (0x084), whose authentic PDU carries the
 * freshness value's bits 16..63 and whose cryptographic PDU the low 16 bits: accepted when its
 * MAC verifies and the full value is above the last accepted one of that sender (and above
 * fv_floor); any forward jump is allowed. A sender with no accepted sync since the engine
 * started is "not synced": its commands are refused. fv_floor, set by the platform, refuses
 * values at or below it for every sender (the Linux appliance: the wall-clock value of the
 * engine's start minus a tolerance, so that a recording made before it cannot be replayed).
 *
 * Thread and memory rules: plain functions on caller-owned state; never allocates, never calls
 * the OS; deterministic. sizeof(sc_secoc_rx) = 256 bytes (the expanded key, 4 senders).
 */
#ifndef SC_SECOC_H
#define SC_SECOC_H

#include <stdint.h>

#include "sc_aes_cmac.h"
#include "sc_config.h" /* SC_SECOC_SENDERS */

#define SC_SECOC_MAX_SENDER_ID  15u
#define SC_SECOC_FV_TRUNC_BITS  16u
#define SC_SECOC_MAC_BYTES      5u /* 40-bit truncated MAC */
#define SC_SECOC_AUTH_PDU_BYTES 8u
#define SC_SECOC_INPUT_BYTES    19u /* data id 2 + authentic PDU 8 + sender 1 + freshness 8 */
#define SC_SECOC_DEFAULT_WINDOW 1024u
#define SC_SECOC_MAX_WINDOW     32768u /* half the truncated range: rebuilding stays unique */

/* The decoded cryptographic PDU. */
typedef struct sc_secoc_auth {
    uint8_t sender; /* 0..15 */
    uint8_t link;   /* the authentic PDU's E2E counter, 0..15 */
    uint16_t fv_low;
    uint8_t mac[SC_SECOC_MAC_BYTES];
} sc_secoc_auth;

/* The bytes the MAC covers (layout above). O(1). Cannot fail. */
void sc_secoc_input(uint16_t data_id, const uint8_t pdu[8], uint8_t sender, uint64_t fv,
                    uint8_t out[SC_SECOC_INPUT_BYTES]);
/* Cryptographic PDU <-> fields. O(1). encode masks sender and link to 4 bits. */
void sc_secoc_auth_encode(const sc_secoc_auth *a, uint8_t out[SC_SECOC_AUTH_PDU_BYTES]);
void sc_secoc_auth_decode(const uint8_t in[SC_SECOC_AUTH_PDU_BYTES], sc_secoc_auth *a);
/* Sender side with the core's CMAC: the cryptographic PDU of authentic PDU `pdu` (its E2E
 * counter, byte 1 bits 0..3, becomes the link). O(1) (2 AES blocks + subkeys precomputed). */
void sc_secoc_sign(const sc_cmac_key *k, uint16_t data_id, const uint8_t pdu[8], uint8_t sender,
                   uint64_t fv, uint8_t auth_pdu[SC_SECOC_AUTH_PDU_BYTES]);

/* Receiver definition: plain data, validated by sc_secoc_rx_init. */
typedef struct sc_secoc_def {
    uint8_t key[SC_AES128_KEY_BYTES]; /* the appliance's command key */
    uint32_t window;                  /* 1..SC_SECOC_MAX_WINDOW */
    uint64_t fv_floor;                /* freshness values <= this are stale for every sender */
} sc_secoc_def;

/* The documented bench key (docs/can-protocol.md): the ASCII bytes "sonocomp-bench-1".
 * For the host simulator, the bench and tests; an appliance configures its own. */
extern const uint8_t sc_secoc_bench_key[SC_AES128_KEY_BYTES];

/* Bench key, window SC_SECOC_DEFAULT_WINDOW, no floor. O(1). */
sc_secoc_def sc_secoc_default_def(void);

typedef enum sc_secoc_result {
    SC_SECOC_OK = 0,         /* MAC verified, freshness new: the command may be applied */
    SC_SECOC_UNKNOWN_SENDER, /* sender id >= SC_SECOC_SENDERS */
    SC_SECOC_NOT_SYNCED,     /* no sync accepted from this sender yet */
    SC_SECOC_STALE,          /* freshness not in (last, last + window] (replayed, too old) */
    SC_SECOC_BAD_MAC,        /* wrong key, altered frame, forged */
    SC_SECOC_RESULT_COUNT
} sc_secoc_result;

const char *sc_secoc_result_name(sc_secoc_result r);

typedef struct sc_secoc_rx {
    sc_cmac_key key;
    uint32_t window;
    uint8_t synced[SC_SECOC_SENDERS];
    uint64_t fv_floor;
    uint64_t last_fv[SC_SECOC_SENDERS]; /* full value of the last accepted command */
} sc_secoc_rx;

/* SC_ERR_RANGE for a window outside 1..SC_SECOC_MAX_WINDOW. Expands the key. O(1). */
int sc_secoc_rx_init(sc_secoc_rx *rx, const sc_secoc_def *def);

/* Verifies the authentic PDU `pdu` (8 bytes) of message data_id against its decoded
 * cryptographic PDU. sync_fv_high: NULL for a command; for CmdFreshnessSync a pointer to the
 * freshness bits 16..63 it carries. On SC_SECOC_OK the sender's freshness advances and
 * *fv_out (if not NULL) gets the full value. Nothing changes otherwise. O(1): at most one CMAC
 * of 2 blocks. Never allocates. */
sc_secoc_result sc_secoc_verify(sc_secoc_rx *rx, uint16_t data_id, const uint8_t pdu[8],
                                const sc_secoc_auth *auth, const uint64_t *sync_fv_high,
                                uint64_t *fv_out);

#endif /* SC_SECOC_H */
