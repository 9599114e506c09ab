/*
 * sc_log_linux.h: hal log (sc_hal_log.h) for Linux: structured key=value lines on stderr
 * (logfmt: `ts=2026-11-21T23:45:01.123Z level=warn event=tracker_timeout err=SC_ERR_TIMEOUT
 * a=3 b=0`), plus the live status line of an interactive run.
 *
 * The frame loop never writes to a file descriptor: sc_log records go into a fixed ring
 * (SC_LOG_LINUX_RING records, single producer: the engine thread) and a writer thread formats
 * and writes them; a full ring drops the record and counts it. Platform messages from other
 * code (start-up, shutdown; free text) and the status line are written directly under the
 * writer's lock, so lines never interleave; a platform message first drains the ring, so
 * records keep their order. When the status line is on, a log line first
 * clears it ("\r\033[K") and the next status update redraws it.
 *
 * Allocation: none after sc_log_linux_start (the ring is inside the struct). Thread rules:
 * sc_log (the dev's write) from one thread; the other functions from any thread.
 */
#ifndef SC_LOG_LINUX_H
#define SC_LOG_LINUX_H

#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdint.h>

#include "sc_hal_log.h"

#ifndef SC_LOG_LINUX_RING
#define SC_LOG_LINUX_RING 256u
#endif
_Static_assert((SC_LOG_LINUX_RING & (SC_LOG_LINUX_RING - 1u)) == 0u, "ring size a power of 2");

typedef struct sc_log_linux_rec {
    int64_t wall_ns; /* CLOCK_REALTIME at the call */
    sc_log_level level;
    const char *event; /* static string */
    int err;
    int64_t a, b;
} sc_log_linux_rec;

typedef struct sc_log_linux {
    int fd; /* 2 unless a test redirects */
    sc_log_level min_level;
    int status_active;     /* a status line is on screen (tty mode) */
    int status_enabled;    /* draw the status line with '\r' (terminal) */
    atomic_uint head;      /* next write (producer) */
    atomic_uint tail;      /* next read (writer thread) */
    atomic_ullong dropped; /* ring full */
    atomic_ullong written; /* records written out */
    atomic_int running;
    pthread_t thread;
    int thread_started;
    pthread_mutex_t lock;       /* one line at a time on fd */
    pthread_mutex_t drain_lock; /* one consumer of the ring at a time */
    sc_log_linux_rec ring[SC_LOG_LINUX_RING];
} sc_log_linux;

/* Start the writer thread. fd: where lines go (2 = stderr). 0 or SC_ERR_IO. */
int sc_log_linux_start(sc_log_linux *l, int fd, sc_log_level min_level);
/* The hal device for the engine. */
sc_log_dev sc_log_linux_dev(sc_log_linux *l);
/* Drain the ring, stop and join the writer. Idempotent. */
void sc_log_linux_stop(sc_log_linux *l);
/* A platform message: `event` plus free-form key=value text (printf format). Written at once. */
void sc_log_linux_msg(sc_log_linux *l, sc_log_level level, const char *event, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* Draw the status line (terminal mode: '\r', no newline; otherwise it is not drawn). */
void sc_log_linux_set_status_mode(sc_log_linux *l, int terminal);
void sc_log_linux_status(sc_log_linux *l, const char *text);
/* End the status line with a newline (before final reports). */
void sc_log_linux_status_done(sc_log_linux *l);
uint64_t sc_log_linux_dropped(sc_log_linux *l);

/* Format one record into buf (no newline); returns its length. Exposed for tests. */
size_t sc_log_linux_format(char *buf, size_t cap, const sc_log_linux_rec *r);

#endif /* SC_LOG_LINUX_H */
