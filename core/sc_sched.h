/*
 * sc_sched.h: the frame scheduler.
 *
 * A fixed period (default 60 Hz) and a fixed list of stages, run in order once per frame.
 * Each frame: sleep until the release time (absolute, through the HAL clock), run every
 * stage timing it on the HAL clock, then compare the end with the deadline (release + period).
 * A miss is counted and the schedule resynchronises to the next period boundary after the end:
 * late frames are never queued up or run back to back to "catch up".
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

typedef void (*sc_stage_fn)(void *user);

typedef struct sc_sched_def {
    uint32_t rate_hz; /* SC_FRAME_RATE_MIN_HZ .. SC_FRAME_RATE_MAX_HZ */
} sc_sched_def;

typedef struct sc_sched_stage {
    const char *name; /* static string */
    sc_stage_fn fn;
    sc_stats stats; /* execution time of this stage */
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
    sc_stats frame_stats;    /* execution time start..end of whole frames */
    sc_stats lateness_stats; /* start - release: wake-up latency */
    sc_sched_stage stages[SC_SCHED_MAX_STAGES];
} sc_sched;

sc_sched_def sc_sched_default_def(void);

/* Validate def and reset all state and statistics. O(stages). Errors: SC_ERR_INVALID_ARG
 * (NULL), SC_ERR_RANGE (rate outside limits). */
int sc_sched_init(sc_sched *s, const sc_sched_def *def, const sc_clock_dev *clock);

/* Append a stage. O(1). SC_ERR_NO_SPACE beyond SC_SCHED_MAX_STAGES, SC_ERR_STATE once started. */
int sc_sched_add_stage(sc_sched *s, const char *name, sc_stage_fn fn);

/* Change the period between frames; takes effect from the next release. SC_ERR_RANGE. */
int sc_sched_set_rate(sc_sched *s, uint32_t rate_hz);

/* Run one frame: wait for the release, run all stages, detect a miss, plan the next release.
 * O(stages) plus the stages' own cost. The first call releases immediately. */
void sc_sched_run_frame(sc_sched *s, void *user, sc_frame_result *out);

/* Misses among the last n (<= 64) frames. */
uint32_t sc_sched_recent_misses(const sc_sched *s, uint32_t n);

void sc_sched_reset_stats(sc_sched *s);

#endif /* SC_SCHED_H */
