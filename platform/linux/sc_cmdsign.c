/* sc_cmdsign.c: signing commands on Linux (Mbed TLS AES-CMAC); see sc_cmdsign.h. */
#include "sc_cmdsign.h"

#include <string.h>
#include <time.h>

#include "sc_err.h"

#if SC_HAVE_MBEDTLS
#include <mbedtls/cipher.h>
#include <mbedtls/cmac.h>
#endif

int sc_cmdsign_uses_mbedtls(void)
{
    return SC_HAVE_MBEDTLS ? 1 : 0;
}

int sc_cmdsign_cmac(const uint8_t key[SC_AES128_KEY_BYTES], const uint8_t *msg, size_t len,
                    uint8_t mac[SC_AES_BLOCK_BYTES])
{
#if SC_HAVE_MBEDTLS
    const mbedtls_cipher_info_t *info = mbedtls_cipher_info_from_type(MBEDTLS_CIPHER_AES_128_ECB);
    if (info == NULL || mbedtls_cipher_cmac(info, key, 128, msg, len, mac) != 0) {
        return SC_ERR_IO;
    }
    return SC_OK;
#else
    sc_cmac_key k;
    sc_cmac_key_init(&k, key);
    sc_cmac(&k, msg, len, mac);
    sc_cmac_key_wipe(&k);
    return SC_OK;
#endif
}

int sc_cmdsign_init(sc_cmdsign *s, const uint8_t key[SC_AES128_KEY_BYTES], uint8_t sender,
                    uint64_t fv_start, int use_clock)
{
    if (sender >= SC_SECOC_SENDERS) {
        return SC_ERR_RANGE;
    }
    memset(s, 0, sizeof(*s));
    memcpy(s->key, key, SC_AES128_KEY_BYTES);
    sc_cmac_key_init(&s->ck, key);
    s->sender = sender;
    s->fv = fv_start;
    s->use_clock = use_clock ? 1u : 0u;
    for (unsigned i = 0; i < SC_CMD_MSGS; i++) {
        sc_e2e_tx_init(&s->tx[i], sc_canproto_info((sc_msg)i)->data_id);
    }
    return SC_OK;
}

uint64_t sc_cmdsign_fv_now(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_REALTIME, &ts) != 0 || ts.tv_sec < 0) {
        return 0u;
    }
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

static int sign(sc_cmdsign *s, const sc_cmd *c, uint64_t fv, sc_can_frame out[2])
{
    const sc_msg m = sc_canproto_cmd_msg(c->kind);
    if (m == SC_MSG_COUNT) {
        return SC_ERR_INVALID_ARG;
    }
    int rc = sc_canproto_encode_cmd(c, s->tx[m].counter, &out[0]);
    if (rc != SC_OK) {
        return rc;
    }
    s->tx[m].counter = (uint8_t)((s->tx[m].counter + 1u) % SC_E2E_COUNTER_MOD);
    uint8_t in[SC_SECOC_INPUT_BYTES], mac[SC_AES_BLOCK_BYTES];
    sc_secoc_input(sc_canproto_info(m)->data_id, out[0].data, s->sender, fv, in);
    rc = sc_cmdsign_cmac(s->key, in, sizeof(in), mac);
    if (rc != SC_OK) {
        return rc;
    }
    sc_secoc_auth a = {.sender = s->sender,
                       .link = (uint8_t)(out[0].data[1] & 0x0Fu),
                       .fv_low = (uint16_t)(fv & 0xFFFFu)};
    memcpy(a.mac, mac, SC_SECOC_MAC_BYTES);
    out[1] = (sc_can_frame){.id = out[0].id + SC_CANID_AUTH_OFFSET, .len = 8};
    sc_secoc_auth_encode(&a, out[1].data);
    s->fv = fv;
    return SC_OK;
}

int sc_cmdsign_command(sc_cmdsign *s, const sc_cmd *c, sc_can_frame out[2])
{
    if (c->kind == SC_CMD_SYNC_FRESHNESS) {
        return SC_ERR_INVALID_ARG;
    }
    return sign(s, c, s->fv + 1u, out);
}

int sc_cmdsign_sync(sc_cmdsign *s, sc_can_frame out[2])
{
    uint64_t fv = s->fv + 1u;
    if (s->use_clock) {
        const uint64_t now = sc_cmdsign_fv_now();
        fv = now > fv ? now : fv;
    }
    const sc_cmd c = {.kind = SC_CMD_SYNC_FRESHNESS, .fv_high = fv >> SC_SECOC_FV_TRUNC_BITS};
    return sign(s, &c, fv, out);
}

int sc_cmdsign_parse_key(const char *hex, uint8_t key[SC_AES128_KEY_BYTES])
{
    if (hex == NULL || strlen(hex) != 2u * SC_AES128_KEY_BYTES) {
        return SC_ERR_CFG_VALUE;
    }
    for (unsigned i = 0; i < 2u * SC_AES128_KEY_BYTES; i++) {
        const char ch = hex[i];
        unsigned v;
        if (ch >= '0' && ch <= '9') {
            v = (unsigned)(ch - '0');
        } else if (ch >= 'a' && ch <= 'f') {
            v = (unsigned)(ch - 'a') + 10u;
        } else if (ch >= 'A' && ch <= 'F') {
            v = (unsigned)(ch - 'A') + 10u;
        } else {
            return SC_ERR_CFG_VALUE;
        }
        if (i % 2u == 0u) {
            key[i / 2u] = (uint8_t)(v << 4);
        } else {
            key[i / 2u] = (uint8_t)(key[i / 2u] | v);
        }
    }
    return SC_OK;
}
