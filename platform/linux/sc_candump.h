/*
 * sc_candump.h: can-utils `candump -l` log lines: writer and a robust parser.
 *
 * Line format (as candump -l writes and canplayer reads):
 *   (1436509052.249713) vcan0 123#DEADBEEF        classic, 3 hex digits = 11-bit id
 *   (1436509052.249713) vcan0 12345678#DEADBEEF   8 hex digits = 29-bit id
 *   (1436509052.249713) vcan0 123#R / 123#R5      remote frame (optional length digit)
 *   (1436509052.249713) vcan0 123##1DEADBEEF      CAN FD, one hex digit of CANFD_* flags
 *   (1436509052.249713) vcan0 20000040#0000000000000000   error frame (CAN_ERR_FLAG set)
 * Data bytes are pairs of hex digits, optionally separated by '.'; a classic frame may end
 * in `_<dlc>` (len8_dlc 9..F). A trailing direction marker ` R` / ` T` (candump -x) is
 * accepted. Error frames become SC_CAN_FLAG_ERR frames whose id holds SC_CAN_ERRF_* classes
 * (sc_socketcan_errf_from_linux), and are written back in Linux CAN_ERR_* form.
 *
 * The parser takes outside input: every malformed line is rejected with a named reason and
 * counted, never crashes, never reads past len. Time stamps are kept in microseconds, the
 * log's resolution: a frame's ts_ns is written rounded down to whole microseconds.
 * The line functions are pure; the reader and writer use stdio. Nothing allocates.
 */
#ifndef SC_CANDUMP_H
#define SC_CANDUMP_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "sc_hal_can.h"

#define SC_CANDUMP_IFNAME_MAX 15u  /* IFNAMSIZ - 1 */
#define SC_CANDUMP_LINE_MAX   256u /* longest valid line: FD, 64 bytes with dots < 256 */

typedef enum sc_candump_reject {
    SC_CDR_OK = 0,
    SC_CDR_EMPTY,         /* blank line */
    SC_CDR_LINE_TOO_LONG, /* longer than SC_CANDUMP_LINE_MAX */
    SC_CDR_TIMESTAMP,     /* missing or malformed "(sec.usec)" (6 fraction digits) */
    SC_CDR_IFACE,         /* missing interface name, or longer than 15 characters */
    SC_CDR_ID,            /* id not 3 or 8 hex digits, or out of range */
    SC_CDR_SEPARATOR,     /* no '#' after the id, or "###" (CAN XL, not supported) */
    SC_CDR_DATA,          /* odd number of hex digits, non-hex, misplaced '.' */
    SC_CDR_LENGTH,        /* too many bytes (classic > 8, FD > 64) or invalid FD length */
    SC_CDR_FD_FLAGS,      /* FD flags digit missing or not hex */
    SC_CDR_DLC,           /* bad "_<dlc>" suffix or remote frame length */
    SC_CDR_TRAILING,      /* unexpected characters after the frame */
    SC_CDR_COUNT
} sc_candump_reject;

const char *sc_candump_reject_name(sc_candump_reject r);

typedef struct sc_candump_rec {
    uint64_t ts_us; /* log time stamp, microseconds */
    char iface[SC_CANDUMP_IFNAME_MAX + 1];
    sc_can_frame frame; /* frame.ts_ns = ts_us * 1000 */
} sc_candump_rec;

/* Parses one line (without or with its trailing newline / CR). 0 and *out filled, or
 * SC_ERR_PARSE and *why set. O(len). */
int sc_candump_parse_line(const char *line, size_t len, sc_candump_rec *out,
                          sc_candump_reject *why);

/* Formats one record as a candump -l line with '\n' and a terminating NUL. Returns the
 * number of characters (without the NUL), SC_ERR_NO_SPACE when cap is too small,
 * SC_ERR_INVALID_ARG for a frame that cannot be written (bad length, bad interface name). */
int sc_candump_format(const sc_candump_rec *r, char *buf, size_t cap);

/* Reads records from a stream, skipping and counting malformed lines. */
typedef struct sc_candump_reader {
    FILE *fp;
    uint32_t line_no;                /* lines read so far */
    uint32_t records;                /* good records returned */
    uint32_t rejected[SC_CDR_COUNT]; /* per reason */
    uint32_t last_reject_line;
    sc_candump_reject last_reject;
} sc_candump_reader;

void sc_candump_reader_init(sc_candump_reader *r, FILE *fp);
/* Next good record: 0; SC_ERR_NOT_FOUND at the end of the stream; SC_ERR_IO on a read
 * error. O(line length) per line read. */
int sc_candump_reader_next(sc_candump_reader *r, sc_candump_rec *out);
uint32_t sc_candump_reader_rejected_total(const sc_candump_reader *r);

/* Writes one record as a line: 0, or the errors of sc_candump_format, SC_ERR_IO. */
int sc_candump_write(FILE *fp, const sc_candump_rec *r);

#endif /* SC_CANDUMP_H */
