/* sc_sched.c: fixed-period frame scheduler, see sc_sched.h. */
#include "sc_sched.h"

#include "sc_assert.h"
#include "sc_err.h"

#define NS_PER_S 1000000000ull

sc_sched_def sc_sched_default_def(void)
{
    return (sc_sched_def){.rate_hz = SC_FRAME_RATE_DEFAULT_HZ};
}

static int rate_valid(uint32_t rate_hz)
{
    return rate_hz >= SC_FRAME_RATE_MIN_HZ && rate_hz <= SC_FRAME_RATE_MAX_HZ;
}

void sc_sched_reset_stats(sc_sched *s)
{
    sc_stats_reset(&s->frame_stats);
    sc_stats_reset(&s->lateness_stats);
    for (uint32_t i = 0; i < s->stage_count; i++) {
        sc_stats_reset(&s->stages[i].stats);
    }
    s->misses = 0;
    s->periods_skipped = 0;
    s->miss_window = 0;
}

int sc_sched_init(sc_sched *s, const sc_sched_def *def, const sc_clock_dev *clock)
{
    if (!s || !def || !clock || !clock->ops) {
        return SC_ERR_INVALID_ARG;
    }
    if (!rate_valid(def->rate_hz)) {
        return SC_ERR_RANGE;
    }
    *s = (sc_sched){0};
    s->clock = clock;
    s->period_ns = NS_PER_S / def->rate_hz;
    sc_sched_reset_stats(s);
    return SC_OK;
}

int sc_sched_add_stage(sc_sched *s, const char *name)
{
    if (!s || !name) {
        return SC_ERR_INVALID_ARG;
    }
    if (s->started) {
        return SC_ERR_STATE;
    }
    if (s->stage_count >= SC_SCHED_MAX_STAGES) {
        return SC_ERR_NO_SPACE;
    }
    sc_sched_stage *st = &s->stages[s->stage_count];
    st->name = name;
    sc_stats_reset(&st->stats);
    return (int)s->stage_count++;
}

int sc_sched_set_rate(sc_sched *s, uint32_t rate_hz)
{
    if (!s) {
        return SC_ERR_INVALID_ARG;
    }
    if (!rate_valid(rate_hz)) {
        return SC_ERR_RANGE;
    }
    s->period_ns = NS_PER_S / rate_hz;
    return SC_OK;
}

void sc_sched_begin_frame(sc_sched *s)
{
    SC_ASSERT(s && s->clock && !s->in_frame);
    if (!s->started) {
        s->started = 1;
        s->next_release_ns = sc_clock_now_ns(s->clock);
    }
    s->release_ns = s->next_release_ns;
    (void)sc_clock_sleep_until_ns(s->clock, s->release_ns);
    s->start_ns = sc_clock_now_ns(s->clock);
    s->mark_ns = s->start_ns;
    for (uint32_t i = 0; i < s->stage_count; i++) {
        s->stages[i].last_ns = 0u; /* a stage this frame does not mark reads 0 */
    }
    s->in_frame = 1;
}

void sc_sched_stage_done(sc_sched *s, uint32_t stage)
{
    SC_ASSERT(s && s->in_frame && stage < s->stage_count);
    const uint64_t t = sc_clock_now_ns(s->clock);
    sc_stats_add(&s->stages[stage].stats, t - s->mark_ns);
    s->stages[stage].last_ns = t - s->mark_ns;
    s->mark_ns = t;
}

uint64_t sc_sched_slack_ns(const sc_sched *s)
{
    const uint64_t deadline = s->release_ns + s->period_ns;
    const uint64_t now = sc_clock_now_ns(s->clock);
    return now < deadline ? deadline - now : 0u;
}

void sc_sched_end_frame(sc_sched *s, sc_frame_result *out)
{
    SC_ASSERT(s && s->in_frame);
    s->in_frame = 0;
    const uint64_t release = s->release_ns;
    const uint64_t start = s->start_ns;
    const uint64_t end = sc_clock_now_ns(s->clock);
    sc_stats_add(&s->frame_stats, end - start);
    sc_stats_add(&s->lateness_stats, start >= release ? start - release : 0u);

    const uint64_t deadline = release + s->period_ns;
    const uint8_t missed = end > deadline;
    uint64_t k = 1; /* periods to advance */
    if (missed) {
        /* resynchronise: the first period boundary strictly after the end */
        k = (end - release) / s->period_ns + 1u;
        s->misses++;
        s->periods_skipped += k - 1u;
    }
    s->next_release_ns = release + k * s->period_ns;
    s->miss_window = (s->miss_window << 1u) | (uint64_t)missed;

    if (out) {
        *out = (sc_frame_result){
            .frame_no = s->frames,
            .release_ns = release,
            .start_ns = start,
            .end_ns = end,
            .periods_skipped = (uint32_t)(k - 1u),
            .missed = missed,
        };
    }
    s->frames++;
}

uint32_t sc_sched_recent_misses(const sc_sched *s, uint32_t n)
{
    if (n > 64u) {
        n = 64u;
    }
    uint64_t mask = n == 64u ? UINT64_MAX : (((uint64_t)1u << n) - 1u);
    uint64_t v = s->miss_window & mask;
    uint32_t c = 0;
    while (v) {
        v &= v - 1u;
        c++;
    }
    return c;
}
