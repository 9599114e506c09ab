/* sc_frame_trace.c: every frame's times as CSV at the end of a run, see sc_frame_trace.h. */
#include "sc_frame_trace.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

static uint32_t us(uint64_t ns)
{
    const uint64_t u = ns / 1000u;
    return u > UINT32_MAX ? UINT32_MAX : (uint32_t)u;
}

int sc_frame_trace_open(sc_frame_trace *t, const char *path, uint64_t frames, const sc_sched *s)
{
    memset(t, 0, sizeof *t);
    if (path == NULL || s == NULL) {
        errno = EINVAL;
        return -1;
    }
    const uint64_t want = frames == 0u ? SC_FRAME_TRACE_DEFAULT_FRAMES : frames;
    t->cap = (uint32_t)(want < SC_FRAME_TRACE_MAX_FRAMES ? want : SC_FRAME_TRACE_MAX_FRAMES);
    t->stages = s->stage_count < SC_SCHED_MAX_STAGES ? s->stage_count : SC_SCHED_MAX_STAGES;
    t->cols = 4u + t->stages;
    for (uint32_t i = 0; i < t->stages; i++) {
        t->names[i] = s->stages[i].name;
    }
    const size_t bytes = (size_t)t->cap * t->cols * sizeof(uint32_t);
    t->rec = malloc(bytes);
    if (t->rec == NULL) {
        errno = ENOMEM;
        return -1;
    }
    /* every page touched now, not on the frame loop's first write to it (locked memory is
     * faulted in at the allocation; this covers a run without rt.mlock) */
    volatile uint8_t *pg = (volatile uint8_t *)t->rec;
    for (size_t o = 0; o < bytes; o += 4096u) {
        pg[o] = 0u;
    }
    t->f = fopen(path, "w");
    if (t->f == NULL) {
        const int e = errno;
        free(t->rec);
        t->rec = NULL;
        errno = e;
        return -1;
    }
    return 0;
}

void sc_frame_trace_add(sc_frame_trace *t, const sc_frame_result *fr, const sc_sched *s)
{
    if (t->rec == NULL) {
        return;
    }
    if (t->n >= t->cap) {
        t->dropped++;
        return;
    }
    uint32_t *r = &t->rec[(size_t)t->n * t->cols];
    r[0] = (uint32_t)fr->frame_no;
    r[1] = us(fr->start_ns > fr->release_ns ? fr->start_ns - fr->release_ns : 0u);
    r[2] = us(fr->end_ns > fr->start_ns ? fr->end_ns - fr->start_ns : 0u);
    r[3] = fr->missed;
    for (uint32_t i = 0; i < t->stages; i++) {
        r[4u + i] = us(s->stages[i].last_ns);
    }
    t->n++;
}

int sc_frame_trace_close(sc_frame_trace *t)
{
    int rc = 0;
    if (t->f != NULL) {
        fprintf(t->f, "frame,wakeup_late_us,frame_us,missed");
        for (uint32_t i = 0; i < t->stages; i++) {
            fprintf(t->f, ",%s_us", t->names[i] != NULL ? t->names[i] : "stage");
        }
        fputc('\n', t->f);
        for (uint32_t k = 0; k < t->n; k++) {
            const uint32_t *r = &t->rec[(size_t)k * t->cols];
            fprintf(t->f, "%u,%u,%u,%u", r[0], r[1], r[2], r[3]);
            for (uint32_t i = 0; i < t->stages; i++) {
                fprintf(t->f, ",%u", r[4u + i]);
            }
            fputc('\n', t->f);
        }
        /* the first failure's reason: a write's (EIO when the stream kept none), else fclose's
         * (the buffered rows did not reach the file) */
        int err = ferror(t->f) ? (errno != 0 ? errno : EIO) : 0;
        if (fclose(t->f) != 0 && err == 0) {
            err = errno;
        }
        t->f = NULL;
        if (err != 0) {
            rc = -1;
            errno = err;
        }
    }
    free(t->rec);
    t->rec = NULL;
    return rc;
}
