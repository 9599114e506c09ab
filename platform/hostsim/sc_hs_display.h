/*
 * sc_hs_display.h: an in-memory display for the host simulator.
 *
 * An sc_display_dev that assembles each frame from its lines into a fixed buffer, checks the
 * protocol (begin/line/end order, line indices in range, each line once, frame numbers) and
 * counts every violation; keeps the last complete frame with its closing record (the frame's
 * compression measure) and a hash (FNV-1a 64) of every frame
 * in a bounded history, so tests and the replay compare frames bit for bit. link_down
 * models a display link that is down: every call answers SC_ERR_IO (counted) and the link
 * state says down. Storage is fixed at compile time; nothing allocates.
 */
#ifndef SC_HS_DISPLAY_H
#define SC_HS_DISPLAY_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_hal_display.h"

#ifndef SC_HS_DISPLAY_HISTORY
#define SC_HS_DISPLAY_HISTORY 4096u
#endif

typedef struct sc_hs_display {
    sc_display_frame_info info;      /* of the frame being assembled / last one */
    uint8_t in_frame;
    uint32_t lines_seen;
    uint8_t line_seen[SC_MAX_SCAN_LINES];
    uint8_t image[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES]; /* line-major: [line][sample] */
    uint8_t last[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];  /* last complete frame */
    sc_display_frame_info last_info;
    sc_display_end_info last_end;   /* closing record of the last complete frame */
    sc_display_end_info end;        /* closing record of the last frame_end call */
    uint64_t frames_complete;
    uint64_t frames_incomplete;  /* ended with missing lines */
    uint64_t lines;
    uint64_t protocol_errors;    /* line outside a frame, bad index, duplicate, bad length */
    uint64_t hashes[SC_HS_DISPLAY_HISTORY]; /* hash of complete frame i (i < history) */
    uint32_t hash_count;
    uint8_t link_down;           /* fault injection: the link is down, every call refused */
    uint64_t calls_refused;      /* begin/line/end refused while down (SC_ERR_IO) */
    /* colour Doppler (optional ops): the frame's colour plane (line-major, 0 no colour), cleared
     * at frame_begin, and the last doppler record with its spectrum copied */
    int8_t colour[SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES];
    uint64_t colour_lines;
    uint64_t doppler_records;
    sc_display_doppler_info doppler;  /* .spectrum points at spectrum below */
    uint8_t spectrum[SC_DISPLAY_SPECTRUM_MAX_BINS];
    uint64_t colour_hash;             /* FNV-1a of every colour line and record so far */
} sc_hs_display;

void sc_hs_display_init(sc_hs_display *d);
sc_display_dev sc_hs_display_dev(sc_hs_display *d);
/* FNV-1a 64 of a byte range: the frame hash used everywhere in tests. */
uint64_t sc_hs_hash64(const void *data, uint64_t size, uint64_t seed);

#endif /* SC_HS_DISPLAY_H */
