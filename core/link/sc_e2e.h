/*
 * sc_e2e.h: end-to-end protection of CAN messages in the AUTOSAR E2E profile 1 style.
 *
 * Layout of every protected payload (Intel byte order, see config/sonocomp.dbc):
 *   byte 0        CRC-8 (SAE J1850 polynomial 0x1D)
 *   byte 1 [3:0]  4-bit alive counter, 0..15, incremented per sent message and wrapping
 *                 (profile 1 reserves 15; like profile 11 we use the whole nibble)
 *   byte 1 [7:4]  message-specific bits (covered by the CRC)
 *   byte 2..n-1   the message's signals
 * The CRC is profile 1's "DataID both bytes" variant: CRC-8 with start value 0x00 and final
 * XOR 0x00 over the data ID's low byte, its high byte, then payload bytes 1..n-1 (all but
 * the CRC byte). (Profile 1 calls the SAE J1850 library routine, whose own start value and
 * XOR are 0xFF, and compensates both, so the effective parameters are 0x00/0x00.)
 *
 * Receive side: one sc_e2e_rx per message; sc_e2e_check() classifies each received payload
 * with a named outcome (sc_e2e_status) and sc_e2e_poll() reports "no new data" and the
 * per-message timeout. Data is usable only when sc_e2e_status_usable() says so.
 *
 * Thread and memory rules: plain functions on caller-owned state; a state is used from one
 * thread. Never allocates, never calls the OS, deterministic.
 */
#ifndef SC_E2E_H
#define SC_E2E_H

#include <stddef.h>
#include <stdint.h>

#define SC_E2E_COUNTER_MOD  16u
#define SC_E2E_HEADER_BYTES 2u

/* CRC-8 SAE J1850, polynomial 0x1D, not reflected, over len bytes starting from crc (the start
 * value). sc_crc8_j1850(d, n, 0xFF) ^ 0xFF is the SAE J1850 / AUTOSAR Crc_CalculateCRC8
 * value (check "123456789" -> 0x4B); sc_crc8_j1850(d, n, 0x00) is profile 1's CRC.
 * O(len), table-driven. Never allocates. Cannot fail. */
uint8_t sc_crc8_j1850(const uint8_t *data, size_t len, uint8_t crc);

/* The profile 1 CRC of a protected payload: over data_id low byte, high byte, data[1..len-1].
 * len >= 2. O(len). */
uint8_t sc_e2e_crc(uint16_t data_id, const uint8_t *data, size_t len);

/* Sender state: one per message. */
typedef struct sc_e2e_tx {
    uint16_t data_id;
    uint8_t counter; /* next counter to send */
} sc_e2e_tx;

void sc_e2e_tx_init(sc_e2e_tx *tx, uint16_t data_id);

/* Writes the current counter into the low nibble of data[1] (high nibble kept), then the CRC
 * into data[0], and advances the counter. O(len). SC_ERR_INVALID_ARG when len < 2. */
int sc_e2e_protect(sc_e2e_tx *tx, uint8_t *data, size_t len);

/* Same, with an explicit counter (used when one sample spans several messages that share a
 * counter, and by fault injection). Does not touch any state. O(len). */
int sc_e2e_protect_with(uint16_t data_id, uint8_t counter, uint8_t *data, size_t len);

/* Named receive outcomes. */
typedef enum sc_e2e_status {
    SC_E2E_OK = 0,         /* counter advanced by exactly 1: data usable */
    SC_E2E_INITIAL,        /* first message after init or after a timeout: data usable */
    SC_E2E_OK_SOME_LOST,   /* counter advanced by 2..max_delta: data usable, losses counted */
    SC_E2E_WRONG_SEQUENCE, /* counter jumped beyond max_delta (or went back): data rejected;
                            * the receiver re-anchors on this counter */
    SC_E2E_REPEATED,       /* same counter as the last accepted message: data rejected */
    SC_E2E_WRONG_CRC,      /* CRC mismatch: data rejected, state untouched */
    SC_E2E_NO_NEW_DATA,    /* poll: nothing received since the last poll */
    SC_E2E_TIMEOUT,        /* poll: nothing usable for longer than the message's timeout */
    SC_E2E_STATUS_COUNT
} sc_e2e_status;

const char *sc_e2e_status_name(sc_e2e_status s);
/* 1 for OK, INITIAL and OK_SOME_LOST. */
int sc_e2e_status_usable(sc_e2e_status s);

/* Receiver definition: plain data, validated by sc_e2e_rx_init. */
typedef struct sc_e2e_rx_def {
    uint16_t data_id;
    uint8_t max_delta_counter; /* 1..14: counter steps accepted in one go (1: no loss) */
    uint32_t timeout_ms;       /* 0: no timeout (event-driven messages) */
} sc_e2e_rx_def;

sc_e2e_rx_def sc_e2e_rx_default_def(uint16_t data_id);

typedef struct sc_e2e_rx {
    sc_e2e_rx_def def;
    uint8_t have_last; /* a usable message was seen since init/timeout */
    uint8_t last_counter;
    uint8_t new_data;                    /* a message arrived since the last poll */
    uint64_t last_ok_ns;                 /* receive time of the last usable message */
    uint32_t lost;                       /* messages lost, from counter gaps of OK_SOME_LOST */
    uint32_t count[SC_E2E_STATUS_COUNT]; /* outcomes seen, saturating */
} sc_e2e_rx;

/* SC_ERR_INVALID_ARG for max_delta_counter outside 1..14. O(1). */
int sc_e2e_rx_init(sc_e2e_rx *rx, const sc_e2e_rx_def *def);

/* Classifies one received payload (len >= 2, else WRONG_CRC) received at now_ns and updates
 * the state. O(len). Never allocates. */
sc_e2e_status sc_e2e_check(sc_e2e_rx *rx, const uint8_t *data, size_t len, uint64_t now_ns);

/* Called once per frame of the receiver. SC_E2E_TIMEOUT (a level, reported on every poll while
 * it lasts) when no usable message was ever received or the last one is older than the
 * timeout; the state then waits for a new first message (INITIAL) and count[SC_E2E_TIMEOUT]
 * counts the edges from fresh to timed out. Otherwise SC_E2E_NO_NEW_DATA when nothing came
 * since the last poll, else SC_E2E_OK. With timeout_ms 0 never TIMEOUT. O(1). */
sc_e2e_status sc_e2e_poll(sc_e2e_rx *rx, uint64_t now_ns);

#endif /* SC_E2E_H */
