/*
 * sc_frame_trace.h: every frame's times kept in memory during a run and written as CSV at its
 * end (sonocomp --trace FILE): frame number, wake-up lateness, the whole frame, whether it
 * missed its deadline, and each scheduler stage (sc_sched.h), in microseconds. For deadline
 * evidence that a histogram cannot give: which frames were slow, and whether they cluster at
 * a phase of the probe's script (a press, a sweep's folds) or spread over the run (the host).
 *
 * The frame loop only stores integers (O(stages) per frame, no I/O, no allocation); the file
 * is opened before the run (a bad path is refused at once) and written after it. Frames past
 * the capacity are counted, not kept, and the count is reported. Allocation: at open only.
 * Threads: one caller.
 */
#ifndef SC_FRAME_TRACE_H
#define SC_FRAME_TRACE_H

#include <stdint.h>
#include <stdio.h>

#include "sc_sched.h"

/* frames kept when the run's length is not known (an hour at 60 Hz), and the most ever kept */
#define SC_FRAME_TRACE_DEFAULT_FRAMES 216000u
#define SC_FRAME_TRACE_MAX_FRAMES     1080000u

typedef struct sc_frame_trace {
    FILE *f;
    uint32_t stages;  /* stage columns (the scheduler's stages at open) */
    uint32_t cols;    /* 4 + stages */
    uint32_t cap, n;  /* records kept: capacity, used */
    uint64_t dropped; /* frames past the capacity */
    uint32_t *rec;    /* cap x cols */
    const char *names[SC_SCHED_MAX_STAGES];
} sc_frame_trace;

/* Open path for writing and keep room for `frames` records (0: the default; capped at the
 * maximum) of the scheduler's stages. 0, or -1 with errno (the file, or ENOMEM). */
int sc_frame_trace_open(sc_frame_trace *t, const char *path, uint64_t frames, const sc_sched *s);

/* The frame just ended (fr from sc_sched_end_frame, the stages' last times from s). O(stages). */
void sc_frame_trace_add(sc_frame_trace *t, const sc_frame_result *fr, const sc_sched *s);

/* Write the kept frames as CSV, close the file, free the records. 0, or -1 with errno. */
int sc_frame_trace_close(sc_frame_trace *t);

#endif /* SC_FRAME_TRACE_H */
