/* sc_hs_log.c: ring-buffer log for the host simulator, see sc_hs_log.h. */
#include "sc_hs_log.h"

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "sc_err.h"

static void hs_write(void *ctx, sc_log_level level, const char *event, int err, int64_t a,
                     int64_t b)
{
    sc_hs_log *l = ctx;
    l->ring[l->total % SC_HS_LOG_RING] =
        (sc_hs_log_record){.level = level, .event = event, .err = err, .a = a, .b = b};
    l->total++;
    if ((unsigned)level < 4u) {
        l->per_level[level]++;
    }
    if (l->print) {
        fprintf(stderr, "level=%s event=%s err=%s a=%" PRId64 " b=%" PRId64 "\n",
                sc_log_level_name(level), event, sc_err_name(err), a, b);
    }
}

static const sc_log_ops hs_log_ops = {.write = hs_write};

void sc_hs_log_init(sc_hs_log *l, int print)
{
    memset(l, 0, sizeof(*l));
    l->print = print;
}

sc_log_dev sc_hs_log_dev(sc_hs_log *l)
{
    return (sc_log_dev){.ops = &hs_log_ops, .ctx = l};
}

uint32_t sc_hs_log_count_event(const sc_hs_log *l, const char *event)
{
    uint64_t n = l->total < SC_HS_LOG_RING ? l->total : SC_HS_LOG_RING;
    uint32_t c = 0;
    for (uint64_t i = 0; i < n; i++) {
        if (l->ring[i].event && strcmp(l->ring[i].event, event) == 0) {
            c++;
        }
    }
    return c;
}
