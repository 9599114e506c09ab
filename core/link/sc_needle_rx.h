/*
 * sc_needle_rx.h: receiver of the tracked needle (a second tool on the CAN bus): E2E checks per
 * message (CRC, counter; sc_e2e.h), 3-frame sample assembly tied by the E2E counter (as the
 * probe's pose), plausibility, and the newest valid sample with a timeout ("needle absent").
 *
 * Plausibility (each refusal counted by reason): shaft direction norm within [0.9, 1.1]
 * (normalised then), tip inside the tracker's workspace (|x|, |y|, |z| <= workspace_mm),
 * insertion depth <= max_depth_mm, tip speed <= max_speed_mm_s between accepted samples.
 * A sample whose tracking state says "not tracking" is no needle (not a refusal).
 *
 * Memory: all state in the caller's sc_needle_rx (about 200 bytes). Never allocates, never
 * calls the OS. One thread. Deterministic.
 */
#ifndef SC_NEEDLE_RX_H
#define SC_NEEDLE_RX_H

#include <stdint.h>

#include "sc_canproto.h"
#include "sc_e2e.h"
#include "sc_hal_can.h"

typedef struct sc_needle_rx_def {
    float workspace_mm;   /* tip coordinates within +-, (0, 1638] */
    float max_depth_mm;   /* inserted length, (0, 3276] */
    float max_speed_mm_s; /* tip speed between samples, > 0 */
    uint32_t timeout_ms;  /* no valid sample for this long: needle absent, [10, 10000] */
} sc_needle_rx_def;

typedef enum sc_needle_outcome {
    SC_NEEDLE_ACCEPTED = 0, /* a complete sample passed every check */
    SC_NEEDLE_PART,         /* a part stored, waiting for the rest of its sample */
    SC_NEEDLE_NOT_OURS,     /* not a needle frame */
    SC_NEEDLE_BAD_LENGTH,
    SC_NEEDLE_E2E_CRC,
    SC_NEEDLE_E2E_SEQUENCE,
    SC_NEEDLE_E2E_REPEATED,
    SC_NEEDLE_NOT_TRACKING,
    SC_NEEDLE_REJ_DIR_NORM,
    SC_NEEDLE_REJ_WORKSPACE,
    SC_NEEDLE_REJ_DEPTH,
    SC_NEEDLE_REJ_SPEED,
    SC_NEEDLE_OUTCOME_COUNT
} sc_needle_outcome;

typedef struct sc_needle_sample {
    float tip_mm[3]; /* tracker frame */
    float dir[3];    /* unit, hub to tip */
    float depth_mm;  /* inserted length */
    uint64_t rx_ns;
} sc_needle_sample;

typedef struct sc_needle_rx {
    sc_needle_rx_def def;
    sc_e2e_rx rx[3];
    uint8_t mask, counter; /* parts of the sample being assembled, its counter */
    sc_needle_msg msg;
    uint8_t have;          /* a valid sample exists */
    sc_needle_sample cur;
    uint32_t outcome[SC_NEEDLE_OUTCOME_COUNT];
    uint32_t rejected;     /* E2E, length and plausibility refusals */
} sc_needle_rx;

/* Workspace 1000 mm, depth 200 mm, speed 2000 mm/s, timeout 100 ms. */
sc_needle_rx_def sc_needle_rx_default_def(void);

/* Validate def (finite, ranges above) and reset. O(1). Errors: SC_ERR_INVALID_ARG,
 * SC_ERR_RANGE, SC_ERR_NOT_FINITE. */
int sc_needle_rx_init(sc_needle_rx *n, const sc_needle_rx_def *def);

/* 1 when f is one of the needle's frames (by id; length not yet checked). O(1). */
int sc_needle_rx_is_needle(const sc_can_frame *f);

/* One received frame: classified, E2E checked, stored, and on the third part of a sample the
 * plausibility checks. Returns the outcome (counted). O(1). */
sc_needle_outcome sc_needle_rx_on_frame(sc_needle_rx *n, const sc_can_frame *f, uint64_t now_ns);

/* The newest valid sample if it is younger than the timeout: 1 and *out, else 0. O(1). */
int sc_needle_rx_poll(const sc_needle_rx *n, uint64_t now_ns, sc_needle_sample *out);

#endif /* SC_NEEDLE_RX_H */
