/* sc_e2e.c: CRC-8 SAE J1850 and the profile-1-style protect/check, see sc_e2e.h. */
#include "sc_e2e.h"

#include "sc_err.h"

/* 256-entry table of polynomial 0x1D, MSB first: table[i] = CRC of the byte i from 0. */
static const uint8_t crc8_table[256] = {
    0x00, 0x1D, 0x3A, 0x27, 0x74, 0x69, 0x4E, 0x53, 0xE8, 0xF5, 0xD2, 0xCF, 0x9C, 0x81, 0xA6, 0xBB,
    0xCD, 0xD0, 0xF7, 0xEA, 0xB9, 0xA4, 0x83, 0x9E, 0x25, 0x38, 0x1F, 0x02, 0x51, 0x4C, 0x6B, 0x76,
    0x87, 0x9A, 0xBD, 0xA0, 0xF3, 0xEE, 0xC9, 0xD4, 0x6F, 0x72, 0x55, 0x48, 0x1B, 0x06, 0x21, 0x3C,
    0x4A, 0x57, 0x70, 0x6D, 0x3E, 0x23, 0x04, 0x19, 0xA2, 0xBF, 0x98, 0x85, 0xD6, 0xCB, 0xEC, 0xF1,
    0x13, 0x0E, 0x29, 0x34, 0x67, 0x7A, 0x5D, 0x40, 0xFB, 0xE6, 0xC1, 0xDC, 0x8F, 0x92, 0xB5, 0xA8,
    0xDE, 0xC3, 0xE4, 0xF9, 0xAA, 0xB7, 0x90, 0x8D, 0x36, 0x2B, 0x0C, 0x11, 0x42, 0x5F, 0x78, 0x65,
    0x94, 0x89, 0xAE, 0xB3, 0xE0, 0xFD, 0xDA, 0xC7, 0x7C, 0x61, 0x46, 0x5B, 0x08, 0x15, 0x32, 0x2F,
    0x59, 0x44, 0x63, 0x7E, 0x2D, 0x30, 0x17, 0x0A, 0xB1, 0xAC, 0x8B, 0x96, 0xC5, 0xD8, 0xFF, 0xE2,
    0x26, 0x3B, 0x1C, 0x01, 0x52, 0x4F, 0x68, 0x75, 0xCE, 0xD3, 0xF4, 0xE9, 0xBA, 0xA7, 0x80, 0x9D,
    0xEB, 0xF6, 0xD1, 0xCC, 0x9F, 0x82, 0xA5, 0xB8, 0x03, 0x1E, 0x39, 0x24, 0x77, 0x6A, 0x4D, 0x50,
    0xA1, 0xBC, 0x9B, 0x86, 0xD5, 0xC8, 0xEF, 0xF2, 0x49, 0x54, 0x73, 0x6E, 0x3D, 0x20, 0x07, 0x1A,
    0x6C, 0x71, 0x56, 0x4B, 0x18, 0x05, 0x22, 0x3F, 0x84, 0x99, 0xBE, 0xA3, 0xF0, 0xED, 0xCA, 0xD7,
    0x35, 0x28, 0x0F, 0x12, 0x41, 0x5C, 0x7B, 0x66, 0xDD, 0xC0, 0xE7, 0xFA, 0xA9, 0xB4, 0x93, 0x8E,
    0xF8, 0xE5, 0xC2, 0xDF, 0x8C, 0x91, 0xB6, 0xAB, 0x10, 0x0D, 0x2A, 0x37, 0x64, 0x79, 0x5E, 0x43,
    0xB2, 0xAF, 0x88, 0x95, 0xC6, 0xDB, 0xFC, 0xE1, 0x5A, 0x47, 0x60, 0x7D, 0x2E, 0x33, 0x14, 0x09,
    0x7F, 0x62, 0x45, 0x58, 0x0B, 0x16, 0x31, 0x2C, 0x97, 0x8A, 0xAD, 0xB0, 0xE3, 0xFE, 0xD9, 0xC4,
};

uint8_t sc_crc8_j1850(const uint8_t *data, size_t len, uint8_t crc)
{
    for (size_t i = 0; i < len; i++) {
        crc = crc8_table[crc ^ data[i]];
    }
    return crc;
}

uint8_t sc_e2e_crc(uint16_t data_id, const uint8_t *data, size_t len)
{
    const uint8_t id[2] = {(uint8_t)(data_id & 0xFFu), (uint8_t)(data_id >> 8)};
    uint8_t crc = sc_crc8_j1850(id, 2u, 0x00u);
    if (len > 1u) {
        crc = sc_crc8_j1850(data + 1, len - 1u, crc);
    }
    return crc;
}

void sc_e2e_tx_init(sc_e2e_tx *tx, uint16_t data_id)
{
    tx->data_id = data_id;
    tx->counter = 0;
}

int sc_e2e_protect_with(uint16_t data_id, uint8_t counter, uint8_t *data, size_t len)
{
    if (data == NULL || len < SC_E2E_HEADER_BYTES) {
        return SC_ERR_INVALID_ARG;
    }
    data[1] = (uint8_t)((data[1] & 0xF0u) | (counter & 0x0Fu));
    data[0] = sc_e2e_crc(data_id, data, len);
    return 0;
}

int sc_e2e_protect(sc_e2e_tx *tx, uint8_t *data, size_t len)
{
    int rc = sc_e2e_protect_with(tx->data_id, tx->counter, data, len);
    if (rc == 0) {
        tx->counter = (uint8_t)((tx->counter + 1u) % SC_E2E_COUNTER_MOD);
    }
    return rc;
}

const char *sc_e2e_status_name(sc_e2e_status s)
{
    switch (s) {
    case SC_E2E_OK:
        return "ok";
    case SC_E2E_INITIAL:
        return "initial";
    case SC_E2E_OK_SOME_LOST:
        return "ok_some_lost";
    case SC_E2E_WRONG_SEQUENCE:
        return "wrong_sequence";
    case SC_E2E_REPEATED:
        return "repeated";
    case SC_E2E_WRONG_CRC:
        return "wrong_crc";
    case SC_E2E_NO_NEW_DATA:
        return "no_new_data";
    case SC_E2E_TIMEOUT:
        return "timeout";
    case SC_E2E_STATUS_COUNT:
        break;
    }
    return "?";
}

int sc_e2e_status_usable(sc_e2e_status s)
{
    return s == SC_E2E_OK || s == SC_E2E_INITIAL || s == SC_E2E_OK_SOME_LOST;
}

sc_e2e_rx_def sc_e2e_rx_default_def(uint16_t data_id)
{
    return (sc_e2e_rx_def){.data_id = data_id, .max_delta_counter = 3u, .timeout_ms = 0u};
}

int sc_e2e_rx_init(sc_e2e_rx *rx, const sc_e2e_rx_def *def)
{
    if (rx == NULL || def == NULL || def->max_delta_counter < 1u ||
        def->max_delta_counter > SC_E2E_COUNTER_MOD - 2u) {
        return SC_ERR_INVALID_ARG;
    }
    *rx = (sc_e2e_rx){.def = *def};
    return 0;
}

static void count_status(sc_e2e_rx *rx, sc_e2e_status s)
{
    if (rx->count[s] != UINT32_MAX) {
        rx->count[s]++;
    }
}

sc_e2e_status sc_e2e_check(sc_e2e_rx *rx, const uint8_t *data, size_t len, uint64_t now_ns)
{
    sc_e2e_status s;
    if (len < SC_E2E_HEADER_BYTES || sc_e2e_crc(rx->def.data_id, data, len) != data[0]) {
        s = SC_E2E_WRONG_CRC;
        count_status(rx, s);
        return s;
    }
    const uint8_t counter = (uint8_t)(data[1] & 0x0Fu);
    rx->new_data = 1u;
    if (!rx->have_last) {
        s = SC_E2E_INITIAL;
    } else {
        const uint8_t delta =
            (uint8_t)((counter + SC_E2E_COUNTER_MOD - rx->last_counter) % SC_E2E_COUNTER_MOD);
        if (delta == 0u) {
            s = SC_E2E_REPEATED;
        } else if (delta == 1u) {
            s = SC_E2E_OK;
        } else if (delta <= rx->def.max_delta_counter) {
            s = SC_E2E_OK_SOME_LOST;
            rx->lost += (uint32_t)(delta - 1u);
        } else {
            s = SC_E2E_WRONG_SEQUENCE;
        }
    }
    if (s != SC_E2E_REPEATED) {
        /* Re-anchor also on a wrong sequence: the next consecutive message is OK again. */
        rx->last_counter = counter;
    }
    if (sc_e2e_status_usable(s)) {
        rx->have_last = 1u;
        rx->last_ok_ns = now_ns;
    }
    count_status(rx, s);
    return s;
}

sc_e2e_status sc_e2e_poll(sc_e2e_rx *rx, uint64_t now_ns)
{
    const int had_new = rx->new_data != 0u;
    rx->new_data = 0u;
    if (rx->def.timeout_ms != 0u) {
        const uint64_t timeout_ns = (uint64_t)rx->def.timeout_ms * 1000000u;
        if (!rx->have_last) {
            return SC_E2E_TIMEOUT;
        }
        if (now_ns > rx->last_ok_ns && now_ns - rx->last_ok_ns > timeout_ns) {
            rx->have_last = 0u;
            count_status(rx, SC_E2E_TIMEOUT);
            return SC_E2E_TIMEOUT;
        }
    }
    if (!had_new) {
        count_status(rx, SC_E2E_NO_NEW_DATA);
        return SC_E2E_NO_NEW_DATA;
    }
    return SC_E2E_OK;
}
