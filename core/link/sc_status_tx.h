/*
 * sc_status_tx.h: the engine's send side of the CAN protocol: the four status frames
 * (EngineStatus, EngineTiming, TrackerDiag, AuthDiag of config/sonocomp.dbc), each protected by its own
 * E2E sender state (rolling counter, CRC-8; sc_e2e.h).
 *
 * The status stage fills an sc_status_msg with the engine's fields; sc_status_tx_encode() adds
 * the tracker's counters (probe lifted, poses accepted, rejects, lifts, command authentication) and encodes the
 * frames.
 * Cost: O(1) per call (four 8-byte frames). Thread and memory rules: one sc_status_tx inside
 * the engine object, one thread. Never allocates, never calls the OS; deterministic.
 */
#ifndef SC_STATUS_TX_H
#define SC_STATUS_TX_H

#include "sc_canproto.h"
#include "sc_e2e.h"
#include "sc_tracker.h"

typedef struct sc_status_tx {
    sc_e2e_tx tx[SC_STATUS_FRAMES]; /* EngineStatus, EngineTiming, TrackerDiag, AuthDiag */
    sc_e2e_tx assess_tx[SC_ASSESS_FRAMES]; /* AssessVessels, AssessForce, AssessScore */
} sc_status_tx;

/* Counters start at 0 with the protocol's data ids. O(1), cannot fail. */
void sc_status_tx_init(sc_status_tx *s);

/* Fill the tracker's fields of *msg from t and encode the four status frames into out (each
 * sender counter advances). O(1). Errors of sc_canproto_encode_status (SC_ERR_CAN_SIGNAL for a
 * state or method out of range or a non-finite ratio). */
int sc_status_tx_encode(sc_status_tx *s, const sc_tracker *t, sc_status_msg *msg,
                        sc_can_frame out[SC_STATUS_FRAMES]);

/* Encode the assessment's three frames (AssessVessels, AssessForce, AssessScore) into out,
 * sent in the same status period after the four status frames; each sender counter advances.
 * O(1). Errors of sc_canproto_encode_assess. */
int sc_status_tx_encode_assess(sc_status_tx *s, const sc_assess_msg *msg,
                               sc_can_frame out[SC_ASSESS_FRAMES]);

#endif /* SC_STATUS_TX_H */
