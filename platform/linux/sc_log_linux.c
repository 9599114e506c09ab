/* sc_log_linux.c: structured log lines and the status line (see sc_log_linux.h). */
#include "sc_log_linux.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "sc_err.h"

static const char k_clear[] = "\r\033[K";

static size_t format_ts(char *buf, size_t cap, int64_t wall_ns)
{
    time_t s = (time_t)(wall_ns / 1000000000);
    struct tm tm;
    gmtime_r(&s, &tm);
    int n = snprintf(buf, cap, "ts=%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                     tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                     (int)((wall_ns / 1000000) % 1000));
    return n < 0 ? 0u : ((size_t)n < cap ? (size_t)n : cap - 1u);
}

static int64_t wall_now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

size_t sc_log_linux_format(char *buf, size_t cap, const sc_log_linux_rec *r)
{
    size_t n = format_ts(buf, cap, r->wall_ns);
    int m;
    if (r->err) {
        m = snprintf(buf + n, cap - n, " level=%s event=%s err=%s a=%lld b=%lld",
                     sc_log_level_name(r->level), r->event ? r->event : "?",
                     sc_err_name(r->err), (long long)r->a, (long long)r->b);
    } else {
        m = snprintf(buf + n, cap - n, " level=%s event=%s a=%lld b=%lld",
                     sc_log_level_name(r->level), r->event ? r->event : "?", (long long)r->a,
                     (long long)r->b);
    }
    if (m > 0) {
        n += (size_t)m < cap - n ? (size_t)m : cap - n - 1u;
    }
    return n;
}

/* Write all of buf (blocking is fine here: writer thread or non-frame code). */
static void write_all(int fd, const char *buf, size_t n)
{
    while (n > 0u) {
        ssize_t w = write(fd, buf, n);
        if (w < 0) {
            if (errno == EINTR) {
                continue;
            }
            return;
        }
        buf += w;
        n -= (size_t)w;
    }
}

/* Caller holds the lock. */
static void emit_line(sc_log_linux *l, const char *line, size_t n)
{
    char buf[600];
    size_t k = 0;
    if (l->status_active) {
        memcpy(buf, k_clear, sizeof k_clear - 1u);
        k = sizeof k_clear - 1u;
        l->status_active = 0;
    }
    if (n > sizeof buf - k - 1u) {
        n = sizeof buf - k - 1u;
    }
    memcpy(buf + k, line, n);
    k += n;
    buf[k++] = '\n';
    write_all(l->fd, buf, k);
}

static void drain(sc_log_linux *l)
{
    pthread_mutex_lock(&l->drain_lock);
    unsigned tail = atomic_load_explicit(&l->tail, memory_order_relaxed);
    unsigned head = atomic_load_explicit(&l->head, memory_order_acquire);
    while (tail != head) {
        const sc_log_linux_rec *r = &l->ring[tail & (SC_LOG_LINUX_RING - 1u)];
        char line[512];
        size_t n = sc_log_linux_format(line, sizeof line, r);
        pthread_mutex_lock(&l->lock);
        emit_line(l, line, n);
        pthread_mutex_unlock(&l->lock);
        tail++;
        atomic_store_explicit(&l->tail, tail, memory_order_release);
        atomic_fetch_add(&l->written, 1u);
    }
    pthread_mutex_unlock(&l->drain_lock);
}

static void *writer_main(void *arg)
{
    sc_log_linux *l = arg;
    const struct timespec period = {0, 10 * 1000 * 1000}; /* 10 ms: latency of a log line */
    while (atomic_load(&l->running)) {
        drain(l);
        nanosleep(&period, NULL);
    }
    drain(l);
    return NULL;
}

static void write_rec(void *ctx, sc_log_level level, const char *event, int err, int64_t a,
                      int64_t b)
{
    sc_log_linux *l = ctx;
    if (level < l->min_level) {
        return;
    }
    unsigned head = atomic_load_explicit(&l->head, memory_order_relaxed);
    unsigned tail = atomic_load_explicit(&l->tail, memory_order_acquire);
    if (head - tail >= SC_LOG_LINUX_RING) {
        atomic_fetch_add(&l->dropped, 1u);
        return;
    }
    sc_log_linux_rec *r = &l->ring[head & (SC_LOG_LINUX_RING - 1u)];
    r->wall_ns = wall_now_ns();
    r->level = level;
    r->event = event;
    r->err = err;
    r->a = a;
    r->b = b;
    atomic_store_explicit(&l->head, head + 1u, memory_order_release);
}

static const sc_log_ops k_ops = {write_rec};

int sc_log_linux_start(sc_log_linux *l, int fd, sc_log_level min_level)
{
    memset(l, 0, sizeof *l);
    l->fd = fd;
    l->min_level = min_level;
    atomic_init(&l->head, 0u);
    atomic_init(&l->tail, 0u);
    atomic_init(&l->dropped, 0u);
    atomic_init(&l->written, 0u);
    atomic_init(&l->running, 1);
    pthread_mutex_init(&l->lock, NULL);
    pthread_mutex_init(&l->drain_lock, NULL);
    if (pthread_create(&l->thread, NULL, writer_main, l) != 0) {
        atomic_store(&l->running, 0);
        return SC_ERR_IO;
    }
    l->thread_started = 1;
    return 0;
}

sc_log_dev sc_log_linux_dev(sc_log_linux *l)
{
    sc_log_dev d = {&k_ops, l};
    return d;
}

void sc_log_linux_stop(sc_log_linux *l)
{
    if (l->thread_started) {
        atomic_store(&l->running, 0);
        pthread_join(l->thread, NULL);
        l->thread_started = 0;
    } else {
        drain(l);
    }
}

void sc_log_linux_msg(sc_log_linux *l, sc_log_level level, const char *event, const char *fmt, ...)
{
    if (level < l->min_level) {
        return;
    }
    char line[512];
    size_t n = format_ts(line, sizeof line, wall_now_ns());
    int m = snprintf(line + n, sizeof line - n, " level=%s event=%s",
                     sc_log_level_name(level), event);
    if (m > 0) {
        n += (size_t)m < sizeof line - n ? (size_t)m : sizeof line - n - 1u;
    }
    if (fmt && fmt[0] && n + 2u < sizeof line) {
        line[n++] = ' ';
        va_list ap;
        va_start(ap, fmt);
        m = vsnprintf(line + n, sizeof line - n, fmt, ap);
        va_end(ap);
        if (m > 0) {
            n += (size_t)m < sizeof line - n ? (size_t)m : sizeof line - n - 1u;
        }
    }
    drain(l); /* records logged before this message go out before it */
    pthread_mutex_lock(&l->lock);
    emit_line(l, line, n);
    pthread_mutex_unlock(&l->lock);
}

void sc_log_linux_set_status_mode(sc_log_linux *l, int terminal)
{
    pthread_mutex_lock(&l->lock);
    l->status_enabled = terminal;
    pthread_mutex_unlock(&l->lock);
}

void sc_log_linux_status(sc_log_linux *l, const char *text)
{
    pthread_mutex_lock(&l->lock);
    if (l->status_enabled) {
        char buf[512];
        int m = snprintf(buf, sizeof buf, "%s%s", k_clear, text);
        if (m > 0) {
            write_all(l->fd, buf, (size_t)m < sizeof buf ? (size_t)m : sizeof buf - 1u);
        }
        l->status_active = 1;
    }
    pthread_mutex_unlock(&l->lock);
}

void sc_log_linux_status_done(sc_log_linux *l)
{
    pthread_mutex_lock(&l->lock);
    if (l->status_active) {
        write_all(l->fd, "\n", 1u);
        l->status_active = 0;
    }
    pthread_mutex_unlock(&l->lock);
}

uint64_t sc_log_linux_dropped(sc_log_linux *l)
{
    return atomic_load(&l->dropped);
}
