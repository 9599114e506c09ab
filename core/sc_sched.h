/*
 * sc_sched.h: the frame scheduler.
 *
 * A fixed period (default 60 Hz). The caller runs the frame's stages itself, in its own code,
 * and marks the end of each: sc_sched_begin_frame() sleeps until the release time (absolute,
 * through the HAL clock), sc_sched_stage_done() charges the time since the previous mark to a
 * named stage, sc_sched_end_frame() compares the end with the deadline (release + period).
 * A miss is counted and the schedule resynchronises to the next period boundary after the end:
 * late frames are never queued up or run back to back to "catch up". sc_sched_slack_ns() tells
 * work between stages how much of the period is left.
 *
 * Memory: all state inside sc_sched (about 12 KiB with 8 stages); never allocates.
 * Threads: one sc_sched is driven by one thread. Never calls the OS: time comes from hal clock.
 */
#ifndef SC_SCHED_H
#define SC_SCHED_H

#include <stdint.h>

#include "sc_config.h"
#include "sc_hal_clock.h"
#include "sc_stats.h"

typedef struct sc_sched_def {
    uint32_t rate_hz; /* SC_FRAME_RATE_MIN_HZ .. SC_FRAME_RATE_MAX_HZ */
} sc_sched_def;

typedef struct sc_sched_stage {
    const char *name; /* static string */
    sc_stats stats;   /* execution time of this stage */
    uint64_t last_ns; /* its time in the running (or last) frame; 0 until it is marked */
} sc_sched_stage;

typedef struct sc_frame_result {
    uint64_t frame_no;       /* 0-based index of the frame just run */
    uint64_t release_ns;     /* nominal start */
    uint64_t start_ns;       /* when the first stage began */
    uint64_t end_ns;         /* when the last stage ended */
    uint32_t periods_skipped; /* release times abandoned because of a miss */
    uint8_t missed;          /* end_ns > release_ns + period */
} sc_frame_result;

typedef struct sc_sched {
    const sc_clock_dev *clock;
    uint64_t period_ns;
    uint64_t next_release_ns;
    uint64_t frames;
    uint64_t misses;
    uint64_t periods_skipped;
    uint64_t miss_window; /* bit i: frame (frames-1-i) missed */
    uint32_t stage_count;
    uint8_t started;
    uint8_t in_frame;
    uint64_t release_ns; /* of the running frame */
    uint64_t start_ns;
    uint64_t mark_ns;    /* end of the last stage marked */
    sc_stats frame_stats;    /* execution time start..end of whole frames */
    sc_stats lateness_stats; /* start - release: wake-up latency */
    sc_sched_stage stages[SC_SCHED_MAX_STAGES];
} sc_sched;

sc_sched_def sc_sched_default_def(void);

/* Validate def and reset all state and statistics. O(stages). Errors: SC_ERR_INVALID_ARG
 * (NULL), SC_ERR_RANGE (rate outside limits). */
int sc_sched_init(sc_sched *s, const sc_sched_def *def, const sc_clock_dev *clock);

/* Name the next timing slot (a stage). Returns its index (>= 0). O(1). SC_ERR_INVALID_ARG,
 * SC_ERR_NO_SPACE beyond SC_SCHED_MAX_STAGES, SC_ERR_STATE once started. */
int sc_sched_add_stage(sc_sched *s, const char *name);

/* Change the period between frames; takes effect from the next release. SC_ERR_RANGE. */
int sc_sched_set_rate(sc_sched *s, uint32_t rate_hz);

/* Wait for the frame's release (the first frame releases immediately) and start timing it.
 * O(stages) plus the sleep. */
void sc_sched_begin_frame(sc_sched *s);

/* The stage `stage` (an index of sc_sched_add_stage) ended now: its time is the time since the
 * frame began or the previous mark. O(log) (statistics insert). */
void sc_sched_stage_done(sc_sched *s, uint32_t stage);

/* Time left until the running frame's deadline; 0 when it has passed. O(1). */
uint64_t sc_sched_slack_ns(const sc_sched *s);

/* The frame ended now: frame statistics, miss detection, the next release. O(1). */
void sc_sched_end_frame(sc_sched *s, sc_frame_result *out);

/* Misses among the last n (<= 64) frames. */
uint32_t sc_sched_recent_misses(const sc_sched *s, uint32_t n);

void sc_sched_reset_stats(sc_sched *s);

#endif /* SC_SCHED_H */
