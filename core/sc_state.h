/*
 * sc_state.h: the state stream for the instructor console (docs/state-stream.md): fixed,
 * versioned, little-endian records that the engine fills at the end of a frame and hands to
 * the optional state device of the HAL (hal/sc_hal_state.h); the platform sends them (UDP on
 * the appliance, a socket or file on the host simulator) and a gateway (tools/gateway) turns
 * them into WebSocket messages for browsers.
 *
 * Every record: a 16-byte header (u32 magic "SCST", u8 version, u8 type, u16 payload bytes,
 * u32 sequence number (+1 per record, wraps), u32 engine frame number), then the payload of its
 * type. Types: FRAME (status, pose, statistics, imaging settings, compression measures),
 * SURF_INFO (the case's surfaces), VERTS (a run of deformed surface vertices), TRIS (a run of
 * triangles), CATALOGUE (one catalogue entry), ASSESSMENT (the exam's assessment record,
 * sc_assess_report in the layout of docs/assessment.md, one per period when the engine has one),
 * MATERIAL (the running tissue's material rows and solver parameters, CmdMaterial). A receiver ignores types and versions it does
 * not know, and never needs every record: FRAME is complete in itself, surfaces are sent
 * round-robin (vertices every period, triangles and catalogue slowly), so a lost record is
 * replaced by the next round.
 *
 * Rate and cost: at most once per state_period_ms (engine def): one FRAME, one SURF_INFO, up
 * to vert_records VERTS (SC_STATE_VERTS_PER_RECORD vertices each: 4 node reads and a weighted
 * sum per vertex), one TRIS, one CATALOGUE, one ASSESSMENT, one MATERIAL. O(vert_records x SC_STATE_VERTS_PER_RECORD), never
 * allocates, never blocks (a record the device refuses is dropped and counted).
 * Memory: one record buffer of SC_STATE_RECORD_MAX bytes in the sc_state_tx.
 */
#ifndef SC_STATE_H
#define SC_STATE_H

#include <stdint.h>

#include "sc_assess.h"
#include "sc_case.h"
#include "sc_hal_state.h"
#include "sc_material.h"
#include "sc_mesh.h"
#include "sc_pose.h"

#define SC_STATE_MAGIC 0x54534353u /* "SCST" little-endian */
#define SC_STATE_VERSION 1u
#define SC_STATE_HEADER_SIZE 16u
#ifndef SC_STATE_RECORD_MAX
#define SC_STATE_RECORD_MAX 1400u /* one UDP datagram inside a 1500-byte MTU */
#endif
#define SC_STATE_VERTS_PER_RECORD 112u /* 12-byte head + 112 x 12 B */
#define SC_STATE_TRIS_PER_RECORD 112u
_Static_assert(SC_STATE_HEADER_SIZE + 12u + SC_STATE_VERTS_PER_RECORD * 12u <= SC_STATE_RECORD_MAX,
               "a VERTS record fits the buffer");

typedef enum sc_state_type {
    SC_STATE_FRAME = 1,
    SC_STATE_SURF_INFO = 2,
    SC_STATE_VERTS = 3,
    SC_STATE_TRIS = 4,
    SC_STATE_CATALOGUE = 5,
    SC_STATE_ASSESSMENT = 6, /* the exam's assessment record (sc_assess.h) */
    SC_STATE_MATERIAL = 7,   /* the running tissue's materials and solver parameters */
} sc_state_type;

/* MATERIAL payload: 32 bytes of head and SC_STATE_MATERIAL_ROWS rows of (E Pa, nu). */
#define SC_STATE_MATERIAL_ROWS 16u
#define SC_STATE_MATERIAL_SIZE (32u + 8u * SC_STATE_MATERIAL_ROWS)
_Static_assert(SC_MAX_LABELS <= SC_STATE_MATERIAL_ROWS, "a MATERIAL record holds every label");

#define SC_STATE_FRAME_SIZE 208u /* FRAME payload bytes (docs/state-stream.md) */

/* What one emission reads: the engine fills it from its own state (sc_engine.c). */
typedef struct sc_state_in {
    uint64_t now_ns;
    uint32_t frame_no;
    uint8_t health_state, case_loaded, case_id, method, tracked, contact, switching, frozen;
    uint32_t faults;
    uint64_t frames, misses, worst_frame_ns, p99_frame_ns;
    float vein_area_ratio, artery_area_ratio;
    sc_pose probe_volume;  /* probe pose in the volume frame */
    float gain_db, dynamic_range_db, depth_mm, tgc_db[8];
    uint32_t geometry_id;
    uint64_t commands_applied, commands_refused, commands_auth_refused;
    uint64_t case_loads, case_load_failures;
    int32_t last_case_error;
    const sc_case *c;       /* NULL without a case */
    const sc_mesh *mesh;    /* NULL without a case */
    const float *x, *y, *z; /* deformed node positions (mm), NULL without a case */
    const sc_assess_report *assess; /* the exam's assessment; NULL: none */
    const char *const *catalogue; /* case_count names */
    uint32_t catalogue_count;
    /* the running tissue's materials (NULL without a case: no MATERIAL record) */
    const sc_material_table *mat;
    uint32_t mat_override_mask; /* labels whose row a CmdMaterial set */
    uint8_t mat_sim_override;   /* the solver parameters below were set by a CmdMaterial */
    uint8_t cg_iterations, corotated;
    float damping_s;            /* gamma / k (MSDS) = Rayleigh beta (FEM) of the running tissue */
    uint64_t material_rebuilds, material_refused;
} sc_state_in;

typedef struct sc_state_tx {
    uint32_t period_ms;     /* 0: stream off */
    uint32_t vert_records;  /* VERTS records per period */
    uint64_t next_ns;
    uint32_t seq;
    uint32_t vert_cursor, tri_cursor, cat_cursor;
    uint32_t periods;
    uint64_t records_sent, records_dropped;
    uint8_t buf[SC_STATE_RECORD_MAX];
} sc_state_tx;

/* period_ms 0 turns the stream off. O(1). */
void sc_state_tx_init(sc_state_tx *t, uint32_t period_ms, uint32_t vert_records);

/* Emit this period's records when due (now_ns past the next period). Returns the records
 * handed to the device this call (0 when not due, or no device). Never fails: refusals are
 * counted in records_dropped. Cost: see the preamble. */
uint32_t sc_state_emit(sc_state_tx *t, const sc_state_dev *dev, const sc_state_in *in);

/* Record decoding helpers for receivers (gateway, tests): check a record's header.
 * Returns the type (> 0) or SC_ERR_INVALID_ARG / SC_ERR_RANGE (bad magic, version, length). */
int sc_state_check(const uint8_t *rec, uint32_t len, uint32_t *seq, uint32_t *frame_no);

#endif /* SC_STATE_H */
