/* sc_aes_cmac.c: AES-128 encryption (FIPS-197) and AES-CMAC (RFC 4493); see sc_aes_cmac.h. */
#include "sc_aes_cmac.h"

#include <string.h>

_Static_assert(sizeof(sc_cmac_key) == 208u, "sc_cmac_key: 176 B round keys + 2 subkeys");

/* FIPS-197 figure 7. */
static const uint8_t k_sbox[256] = {
    0x63, 0x7c, 0x77, 0x7b, 0xf2, 0x6b, 0x6f, 0xc5, 0x30, 0x01, 0x67, 0x2b, 0xfe, 0xd7, 0xab, 0x76,
    0xca, 0x82, 0xc9, 0x7d, 0xfa, 0x59, 0x47, 0xf0, 0xad, 0xd4, 0xa2, 0xaf, 0x9c, 0xa4, 0x72, 0xc0,
    0xb7, 0xfd, 0x93, 0x26, 0x36, 0x3f, 0xf7, 0xcc, 0x34, 0xa5, 0xe5, 0xf1, 0x71, 0xd8, 0x31, 0x15,
    0x04, 0xc7, 0x23, 0xc3, 0x18, 0x96, 0x05, 0x9a, 0x07, 0x12, 0x80, 0xe2, 0xeb, 0x27, 0xb2, 0x75,
    0x09, 0x83, 0x2c, 0x1a, 0x1b, 0x6e, 0x5a, 0xa0, 0x52, 0x3b, 0xd6, 0xb3, 0x29, 0xe3, 0x2f, 0x84,
    0x53, 0xd1, 0x00, 0xed, 0x20, 0xfc, 0xb1, 0x5b, 0x6a, 0xcb, 0xbe, 0x39, 0x4a, 0x4c, 0x58, 0xcf,
    0xd0, 0xef, 0xaa, 0xfb, 0x43, 0x4d, 0x33, 0x85, 0x45, 0xf9, 0x02, 0x7f, 0x50, 0x3c, 0x9f, 0xa8,
    0x51, 0xa3, 0x40, 0x8f, 0x92, 0x9d, 0x38, 0xf5, 0xbc, 0xb6, 0xda, 0x21, 0x10, 0xff, 0xf3, 0xd2,
    0xcd, 0x0c, 0x13, 0xec, 0x5f, 0x97, 0x44, 0x17, 0xc4, 0xa7, 0x7e, 0x3d, 0x64, 0x5d, 0x19, 0x73,
    0x60, 0x81, 0x4f, 0xdc, 0x22, 0x2a, 0x90, 0x88, 0x46, 0xee, 0xb8, 0x14, 0xde, 0x5e, 0x0b, 0xdb,
    0xe0, 0x32, 0x3a, 0x0a, 0x49, 0x06, 0x24, 0x5c, 0xc2, 0xd3, 0xac, 0x62, 0x91, 0x95, 0xe4, 0x79,
    0xe7, 0xc8, 0x37, 0x6d, 0x8d, 0xd5, 0x4e, 0xa9, 0x6c, 0x56, 0xf4, 0xea, 0x65, 0x7a, 0xae, 0x08,
    0xba, 0x78, 0x25, 0x2e, 0x1c, 0xa6, 0xb4, 0xc6, 0xe8, 0xdd, 0x74, 0x1f, 0x4b, 0xbd, 0x8b, 0x8a,
    0x70, 0x3e, 0xb5, 0x66, 0x48, 0x03, 0xf6, 0x0e, 0x61, 0x35, 0x57, 0xb9, 0x86, 0xc1, 0x1d, 0x9e,
    0xe1, 0xf8, 0x98, 0x11, 0x69, 0xd9, 0x8e, 0x94, 0x9b, 0x1e, 0x87, 0xe9, 0xce, 0x55, 0x28, 0xdf,
    0x8c, 0xa1, 0x89, 0x0d, 0xbf, 0xe6, 0x42, 0x68, 0x41, 0x99, 0x2d, 0x0f, 0xb0, 0x54, 0xbb, 0x16,
};

/* multiplication by x in GF(2^8) mod x^8 + x^4 + x^3 + x + 1 */
static uint8_t xtime(uint8_t v)
{
    return (uint8_t)((uint8_t)(v << 1) ^ ((v & 0x80u) ? 0x1bu : 0x00u));
}

void sc_aes128_init(sc_aes128 *a, const uint8_t key[SC_AES128_KEY_BYTES])
{
    memcpy(a->rk, key, SC_AES128_KEY_BYTES);
    uint8_t rcon = 0x01u;
    for (unsigned i = 4u; i < 4u * (SC_AES128_ROUNDS + 1u); i++) {
        uint8_t t[4];
        memcpy(t, &a->rk[(i - 1u) * 4u], 4u);
        if (i % 4u == 0u) { /* RotWord, SubWord, Rcon */
            const uint8_t t0 = t[0];
            t[0] = (uint8_t)(k_sbox[t[1]] ^ rcon);
            t[1] = k_sbox[t[2]];
            t[2] = k_sbox[t[3]];
            t[3] = k_sbox[t0];
            rcon = xtime(rcon);
        }
        for (unsigned j = 0; j < 4u; j++) {
            a->rk[i * 4u + j] = (uint8_t)(a->rk[(i - 4u) * 4u + j] ^ t[j]);
        }
    }
}

static void add_round_key(uint8_t s[16], const uint8_t *rk)
{
    for (unsigned i = 0; i < 16u; i++) {
        s[i] = (uint8_t)(s[i] ^ rk[i]);
    }
}

/* SubBytes and ShiftRows together; the state is column-major (s[4c + r]). */
static void sub_shift(uint8_t s[16])
{
    uint8_t t[16];
    for (unsigned c = 0; c < 4u; c++) {
        for (unsigned r = 0; r < 4u; r++) {
            t[4u * c + r] = k_sbox[s[4u * ((c + r) % 4u) + r]];
        }
    }
    memcpy(s, t, 16u);
}

static void mix_columns(uint8_t s[16])
{
    for (unsigned c = 0; c < 4u; c++) {
        uint8_t *col = &s[4u * c];
        const uint8_t a0 = col[0], a1 = col[1], a2 = col[2], a3 = col[3];
        const uint8_t all = (uint8_t)(a0 ^ a1 ^ a2 ^ a3);
        col[0] = (uint8_t)(a0 ^ all ^ xtime((uint8_t)(a0 ^ a1)));
        col[1] = (uint8_t)(a1 ^ all ^ xtime((uint8_t)(a1 ^ a2)));
        col[2] = (uint8_t)(a2 ^ all ^ xtime((uint8_t)(a2 ^ a3)));
        col[3] = (uint8_t)(a3 ^ all ^ xtime((uint8_t)(a3 ^ a0)));
    }
}

void sc_aes128_encrypt(const sc_aes128 *a, const uint8_t in[SC_AES_BLOCK_BYTES],
                       uint8_t out[SC_AES_BLOCK_BYTES])
{
    uint8_t s[16];
    memcpy(s, in, 16u);
    add_round_key(s, &a->rk[0]);
    for (unsigned round = 1u; round < SC_AES128_ROUNDS; round++) {
        sub_shift(s);
        mix_columns(s);
        add_round_key(s, &a->rk[16u * round]);
    }
    sub_shift(s);
    add_round_key(s, &a->rk[16u * SC_AES128_ROUNDS]);
    memcpy(out, s, 16u);
}

/* Left shift of a 128-bit big-endian string by one bit, XOR Rb = 0x87 when the MSB was set. */
static void dbl(const uint8_t in[16], uint8_t out[16])
{
    const uint8_t msb = (uint8_t)(in[0] >> 7);
    for (unsigned i = 0; i < 15u; i++) {
        out[i] = (uint8_t)((uint8_t)(in[i] << 1) | (uint8_t)(in[i + 1u] >> 7));
    }
    out[15] = (uint8_t)((uint8_t)(in[15] << 1) ^ (msb ? 0x87u : 0x00u));
}

void sc_cmac_key_init(sc_cmac_key *k, const uint8_t key[SC_AES128_KEY_BYTES])
{
    sc_aes128_init(&k->aes, key);
    uint8_t l[16] = {0};
    sc_aes128_encrypt(&k->aes, l, l);
    dbl(l, k->k1);
    dbl(k->k1, k->k2);
    memset(l, 0, sizeof(l));
}

void sc_cmac_key_wipe(sc_cmac_key *k)
{
    volatile uint8_t *p = (volatile uint8_t *)k;
    for (size_t i = 0; i < sizeof(*k); i++) {
        p[i] = 0u;
    }
}

void sc_cmac(const sc_cmac_key *k, const uint8_t *msg, size_t len, uint8_t mac[SC_AES_BLOCK_BYTES])
{
    /* n blocks, the last one complete or padded (10*); an empty message is one padded block */
    const size_t n = len == 0u ? 1u : (len + 15u) / 16u;
    const int last_complete = len != 0u && len % 16u == 0u;
    uint8_t x[16] = {0};
    for (size_t b = 0; b + 1u < n; b++) {
        for (unsigned i = 0; i < 16u; i++) {
            x[i] = (uint8_t)(x[i] ^ msg[16u * b + i]);
        }
        sc_aes128_encrypt(&k->aes, x, x);
    }
    const size_t off = 16u * (n - 1u);
    const size_t rem = len - off;
    uint8_t last[16] = {0};
    memcpy(last, msg == NULL ? last : msg + off, msg == NULL ? 0u : rem);
    if (!last_complete) {
        last[rem] = 0x80u;
    }
    const uint8_t *sub = last_complete ? k->k1 : k->k2;
    for (unsigned i = 0; i < 16u; i++) {
        x[i] = (uint8_t)(x[i] ^ last[i] ^ sub[i]);
    }
    sc_aes128_encrypt(&k->aes, x, mac);
}

int sc_mac_equal(const uint8_t *a, const uint8_t *b, size_t n)
{
    uint8_t d = 0;
    for (size_t i = 0; i < n; i++) {
        d = (uint8_t)(d | (a[i] ^ b[i]));
    }
    return d == 0u;
}
