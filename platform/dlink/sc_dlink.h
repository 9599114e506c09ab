/*
 * sc_dlink.h: the display link: packet codec and receiver-side frame assembler.
 *
 * The engine sends each B-scan to the display controller as UDP datagrams (one per packet):
 * a FRAME_BEGIN packet, one LINE packet per scan line (any order, each at most once), and a
 * FRAME_END packet. Every packet starts with the same 28-byte little-endian header carrying
 * magic, version, type, flags, frame number, line index, line count, samples per line,
 * geometry id, payload length and a CRC-32 (core/base/sc_crc32.h) over header and payload. The wire
 * format is specified byte by byte in docs/display-link.md; SC_DLINK_VERSION changes whenever
 * that format changes.
 *
 * The link is loss-tolerant: the receiver never waits for a missing packet. The assembler
 * closes a frame on its FRAME_END, or when a packet of a newer frame arrives; lines that never
 * arrived by then are counted lost (and show the previous frame's line), lines that arrive for
 * a closed frame are counted late, repeated lines duplicate, and malformed packets are rejected
 * and counted by reason.
 *
 * Thread and memory rules: the codec functions are pure, reentrant and work on caller buffers.
 * An sc_dlink_asm is driven by one thread; it holds two image planes of
 * SC_MAX_SCAN_LINES x SC_MAX_SCAN_SAMPLES bytes (512 KiB with the default limits) and is meant
 * for static storage. Never allocates, never calls the OS.
 */
#ifndef SC_DLINK_H
#define SC_DLINK_H

#include <stddef.h>
#include <stdint.h>

#include "sc_config.h"

#define SC_DLINK_MAGIC         0x4C444353u /* bytes 'S' 'C' 'D' 'L' on the wire (little-endian) */
#define SC_DLINK_VERSION       2u /* 2: the compression measure moved to FRAME_END */
/* Version 3, an extension: colour Doppler (COLOUR_LINE, DOPPLER packets). Only the new packet
 * types carry version 3; B-mode packets stay version 2, so a version-2 receiver keeps showing
 * the B-scan and refuses the colour packets by name (SC_ERR_DLINK_VERSION, counted). */
#define SC_DLINK_VERSION_COLOUR 3u
#define SC_DLINK_COLOUR_HEAD    4u  /* COLOUR_LINE: first sample, count (u16 each), then values */
#define SC_DLINK_DOPPLER_HEAD   28u /* DOPPLER: box, scale, steering, gate; then the spectrum */
#define SC_DLINK_SPECTRUM_MAX   128u
#define SC_DLINK_HEADER_SIZE   28u
#define SC_DLINK_BEGIN_PAYLOAD 16u /* depth, width, radius f32; reserved u32 */
#define SC_DLINK_END_PAYLOAD   8u  /* lines_sent, lines_dropped, vein and artery compression u16 */
#define SC_DLINK_PARAMS_PAYLOAD 48u /* gain, range, focus, frequency, tgc[8]: f32 */
#define SC_DLINK_PARAMS_TGC     8u
/* Largest packet: a line of SC_MAX_SCAN_SAMPLES samples (540 bytes with the default limits,
 * below the 1472-byte UDP payload of a 1500-byte Ethernet MTU, so no IP fragmentation). */
#define SC_DLINK_MAX_PACKET (SC_DLINK_HEADER_SIZE + SC_DLINK_COLOUR_HEAD + SC_MAX_SCAN_SAMPLES)
/* Compression measure unknown (the sender has none, e.g. no vessel in view). */
#define SC_DLINK_COMPRESSION_UNKNOWN 0xFFFFu

_Static_assert(SC_DLINK_MAX_PACKET <= 1472u, "a line packet must fit one unfragmented datagram");
_Static_assert(SC_MAX_SCAN_LINES <= 65535u && SC_MAX_SCAN_SAMPLES <= 65535u,
               "line index and sample count are 16-bit on the wire");

typedef enum sc_dlink_type {
    SC_DLINK_FRAME_BEGIN = 1,
    SC_DLINK_LINE = 2,
    SC_DLINK_FRAME_END = 3,
    /* additive extension (same version): the imaging parameters a scanner's display shows,
     * optional, once between FRAME_BEGIN and FRAME_END. A receiver that predates it rejects
     * it by type (counted) and still shows the frame; 4..7 left to other extensions. */
    SC_DLINK_FRAME_PARAMS = 8,
    SC_DLINK_COLOUR_LINE = 4, /* version 3 */
    SC_DLINK_DOPPLER = 5,     /* version 3 */
} sc_dlink_type;

/* Decoded header. For FRAME_BEGIN and FRAME_END line_index is 0. */
typedef struct sc_dlink_header {
    uint8_t version;
    uint8_t type;   /* sc_dlink_type */
    uint16_t flags; /* SC_DISPLAY_FLAG_* of hal/sc_hal_display.h */
    uint32_t frame_no;
    uint16_t line_index;  /* LINE: 0 .. line_count-1 */
    uint16_t line_count;  /* lines of the frame: 1 .. SC_MAX_SCAN_LINES */
    uint16_t samples;     /* samples per line: 1 .. SC_MAX_SCAN_SAMPLES */
    uint16_t geometry_id; /* 0 linear, 1 curvilinear */
    uint16_t payload_len; /* bytes after the header */
} sc_dlink_header;

/* FRAME_BEGIN payload. */
typedef struct sc_dlink_begin {
    float depth_mm;          /* imaging depth */
    float width_mm;          /* linear: aperture width; curvilinear: sector angle in degrees */
    float radius_mm;         /* curvilinear: probe face radius (apex behind the face); linear 0 */
} sc_dlink_begin;

/* FRAME_END payload: what the sender did with this frame's lines, and what the frame's own
 * pass computed (the measure is known only once the last line is computed, so it closes the
 * frame it belongs to). */
typedef struct sc_dlink_end {
    uint16_t lines_sent;     /* handed to the network */
    uint16_t lines_dropped;  /* dropped by the sender (socket full, over its time budget) */
    uint16_t compression_pm; /* vein compression, 1000 (1 - area now / at rest), permille; or
                              * ..._UNKNOWN */
    uint16_t artery_compression_pm; /* the same for the artery */
} sc_dlink_end;

/* FRAME_PARAMS payload (little-endian f32 each). Ranges checked by the codec: gain and TGC
 * [-60, 60] dB, range [0, 120] dB, focus [0, 300] mm, frequency [0, 30] MHz (0: not known). */
typedef struct sc_dlink_params {
    float gain_db;
    float dynamic_range_db;
    float focus_mm;
    float frequency_mhz;
    float tgc_db[SC_DLINK_PARAMS_TGC];
} sc_dlink_params;
/* DOPPLER payload (version 3): the frame's colour box, scale and pulsed-wave spectrum column
 * (as hal/sc_hal_display.h's sc_display_doppler_info). */
typedef struct sc_dlink_doppler {
    uint16_t box_line_lo, box_line_hi;     /* lines [lo, hi), hi <= line_count */
    uint16_t box_sample_lo, box_sample_hi; /* samples [lo, hi), hi <= samples */
    float nyquist_mm_s;                    /* > 0, finite */
    float steer_deg;                       /* [-90, 90] */
    float gate_velocity_mm_s;              /* finite */
    uint16_t gate_line;                    /* < line_count */
    uint16_t gate_sample_lo, gate_sample_hi; /* lo < hi <= samples */
    uint16_t bins;                         /* 0 .. SC_DLINK_SPECTRUM_MAX */
    uint8_t spectrum[SC_DLINK_SPECTRUM_MAX];
} sc_dlink_doppler;

/* The compression measure in permille of an area ratio (now / at rest; < 0 or not finite:
 * unknown): 1000 (1 - ratio), clamped to 0..1000. O(1). */
uint16_t sc_dlink_compression_pm(float area_ratio);

/* Frame parameters shared by the packets of one frame. */
typedef struct sc_dlink_frame {
    uint32_t frame_no;
    uint16_t flags;
    uint16_t line_count;
    uint16_t samples;
    uint16_t geometry_id;
} sc_dlink_frame;

/* ---- codec ---------------------------------------------------------------------------------
 * Encoders write one packet into buf (capacity cap) and return its length (> 0), or
 * SC_ERR_NO_SPACE when cap is too small, SC_ERR_DLINK_FIELD when a field is outside the wire
 * limits (line_count or samples 0 or above the SC_MAX_SCAN_* limits, line_index >= line_count,
 * geometry_id > 1, count != samples, a compression above 1000 and not unknown, lines_sent +
 * lines_dropped above line_count, radius negative), SC_ERR_NOT_FINITE for a non-finite depth,
 * width or radius,
 * SC_ERR_INVALID_ARG for NULL pointers. O(header + payload), never allocates. */
int sc_dlink_encode_begin(uint8_t *buf, size_t cap, const sc_dlink_frame *f,
                          const sc_dlink_begin *b);
int sc_dlink_encode_line(uint8_t *buf, size_t cap, const sc_dlink_frame *f, uint16_t line_index,
                         const uint8_t *samples, uint16_t count);
int sc_dlink_encode_end(uint8_t *buf, size_t cap, const sc_dlink_frame *f, const sc_dlink_end *e);
/* FRAME_PARAMS: as the others; SC_ERR_NOT_FINITE for a non-finite value, SC_ERR_DLINK_FIELD for
 * one outside the ranges of sc_dlink_params. */
int sc_dlink_encode_params(uint8_t *buf, size_t cap, const sc_dlink_frame *f,
                           const sc_dlink_params *p);

/* Version 3 encoders. COLOUR_LINE: colour values of samples [first, first + count) of a line
 * (signed bytes, 0 no colour); errors as above plus SC_ERR_DLINK_FIELD for count 0 or
 * first + count > samples. DOPPLER: SC_ERR_DLINK_FIELD for a box, gate or bin count outside the
 * frame or the limits above, SC_ERR_NOT_FINITE for a non-finite float. */
int sc_dlink_encode_colour(uint8_t *buf, size_t cap, const sc_dlink_frame *f, uint16_t line_index,
                           uint16_t first, const int8_t *values, uint16_t count);
int sc_dlink_encode_doppler(uint8_t *buf, size_t cap, const sc_dlink_frame *f,
                            const sc_dlink_doppler *d);

/* Decode and check one received packet of len bytes. On success fills *h, points *payload at
 * the payload inside pkt and returns 0. Checks, in this order: length at least a header
 * (SC_ERR_DLINK_LENGTH), magic (SC_ERR_DLINK_MAGIC), version (SC_ERR_DLINK_VERSION), header
 * plus payload_len equal to len (SC_ERR_DLINK_LENGTH), CRC (SC_ERR_DLINK_CRC), type
 * (SC_ERR_DLINK_TYPE), payload length for the type (SC_ERR_DLINK_LENGTH), header and payload
 * field ranges as for the encoders, reserved bytes zero (SC_ERR_DLINK_FIELD). A corrupted byte
 * anywhere is thus refused: magic and version by name, everything else by the CRC. Errors:
 * also SC_ERR_INVALID_ARG for NULL pointers. O(len), never allocates. */
int sc_dlink_decode(const uint8_t *pkt, size_t len, sc_dlink_header *h, const uint8_t **payload);

/* sc_dlink_decode as a receiver of protocol version max_version (2 or 3) does it: a version-2
 * receiver accepts version 2 only (exactly the version-2 rules: a colour packet is refused with
 * SC_ERR_DLINK_VERSION before anything else is read); a version-3 receiver accepts version 2 for
 * types 1-3 and version 3 for types 4-5 (any other pairing: SC_ERR_DLINK_TYPE). Payload checks
 * of the new types: COLOUR_LINE payload 4 + count, count >= 1, first + count <= samples,
 * line_index < line_count; DOPPLER payload 28 + bins, the DOPPLER ranges above. sc_dlink_decode is
 * this with max_version 3. */
int sc_dlink_decode_as(const uint8_t *pkt, size_t len, uint8_t max_version, sc_dlink_header *h,
                       const uint8_t **payload);

/* Payload accessors for a packet that sc_dlink_decode accepted with that type (the decoder
 * has checked the payload: finite depth, width and radius >= 0, compression <= 1000 or unknown,
 * lines_sent + lines_dropped <= line_count, reserved bytes zero). O(1), cannot fail. */
void sc_dlink_parse_begin(const uint8_t *payload, sc_dlink_begin *b);
void sc_dlink_parse_end(const uint8_t *payload, sc_dlink_end *e);
void sc_dlink_parse_params(const uint8_t *payload, sc_dlink_params *p);
void sc_dlink_parse_doppler(const uint8_t *payload, sc_dlink_doppler *d);

/* ---- receiver-side frame assembler ----------------------------------------------------- */

typedef struct sc_dlink_rx_stats {
    uint64_t packets;  /* datagrams offered */
    uint64_t rejected; /* failed sc_dlink_decode (sum of the reasons below) */
    uint64_t rej_length, rej_magic, rej_version, rej_crc, rej_type, rej_field;
    uint64_t lines_received;       /* stored in their frame */
    uint64_t lines_lost;           /* expected, not received when the frame closed */
    uint64_t lines_late;           /* arrived for a frame already closed */
    uint64_t lines_duplicate;      /* same line twice in one frame */
    uint64_t lines_sender_dropped; /* reported by the sender in FRAME_END */
    uint64_t frames_complete;      /* closed with every line */
    uint64_t frames_incomplete;    /* closed with lines lost */
    uint64_t begins_missing;       /* frame started by a line or end: its FRAME_BEGIN never came */
    uint64_t ends_missing;         /* frame closed by a newer frame: its FRAME_END never came */
    uint64_t frames_late;          /* FRAME_BEGIN/END of a frame older than the current one */
    uint64_t colour_lines;         /* COLOUR_LINE packets stored */
    uint64_t doppler_records;      /* DOPPLER packets stored */
} sc_dlink_rx_stats;

/* A closed frame, ready to show: image rows 0..line_count-1, each `samples` bytes, stride
 * SC_MAX_SCAN_SAMPLES. Lost rows hold the previous frame's row. */
typedef struct sc_dlink_done {
    sc_dlink_frame frame;
    sc_dlink_begin begin; /* from FRAME_BEGIN, or the previous frame's if it was lost */
    sc_dlink_end end;     /* from FRAME_END; measures ..._UNKNOWN when it never came */
    uint16_t lines_received;
    uint16_t lines_lost;
    uint8_t begin_seen;
    uint8_t end_seen;
    const uint8_t *image; /* valid until the next frame closes */
    sc_dlink_params params; /* FRAME_PARAMS, or the last frame's that had one */
    uint8_t params_known;   /* a FRAME_PARAMS has arrived (this frame or before) */
    /* colour Doppler (version 3): colour plane like image (signed, 0 no colour), or NULL when
     * the frame carried no colour; the doppler record when doppler_seen */
    const int8_t *colour;
    uint8_t doppler_seen;
    sc_dlink_doppler doppler;
} sc_dlink_done;

typedef struct sc_dlink_asm {
    uint8_t image[2][SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES]; /* assembling / last closed */
    int8_t colour[2][SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES]; /* colour planes, as image */
    uint8_t colour_used[2];  /* plane holds colour (cleared when a frame opens on it) */
    uint8_t max_version;     /* receiver's protocol version: 3 (init), 2 as an old receiver */
    uint8_t doppler_seen;    /* open frame */
    sc_dlink_doppler doppler; /* open frame's */
    uint32_t got[(SC_MAX_SCAN_LINES + 31u) / 32u];             /* lines of the open frame */
    uint8_t cur;                                               /* plane being assembled */
    uint8_t open;                                              /* a frame is being assembled */
    uint8_t have_done;                                         /* a closed frame exists */
    uint8_t begin_seen;
    sc_dlink_frame frame;    /* open frame */
    sc_dlink_begin begin;    /* open frame's (or last known) begin payload */
    sc_dlink_end end;        /* the FRAME_END payload that closes the open frame */
    sc_dlink_params params;  /* last FRAME_PARAMS received */
    uint8_t params_known;
    uint16_t received;       /* lines of the open frame */
    uint32_t last_closed_no; /* frame number of the last closed frame */
    sc_dlink_done done;      /* last closed frame */
    sc_dlink_rx_stats stats;
} sc_dlink_asm;

/* Reset all state and statistics. O(SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES). */
void sc_dlink_asm_init(sc_dlink_asm *a);

/* A packet more than this many frames older than the last closed frame is taken as a sender
 * restart (its frame counter began again), not as a late packet: the assembler resynchronises. */
#define SC_DLINK_RESYNC_FRAMES 256u

/* Offer one received datagram. Returns 1 when a frame closed (because of this packet; read it
 * with sc_dlink_asm_done() before the next push), 0 when not, or the negative decode error when
 * the packet was rejected (counted in stats, state unchanged). Frame numbers compare in serial
 * arithmetic (wrap-safe): a packet of a frame newer than the open one closes it and opens the
 * new one. (A FRAME_END of a newer frame whose other packets were all lost closes two frames in
 * one push; both are counted, only the second is left to read.) O(len + samples), plus O(lines x samples) to carry lost rows over on a close. */
int sc_dlink_asm_push(sc_dlink_asm *a, const uint8_t *pkt, size_t len);

/* Close the open frame, if any (end of stream). Returns 1 when a frame closed, else 0. */
int sc_dlink_asm_flush(sc_dlink_asm *a);

/* The last closed frame, or NULL before the first. O(1). */
const sc_dlink_done *sc_dlink_asm_done(const sc_dlink_asm *a);

#endif /* SC_DLINK_H */
