/*
 * sc_cmdsign.h: the sending side of authenticated commands (core/link/sc_secoc.h) for Linux
 * programs: the tracker emulator, the bench tools, the host-simulator tests. One sc_cmdsign per
 * sender: its id, the appliance's key, its freshness counter and the E2E counters of the five
 * command messages. Each secured command is two classic frames: the command (E2E-protected)
 * and its cryptographic PDU (the low 16 bits of the freshness value and the 40-bit truncated
 * AES-CMAC). The MAC is computed with Mbed TLS (mbedtls_cipher_cmac) where the build found it
 * (SC_HAVE_MBEDTLS), else with the core's sc_cmac; test_sc_aes_cmac checks both agree.
 *
 * Freshness (sc_secoc.h): +1 per secured command; a sync takes max(last + 1, fv_clock) so that
 * a sender started long before the engine, or restarted, is still above the engine's floor.
 * fv_clock comes from sc_cmdsign_fv_now() (CLOCK_REALTIME in microseconds) or, for
 * deterministic tests, is fixed at init (clock_fv 0: no clock).
 * Never allocates. Not thread-safe (one sender, one thread).
 */
#ifndef SC_CMDSIGN_H
#define SC_CMDSIGN_H

#include <stdint.h>

#include "sc_canproto.h"
#include "sc_e2e.h"
#include "sc_hal_can.h"
#include "sc_secoc.h"

typedef struct sc_cmdsign {
    uint8_t key[SC_AES128_KEY_BYTES];
    sc_cmac_key ck;    /* the core's CMAC (used when Mbed TLS is absent) */
    uint8_t sender;    /* 0..SC_SECOC_SENDERS-1 */
    uint8_t use_clock; /* syncs jump to the wall clock */
    uint64_t fv;       /* last freshness value used */
    sc_e2e_tx tx[SC_CMD_MSGS];
} sc_cmdsign;

/* key, sender id 0..SC_SECOC_SENDERS-1, the first freshness value minus one (fv_start), and
 * whether syncs follow the wall clock. SC_ERR_RANGE for a sender id out of range. */
int sc_cmdsign_init(sc_cmdsign *s, const uint8_t key[SC_AES128_KEY_BYTES], uint8_t sender,
                    uint64_t fv_start, int use_clock);
/* CLOCK_REALTIME in microseconds (the freshness clock of the Linux senders and of the
 * appliance's floor). */
uint64_t sc_cmdsign_fv_now(void);
/* The two frames of a secured command (out[0] the command, out[1] its cryptographic PDU).
 * Errors of sc_canproto_encode_cmd; SC_ERR_INVALID_ARG for SC_CMD_SYNC_FRESHNESS (use
 * sc_cmdsign_sync). */
int sc_cmdsign_command(sc_cmdsign *s, const sc_cmd *c, sc_can_frame out[2]);
/* The two frames of a CmdFreshnessSync. */
int sc_cmdsign_sync(sc_cmdsign *s, sc_can_frame out[2]);
/* The full AES-CMAC of msg with key, by Mbed TLS when built with it, else by sc_cmac. 0 or
 * SC_ERR_IO (Mbed TLS refused). */
int sc_cmdsign_cmac(const uint8_t key[SC_AES128_KEY_BYTES], const uint8_t *msg, size_t len,
                    uint8_t mac[SC_AES_BLOCK_BYTES]);
/* 1 when the MAC comes from Mbed TLS. */
int sc_cmdsign_uses_mbedtls(void);
/* Parses 32 hex digits into a key: 0 or SC_ERR_CFG_VALUE. */
int sc_cmdsign_parse_key(const char *hex, uint8_t key[SC_AES128_KEY_BYTES]);

#endif /* SC_CMDSIGN_H */
