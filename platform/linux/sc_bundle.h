/*
 * sc_bundle.h: session bundles (docs/session-bundle.md): one text file (.scb) that holds a
 * recorded session whole: the case's identity (file name and content id, sc_case.case_id),
 * the method and configuration, every CAN frame the engine received (candump -l lines, as
 * `sc-hostsim --record` writes), the engine's events, the image hash of every frame, and the
 * assessment's score (core/imaging/sc_assess.h); versioned, and closed by a CRC-32 over all
 * of it. `sc-hostsim --record-bundle FILE` writes one, `sc-hostsim --replay FILE` replays it
 * with nothing else given and checks every frame's image hash, `--list-bundles DIR` lists them
 * as JSON.
 *
 * The parser takes any bytes: it never reads outside [buf, buf + len), never allocates, and
 * refuses a bad bundle with a named reason (sc_bundle_reject) and the line where it failed.
 * The writer keeps the three growing sections in temporary files and assembles the bundle at
 * the end (header first, with the counts), written to FILE.tmp and renamed.
 */
#ifndef SC_BUNDLE_H
#define SC_BUNDLE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "sc_candump.h"

#define SC_BUNDLE_MAGIC      "SCBUNDLE"
#define SC_BUNDLE_VERSION    1u
#define SC_BUNDLE_TEXT_MAX   128u      /* case name, source, date: bytes with the NUL */
#define SC_BUNDLE_FRAMES_MAX 100000000u /* frames a bundle may declare (about 19 days) */

typedef enum sc_bundle_reject {
    SC_BDL_OK = 0,
    SC_BDL_MAGIC,     /* not a bundle: the first line is not "SCBUNDLE <version>" */
    SC_BDL_VERSION,   /* a version this reader does not know */
    SC_BDL_TRUNCATED, /* the file ends before its "end" line */
    SC_BDL_CRC,       /* the CRC-32 of the "end" line does not match the bytes before it */
    SC_BDL_FIELD,     /* a header line missing, out of order, or with a bad value */
    SC_BDL_SECTION,   /* a section header missing or its count out of range */
    SC_BDL_CAN_LINE,  /* a CAN record that is not a valid candump -l line, or out of time order */
    SC_BDL_EVENT_LINE,
    SC_BDL_HASH_LINE, /* not "<frame> <16 hex digits>" with frames 0, 1, 2, ... */
    SC_BDL_TRAILING,  /* bytes after the "end" line */
    SC_BDL_COUNT
} sc_bundle_reject;

const char *sc_bundle_reject_name(sc_bundle_reject r);

/* The header: what the session was and how it ended. */
typedef struct sc_bundle_meta {
    char case_name[SC_BUNDLE_TEXT_MAX]; /* the case file's name in the case folder (no '/') */
    uint32_t case_id;                   /* sc_case.case_id: the case content's CRC-32 */
    uint8_t method;                     /* SC_TISSUE_MSDS / SC_TISSUE_FEM */
    uint32_t rate_hz;                   /* frame rate */
    uint64_t frames;                    /* frames run */
    uint32_t rx_cost_us;                /* virtual cost of a received CAN frame */
    char source[SC_BUNDLE_TEXT_MAX];    /* what drove the probe (informational) */
    char date[SC_BUNDLE_TEXT_MAX];      /* UTC time of the recording, ISO 8601 */
    uint32_t score, score_max, criteria; /* the assessment at the end */
    uint8_t call, finding;               /* SC_ASSESS_CALL_* */
    float min_ratio[3];                  /* vein, artery, thrombus; < 0 never in view */
    float peak_force_n;                  /* < 0 not available */
} sc_bundle_meta;

/* A parsed bundle: the header and where each section's lines are in the buffer. */
typedef struct sc_bundle_info {
    sc_bundle_meta meta;
    size_t can_off, can_len; /* byte range of the CAN lines */
    uint64_t can_count;
    size_t ev_off, ev_len;
    uint64_t ev_count;
    size_t hash_off, hash_len;
    uint64_t hash_count; /* == meta.frames */
    uint32_t crc;
} sc_bundle_info;

/* Validate the whole bundle buf[0..len) and fill *out. O(len). 0, or SC_ERR_PARSE with *why
 * (and *line, 1-based, when not NULL) set. Never allocates. */
int sc_bundle_parse(const uint8_t *buf, size_t len, sc_bundle_info *out, sc_bundle_reject *why,
                    uint64_t *line);

/* The next line of a section: [*pos, end) is what is left; *line/len get the line without
 * its '\n'. 1 while there is one, 0 at the end. */
int sc_bundle_next_line(const uint8_t *buf, size_t end, size_t *pos, const char **line,
                        size_t *len);
/* A hash line "<frame> <hex16>" (already validated by the parser). */
uint64_t sc_bundle_hash_of_line(const char *line, size_t len);

/* ---- writing ----------------------------------------------------------------------------- */
typedef struct sc_bundle_writer {
    FILE *can, *ev, *hash; /* temporary files */
    uint64_t n_can, n_ev, n_hash;
    int failed; /* a write failed: finish refuses */
} sc_bundle_writer;

/* 0 or SC_ERR_IO (no temporary file). */
int sc_bundle_writer_open(sc_bundle_writer *w);
void sc_bundle_add_can(sc_bundle_writer *w, const sc_candump_rec *r);
/* event: [a-z0-9_]+ (others are written as "?"). */
void sc_bundle_add_event(sc_bundle_writer *w, uint64_t frame, const char *event, int err,
                         int64_t a, int64_t b);
void sc_bundle_add_hash(sc_bundle_writer *w, uint64_t frame, uint64_t hash);
/* Write the bundle to path (via path.tmp, renamed). meta->frames must equal the hashes added.
 * 0, SC_ERR_INVALID_ARG (meta not writable: bad name, counts), SC_ERR_IO. */
int sc_bundle_writer_finish(sc_bundle_writer *w, const sc_bundle_meta *meta, const char *path);
void sc_bundle_writer_close(sc_bundle_writer *w);

/* Read a whole file into a malloc'd buffer (at most max_bytes): 0, SC_ERR_IO, SC_ERR_NO_SPACE
 * (too large). The caller frees *buf. */
int sc_bundle_read_file(const char *path, size_t max_bytes, uint8_t **buf, size_t *len);
/* 1 when buf starts with the bundle magic (a candump log never does). */
int sc_bundle_is_bundle(const uint8_t *buf, size_t len);

/* "normal", "dvt" or "none". */
const char *sc_bundle_call_name(uint8_t call);

#endif /* SC_BUNDLE_H */
