/* sc_can_replay.c: see sc_can_replay.h. */
#include "sc_can_replay.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_err.h"
#include "sc_rt.h"
#include "sc_storage_linux.h"

static uint64_t rt_now(void *ctx)
{
    (void)ctx;
    return sc_rt_now_ns();
}

int sc_can_replay_open(sc_can_replay *r, const char *path, sc_can_replay_now_fn now, void *now_ctx)
{
    memset(r, 0, sizeof *r);
    r->now = now ? now : rt_now;
    r->now_ctx = now_ctx;
    FILE *fp = sc_fopen_regular(path); /* a FIFO or device is refused, never waited on */
    if (!fp) {
        return errno == ENOENT ? SC_ERR_NOT_FOUND : SC_ERR_IO;
    }
    sc_candump_reader rd;
    sc_candump_reader_init(&rd, fp);
    size_t cap = 0;
    uint64_t first_us = 0;
    int rc = 0;
    for (;;) {
        sc_candump_rec rec;
        int n = sc_candump_reader_next(&rd, &rec);
        if (n == SC_ERR_NOT_FOUND) {
            break;
        }
        if (n != 0) {
            rc = n;
            break;
        }
        if (r->count == cap) {
            size_t ncap = cap ? cap * 2u : 1024u;
            sc_can_frame *nf = realloc(r->frames, ncap * sizeof *nf);
            if (!nf) {
                rc = SC_ERR_NO_SPACE;
                break;
            }
            r->frames = nf;
            cap = ncap;
        }
        if (r->count == 0u) {
            first_us = rec.ts_us;
        }
        sc_can_frame f = rec.frame;
        f.ts_ns = rec.ts_us > first_us ? (rec.ts_us - first_us) * 1000u : 0u;
        if (f.ts_ns > r->duration_ns) {
            r->duration_ns = f.ts_ns;
        }
        r->frames[r->count++] = f;
    }
    r->lines = rd.line_no;
    r->rejected = sc_candump_reader_rejected_total(&rd);
    if (r->rejected > 0u) {
        r->last_reject_line = rd.last_reject_line;
        r->last_reject = rd.last_reject;
    }
    fclose(fp);
    if (rc == 0 && r->count == 0u) {
        rc = SC_ERR_PARSE;
    }
    if (rc != 0) {
        free(r->frames);
        r->frames = NULL;
        r->count = 0;
    }
    return rc;
}

static int replay_send(void *ctx, const sc_can_frame *f)
{
    sc_can_replay *r = ctx;
    if (!sc_can_len_valid(f->len, f->flags)) {
        return SC_ERR_INVALID_ARG;
    }
    r->sent++;
    return 0;
}

static int replay_recv(void *ctx, sc_can_frame *out)
{
    sc_can_replay *r = ctx;
    const uint64_t now = r->now(r->now_ctx);
    if (!r->started) {
        r->started = 1;
        r->start_ns = now;
    }
    if (r->next >= r->count) {
        return SC_ERR_WOULD_BLOCK;
    }
    const sc_can_frame *f = &r->frames[r->next];
    if (f->ts_ns > now - r->start_ns) {
        return SC_ERR_WOULD_BLOCK;
    }
    *out = *f;
    out->ts_ns = r->start_ns + f->ts_ns;
    r->next++;
    r->received++;
    return 0;
}

static int replay_get_state(void *ctx, sc_can_state *state, sc_can_counters *counters)
{
    (void)ctx;
    if (state) {
        *state = SC_CAN_STATE_ERROR_ACTIVE;
    }
    if (counters) {
        memset(counters, 0, sizeof *counters);
    }
    return 0;
}

static const sc_can_ops k_replay_ops = {replay_send, replay_recv, NULL, replay_get_state};

sc_can_dev sc_can_replay_dev(sc_can_replay *r)
{
    sc_can_dev d = {&k_replay_ops, r};
    return d;
}

int sc_can_replay_done(const sc_can_replay *r)
{
    return r->next >= r->count;
}

void sc_can_replay_close(sc_can_replay *r)
{
    free(r->frames);
    r->frames = NULL;
    r->count = 0;
    r->next = 0;
}
