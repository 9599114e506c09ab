/*
 * sc_png_sink.h: hal display (sc_hal_display.h) that writes frames as PNG files, for machines
 * without a display (bench, CI, the README's main job): DIR/frame_000042.png, scan-converted
 * to the image's physical aspect (sc_scanconv.h) in a fixed raster.
 *
 * The frame loop only copies lines into a frame buffer (O(samples) per line). At frame_end a
 * complete frame is handed to a writer thread when it is idle (one memcpy of the frame), else
 * it is skipped and counted: file system latency never reaches the frame loop. Incomplete
 * frames (lines missing) are written too, with the missing lines black, and counted.
 *
 * Allocation: at open only (frame buffers, scan-conversion table, raster). Threads: one caller
 * for the device, plus the sink's own writer thread.
 */
#ifndef SC_PNG_SINK_H
#define SC_PNG_SINK_H

#include <stdint.h>

#include "sc_hal_display.h"

typedef struct sc_png_sink sc_png_sink;

typedef struct sc_png_sink_def {
    const char *dir;     /* must exist */
    uint32_t width_px;   /* canvas; 0: 512 (a file is the image's box in it) */
    uint32_t height_px;  /* 0: 512 */
    uint32_t every_n;    /* write every n-th frame (by frame number); 0 or 1: all */
    uint32_t max_frames; /* stop writing after this many files; 0: no limit */
} sc_png_sink_def;

typedef struct sc_png_sink_stats {
    uint64_t frames;         /* frame_end calls */
    uint64_t frames_written; /* files written */
    uint64_t frames_busy;    /* skipped: writer still busy with the previous one */
    uint64_t frames_incomplete;
    uint64_t write_errors;
    uint64_t protocol_errors;
} sc_png_sink_stats;

/* 0, SC_ERR_INVALID_ARG, SC_ERR_NOT_FOUND (dir missing), SC_ERR_IO (thread or memory). */
int sc_png_sink_open(sc_png_sink **out, const sc_png_sink_def *def);
sc_display_dev sc_png_sink_dev(sc_png_sink *s);
void sc_png_sink_get_stats(sc_png_sink *s, sc_png_sink_stats *st);
/* Finish the pending file, stop the writer and free everything. */
void sc_png_sink_close(sc_png_sink *s);

#endif /* SC_PNG_SINK_H */
