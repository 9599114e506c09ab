/*
 * sc_aes_cmac.h: AES-128 (encryption only, FIPS-197) and AES-CMAC (NIST SP 800-38B, RFC 4493):
 * the message authentication code of the command frames (sc_secoc.h).
 *
 * Why here and not a library: the core runs on the MCU too, without an OS or a heap, and
 * verifies a handful of 2-block MACs per second; a small, byte-oriented AES (S-box table, no
 * T-tables: 256 bytes of flash, no data-dependent table beyond the S-box) is enough. It is
 * checked against FIPS-197's example vector and RFC 4493's four CMAC vectors, and against Mbed
 * TLS on random keys and messages (tests/unit/test_sc_aes_cmac.c); the Linux tools sign with
 * Mbed TLS. Not hardened against cache-timing side channels (the S-box lookups): an attacker
 * on the CAN bus does not observe the engine's cache.
 *
 * Thread and memory rules: plain functions on caller-owned state; never allocates, never calls
 * the OS; deterministic. A key object holds the expanded key and the CMAC subkeys (208 bytes);
 * sc_cmac_key_wipe() clears it.
 */
#ifndef SC_AES_CMAC_H
#define SC_AES_CMAC_H

#include <stddef.h>
#include <stdint.h>

#define SC_AES_BLOCK_BYTES  16u
#define SC_AES128_KEY_BYTES 16u
#define SC_AES128_ROUNDS    10u

typedef struct sc_aes128 {
    uint8_t rk[(SC_AES128_ROUNDS + 1u) * SC_AES_BLOCK_BYTES]; /* round keys, 176 bytes */
} sc_aes128;

/* Key expansion. O(1) (40 words). Cannot fail. */
void sc_aes128_init(sc_aes128 *a, const uint8_t key[SC_AES128_KEY_BYTES]);
/* One block, in and out may alias. O(1) (10 rounds). Cannot fail. */
void sc_aes128_encrypt(const sc_aes128 *a, const uint8_t in[SC_AES_BLOCK_BYTES],
                       uint8_t out[SC_AES_BLOCK_BYTES]);

typedef struct sc_cmac_key {
    sc_aes128 aes;
    uint8_t k1[SC_AES_BLOCK_BYTES]; /* subkeys of SP 800-38B section 6.1 */
    uint8_t k2[SC_AES_BLOCK_BYTES];
} sc_cmac_key;

/* Expands the key and derives the subkeys. O(1). Cannot fail. */
void sc_cmac_key_init(sc_cmac_key *k, const uint8_t key[SC_AES128_KEY_BYTES]);
/* Overwrites the key material with zeros. O(1). */
void sc_cmac_key_wipe(sc_cmac_key *k);
/* The full 16-byte AES-CMAC of msg[0..len-1] (len may be 0). O(len / 16 + 1) block
 * encryptions. Cannot fail. */
void sc_cmac(const sc_cmac_key *k, const uint8_t *msg, size_t len, uint8_t mac[SC_AES_BLOCK_BYTES]);
/* Compares the first n bytes of a computed and a received MAC in time independent of where
 * they differ: 1 when equal. O(n). */
int sc_mac_equal(const uint8_t *a, const uint8_t *b, size_t n);

#endif /* SC_AES_CMAC_H */
