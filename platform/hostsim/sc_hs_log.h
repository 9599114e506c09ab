/*
 * sc_hs_log.h: the host simulator's log: a fixed ring of the last records, counts per level,
 * and optional printing to stderr (off by default so tests stay quiet).
 */
#ifndef SC_HS_LOG_H
#define SC_HS_LOG_H

#include <stdint.h>

#include "sc_hal_log.h"

#ifndef SC_HS_LOG_RING
#define SC_HS_LOG_RING 256u
#endif

typedef struct sc_hs_log_record {
    sc_log_level level;
    const char *event;
    int err;
    int64_t a, b;
} sc_hs_log_record;

typedef struct sc_hs_log {
    sc_hs_log_record ring[SC_HS_LOG_RING];
    uint64_t total;
    uint64_t per_level[4];
    int print; /* 1: also print each record to stderr */
} sc_hs_log;

void sc_hs_log_init(sc_hs_log *l, int print);
sc_log_dev sc_hs_log_dev(sc_hs_log *l);
/* Number of records with this event name among the ones kept in the ring. */
uint32_t sc_hs_log_count_event(const sc_hs_log *l, const char *event);

#endif /* SC_HS_LOG_H */
