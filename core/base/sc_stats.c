/* sc_stats.c: log-linear duration histogram, see sc_stats.h. */
#include "sc_stats.h"

#include "sc_assert.h"

SC_STATIC_ASSERT(SC_STATS_BINS == 320u, "histogram layout changed: update docs");

void sc_stats_reset(sc_stats *s)
{
    SC_ASSERT(s != 0);
    *s = (sc_stats){0};
    s->best_ns = UINT64_MAX;
}

static uint32_t floor_log2_u64(uint64_t v)
{
    uint32_t r = 0;
    while (v >>= 1u) {
        r++;
    }
    return r;
}

uint32_t sc_stats_bin_of_us(uint64_t us)
{
    if (us < SC_STATS_SUB) {
        return (uint32_t)us;
    }
    uint32_t e = floor_log2_u64(us); /* >= SC_STATS_SUB_BITS */
    uint32_t octave = e - SC_STATS_SUB_BITS;
    if (octave >= SC_STATS_OCTAVES) {
        return SC_STATS_BINS - 1u;
    }
    uint32_t sub = (uint32_t)((us >> octave) & (SC_STATS_SUB - 1u));
    return SC_STATS_SUB + octave * SC_STATS_SUB + sub;
}

uint64_t sc_stats_bin_upper_us(uint32_t bin)
{
    SC_ASSERT(bin < SC_STATS_BINS);
    if (bin < SC_STATS_SUB) {
        return bin;
    }
    uint32_t octave = (bin - SC_STATS_SUB) / SC_STATS_SUB;
    uint32_t sub = (bin - SC_STATS_SUB) % SC_STATS_SUB;
    uint64_t lo = ((uint64_t)(SC_STATS_SUB + sub)) << octave;
    return lo + (((uint64_t)1u << octave) - 1u);
}

void sc_stats_add(sc_stats *s, uint64_t duration_ns)
{
    s->count++;
    s->sum_ns += duration_ns;
    if (duration_ns > s->worst_ns) {
        s->worst_ns = duration_ns;
    }
    if (duration_ns < s->best_ns) {
        s->best_ns = duration_ns;
    }
    uint32_t bin = sc_stats_bin_of_us(duration_ns / 1000u);
    if (s->hist[bin] != UINT32_MAX) {
        s->hist[bin]++;
    }
}

uint64_t sc_stats_mean_ns(const sc_stats *s)
{
    return s->count ? s->sum_ns / s->count : 0u;
}

uint64_t sc_stats_percentile_ns(const sc_stats *s, uint32_t permille)
{
    uint64_t total = 0;
    for (uint32_t i = 0; i < SC_STATS_BINS; i++) {
        total += s->hist[i];
    }
    if (total == 0u) {
        return 0u;
    }
    if (permille > 1000u) {
        permille = 1000u;
    }
    /* rank of the sample, 1-based, rounded up: the p-th permille sample */
    uint64_t rank = (total * permille + 999u) / 1000u;
    if (rank == 0u) {
        rank = 1u;
    }
    uint64_t seen = 0;
    for (uint32_t i = 0; i < SC_STATS_BINS; i++) {
        seen += s->hist[i];
        if (seen >= rank) {
            uint64_t upper_ns = (sc_stats_bin_upper_us(i) + 1u) * 1000u - 1u;
            /* never report more than the worst seen */
            return upper_ns < s->worst_ns ? upper_ns : s->worst_ns;
        }
    }
    return s->worst_ns;
}
