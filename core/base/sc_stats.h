/*
 * sc_stats.h: duration statistics in fixed storage.
 *
 * Count, sum, best, worst and a log-linear histogram (16 sub-buckets per power of two of
 * microseconds, so a percentile is reported within 1/16 = 6.25% of the true value, rounded
 * up; exact below 16 us). 320 bins cover 0 us .. about 8.6 s; longer durations land in the
 * last bin and still count in worst. Never allocates; every call O(1) except
 * sc_stats_percentile_ns, O(SC_STATS_BINS).
 */
#ifndef SC_STATS_H
#define SC_STATS_H

#include <stdint.h>

#define SC_STATS_SUB_BITS 4u
#define SC_STATS_SUB (1u << SC_STATS_SUB_BITS)
#define SC_STATS_OCTAVES 19u
#define SC_STATS_BINS (SC_STATS_SUB + SC_STATS_OCTAVES * SC_STATS_SUB) /* 320 */

typedef struct sc_stats {
    uint64_t count;
    uint64_t sum_ns;
    uint64_t best_ns;
    uint64_t worst_ns;
    uint32_t hist[SC_STATS_BINS]; /* saturating counts */
} sc_stats; /* 1,312 bytes */

void sc_stats_reset(sc_stats *s);
void sc_stats_add(sc_stats *s, uint64_t duration_ns);
/* Upper bound of the bin holding the p-th permille sample (p in 0..1000), in ns; 0 when empty. */
uint64_t sc_stats_percentile_ns(const sc_stats *s, uint32_t permille);
uint64_t sc_stats_mean_ns(const sc_stats *s);

/* Exposed for tests: bin of a duration in microseconds, and the bin's upper bound in us. */
uint32_t sc_stats_bin_of_us(uint64_t us);
uint64_t sc_stats_bin_upper_us(uint32_t bin);

#endif /* SC_STATS_H */
