/* sc_secoc.c: SecOC-style command authentication; see sc_secoc.h. */
#include "sc_secoc.h"

#include <stddef.h>
#include <string.h>

#include "sc_err.h"

const uint8_t sc_secoc_bench_key[SC_AES128_KEY_BYTES] = {
    's', 'o', 'n', 'o', 'c', 'o', 'm', 'p', '-', 'b', 'e', 'n', 'c', 'h', '-', '1',
};

sc_secoc_def sc_secoc_default_def(void)
{
    sc_secoc_def d;
    memcpy(d.key, sc_secoc_bench_key, sizeof(d.key));
    d.window = SC_SECOC_DEFAULT_WINDOW;
    d.fv_floor = 0u;
    return d;
}

const char *sc_secoc_result_name(sc_secoc_result r)
{
    switch (r) {
    case SC_SECOC_OK:
        return "ok";
    case SC_SECOC_UNKNOWN_SENDER:
        return "unknown_sender";
    case SC_SECOC_NOT_SYNCED:
        return "not_synced";
    case SC_SECOC_STALE:
        return "stale";
    case SC_SECOC_BAD_MAC:
        return "bad_mac";
    case SC_SECOC_RESULT_COUNT:
        break;
    }
    return "?";
}

void sc_secoc_input(uint16_t data_id, const uint8_t pdu[8], uint8_t sender, uint64_t fv,
                    uint8_t out[SC_SECOC_INPUT_BYTES])
{
    out[0] = (uint8_t)(data_id >> 8);
    out[1] = (uint8_t)data_id;
    memcpy(&out[2], pdu, 8u);
    out[10] = sender;
    for (unsigned i = 0; i < 8u; i++) {
        out[11u + i] = (uint8_t)(fv >> (56u - 8u * i));
    }
}

void sc_secoc_auth_encode(const sc_secoc_auth *a, uint8_t out[SC_SECOC_AUTH_PDU_BYTES])
{
    out[0] = (uint8_t)((a->sender & 0x0Fu) | (uint8_t)((a->link & 0x0Fu) << 4));
    out[1] = (uint8_t)a->fv_low;
    out[2] = (uint8_t)(a->fv_low >> 8);
    memcpy(&out[3], a->mac, SC_SECOC_MAC_BYTES);
}

void sc_secoc_auth_decode(const uint8_t in[SC_SECOC_AUTH_PDU_BYTES], sc_secoc_auth *a)
{
    a->sender = (uint8_t)(in[0] & 0x0Fu);
    a->link = (uint8_t)(in[0] >> 4);
    a->fv_low = (uint16_t)(in[1] | (uint16_t)(in[2] << 8));
    memcpy(a->mac, &in[3], SC_SECOC_MAC_BYTES);
}

static void mac_of(const sc_cmac_key *k, uint16_t data_id, const uint8_t pdu[8], uint8_t sender,
                   uint64_t fv, uint8_t mac[SC_AES_BLOCK_BYTES])
{
    uint8_t in[SC_SECOC_INPUT_BYTES];
    sc_secoc_input(data_id, pdu, sender, fv, in);
    sc_cmac(k, in, sizeof(in), mac);
}

void sc_secoc_sign(const sc_cmac_key *k, uint16_t data_id, const uint8_t pdu[8], uint8_t sender,
                   uint64_t fv, uint8_t auth_pdu[SC_SECOC_AUTH_PDU_BYTES])
{
    uint8_t mac[SC_AES_BLOCK_BYTES];
    mac_of(k, data_id, pdu, sender, fv, mac);
    sc_secoc_auth a = {
        .sender = sender, .link = (uint8_t)(pdu[1] & 0x0Fu), .fv_low = (uint16_t)(fv & 0xFFFFu)};
    memcpy(a.mac, mac, SC_SECOC_MAC_BYTES);
    sc_secoc_auth_encode(&a, auth_pdu);
}

int sc_secoc_rx_init(sc_secoc_rx *rx, const sc_secoc_def *def)
{
    if (def->window < 1u || def->window > SC_SECOC_MAX_WINDOW) {
        return SC_ERR_RANGE;
    }
    memset(rx, 0, sizeof(*rx));
    sc_cmac_key_init(&rx->key, def->key);
    rx->window = def->window;
    rx->fv_floor = def->fv_floor;
    return SC_OK;
}

sc_secoc_result sc_secoc_verify(sc_secoc_rx *rx, uint16_t data_id, const uint8_t pdu[8],
                                const sc_secoc_auth *auth, const uint64_t *sync_fv_high,
                                uint64_t *fv_out)
{
    if (auth->sender >= SC_SECOC_SENDERS) {
        return SC_SECOC_UNKNOWN_SENDER;
    }
    const unsigned s = auth->sender;
    const uint64_t mask = ((uint64_t)1 << SC_SECOC_FV_TRUNC_BITS) - 1u;
    uint64_t fv;
    if (sync_fv_high != NULL) {
        /* resynchronisation: the full value travels; any step forward is accepted */
        if (*sync_fv_high > (UINT64_MAX >> SC_SECOC_FV_TRUNC_BITS)) {
            return SC_SECOC_STALE; /* unreachable with a 48-bit signal */
        }
        fv = (*sync_fv_high << SC_SECOC_FV_TRUNC_BITS) | auth->fv_low;
        const uint64_t last = rx->synced[s] ? rx->last_fv[s] : 0u;
        if (fv <= last || fv <= rx->fv_floor) {
            return SC_SECOC_STALE;
        }
    } else {
        if (!rx->synced[s]) {
            return SC_SECOC_NOT_SYNCED;
        }
        const uint64_t last = rx->last_fv[s];
        fv = (last & ~mask) | auth->fv_low;
        if (fv <= last) {
            if (last > UINT64_MAX - (mask + 1u)) {
                return SC_SECOC_STALE; /* the counter space is used up */
            }
            fv += mask + 1u;
        }
        if (fv - last > rx->window || fv <= rx->fv_floor) {
            return SC_SECOC_STALE;
        }
    }
    uint8_t mac[SC_AES_BLOCK_BYTES];
    mac_of(&rx->key, data_id, pdu, auth->sender, fv, mac);
    if (!sc_mac_equal(mac, auth->mac, SC_SECOC_MAC_BYTES)) {
        return SC_SECOC_BAD_MAC;
    }
    rx->synced[s] = 1u;
    rx->last_fv[s] = fv;
    if (fv_out != NULL) {
        *fv_out = fv;
    }
    return SC_SECOC_OK;
}
