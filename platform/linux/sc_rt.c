/* sc_rt.c: Linux real-time helpers (see sc_rt.h). */
#include "sc_rt.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/watchdog.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include "sc_err.h"

/* ---- clock ------------------------------------------------------------------------------ */

uint64_t sc_rt_now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static uint64_t clock_now(void *ctx)
{
    (void)ctx;
    return sc_rt_now_ns();
}

static int clock_sleep_until(void *ctx, uint64_t t_ns)
{
    (void)ctx;
    struct timespec ts = {(time_t)(t_ns / 1000000000u), (long)(t_ns % 1000000000u)};
    for (;;) {
        int rc = clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
        if (rc == 0) {
            return 0;
        }
        if (rc != EINTR) {
            return SC_ERR_IO;
        }
        /* a signal: resume until the release time; the loop checks the stop flag per frame */
    }
}

static const sc_clock_ops k_clock_ops = {clock_now, clock_sleep_until};

sc_clock_dev sc_rt_clock_dev(void)
{
    sc_clock_dev d = {&k_clock_ops, NULL};
    return d;
}

/* ---- process set-up --------------------------------------------------------------------- */

sc_rt_def sc_rt_default_def(void)
{
    sc_rt_def d = {.mlock = 1,
                   .prefault_stack_bytes = 256u * 1024u,
                   .sched_fifo = 1,
                   .priority = 80,
                   .cpu = -1};
    return d;
}

int sc_rt_advise_hugepages(void *p, size_t n)
{
    const uintptr_t huge = (uintptr_t)2u << 20;
    const uintptr_t a = ((uintptr_t)p + huge - 1u) & ~(huge - 1u);
    const uintptr_t e = ((uintptr_t)p + n) & ~(huge - 1u);
    if (p == NULL || e <= a) {
        return 1;
    }
    return madvise((void *)a, (size_t)(e - a), MADV_HUGEPAGE) == 0 ? 0 : SC_ERR_IO;
}

void sc_rt_prefault(void *p, size_t n)
{
    const long page = sysconf(_SC_PAGESIZE);
    const size_t step = page > 0 ? (size_t)page : 4096u;
    volatile uint8_t *b = p;
    for (size_t i = 0; i < n; i += step) {
        b[i] = 0;
    }
    if (n) {
        b[n - 1u] = 0;
    }
}

/* Touch the stack below us so its pages are resident (and locked). */
static void __attribute__((noinline)) prefault_stack(size_t n)
{
    volatile uint8_t buf[64 * 1024];
    for (size_t i = 0; i < sizeof buf; i += 256u) {
        buf[i] = 0;
    }
    if (n > sizeof buf) {
        prefault_stack(n - sizeof buf);
    }
}

int sc_rt_apply(const sc_rt_def *def, sc_rt_report *rep)
{
    memset(rep, 0, sizeof *rep);
    int fell_back = 0;
    if (def->mlock) {
        if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
            rep->locked = 1;
        } else {
            rep->lock_errno = errno;
            fell_back = 1;
        }
        prefault_stack(def->prefault_stack_bytes ? def->prefault_stack_bytes : 256u * 1024u);
    }
    if (def->cpu >= 0) {
        cpu_set_t set;
        CPU_ZERO(&set);
        if (def->cpu < CPU_SETSIZE) {
            CPU_SET((size_t)def->cpu, &set);
            if (sched_setaffinity(0, sizeof set, &set) == 0) {
                rep->pinned = 1;
            } else {
                rep->pin_errno = errno;
                fell_back = 1;
            }
        } else {
            rep->pin_errno = EINVAL;
            fell_back = 1;
        }
    }
    if (def->sched_fifo) {
        struct sched_param sp = {.sched_priority = def->priority};
        if (sched_setscheduler(0, SCHED_FIFO, &sp) == 0) {
            rep->fifo = 1;
        } else {
            rep->fifo_errno = errno;
            fell_back = 1;
        }
    }
    return fell_back;
}

/* ---- signals ---------------------------------------------------------------------------- */

static volatile sig_atomic_t g_stop;
static volatile sig_atomic_t g_stop_signal;

static void on_stop_signal(int sig)
{
    g_stop = 1;
    g_stop_signal = sig;
}

int sc_rt_install_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0; /* no SA_RESTART: blocking calls return EINTR */
    if (sigaction(SIGINT, &sa, NULL) != 0 || sigaction(SIGTERM, &sa, NULL) != 0) {
        return SC_ERR_IO;
    }
    signal(SIGPIPE, SIG_IGN);
    return 0;
}

int sc_rt_stop_requested(void)
{
    return g_stop != 0;
}

int sc_rt_stop_signal(void)
{
    return (int)g_stop_signal;
}

void sc_rt_request_stop(void)
{
    g_stop = 1;
}

/* ---- software watchdog ------------------------------------------------------------------ */

static void *soft_wdg_main(void *arg)
{
    sc_soft_watchdog *w = arg;
    while (atomic_load(&w->running)) {
        const uint32_t tmo = atomic_load(&w->timeout_ms);
        /* check four times per timeout: expiry detected within 1.25 x timeout */
        struct timespec nap = {(time_t)(tmo / 4000u), (long)((tmo / 4u) % 1000u) * 1000000L};
        if (nap.tv_sec == 0 && nap.tv_nsec == 0) {
            nap.tv_nsec = 1000000L;
        }
        nanosleep(&nap, NULL);
        if (!atomic_load(&w->running)) {
            break;
        }
        const uint64_t now = sc_rt_now_ns();
        const uint64_t last = atomic_load(&w->last_kick_ns);
        const uint64_t limit_ns = (uint64_t)tmo * 1000000u * (atomic_load(&w->kicked) ? 1u : 10u);
        if (now > last && now - last > limit_ns) {
            atomic_fetch_add(&w->expiries, 1u);
            if (w->abort_on_expiry) {
                char msg[160];
                int n = snprintf(msg, sizeof msg,
                                 "\nlevel=error event=watchdog_expired timeout_ms=%u "
                                 "since_kick_ms=%llu action=abort\n",
                                 tmo, (unsigned long long)((now - last) / 1000000u));
                if (n > 0) {
                    ssize_t ignored = write(2, msg, (size_t)n);
                    (void)ignored;
                }
                abort();
            }
            atomic_store(&w->last_kick_ns, now); /* re-arm (counting mode) */
        }
    }
    return NULL;
}

static int soft_wdg_start(void *ctx, uint32_t timeout_ms)
{
    sc_soft_watchdog *w = ctx;
    if (timeout_ms == 0u) {
        return SC_ERR_RANGE;
    }
    atomic_store(&w->timeout_ms, timeout_ms);
    atomic_store(&w->kicked, 0);
    atomic_store(&w->last_kick_ns, sc_rt_now_ns());
    if (w->thread_started) {
        return 0;
    }
    atomic_store(&w->running, 1);
    if (pthread_create(&w->thread, NULL, soft_wdg_main, w) != 0) {
        atomic_store(&w->running, 0);
        return SC_ERR_IO;
    }
    w->thread_started = 1;
    return 0;
}

static int soft_wdg_kick(void *ctx)
{
    sc_soft_watchdog *w = ctx;
    atomic_store(&w->last_kick_ns, sc_rt_now_ns());
    atomic_store(&w->kicked, 1);
    return 0;
}

static const sc_watchdog_ops k_soft_ops = {soft_wdg_start, soft_wdg_kick};

void sc_soft_watchdog_init(sc_soft_watchdog *w, int abort_on_expiry)
{
    memset(w, 0, sizeof *w);
    atomic_init(&w->last_kick_ns, 0u);
    atomic_init(&w->timeout_ms, 1000u);
    atomic_init(&w->running, 0);
    atomic_init(&w->expiries, 0u);
    atomic_init(&w->kicked, 0);
    w->abort_on_expiry = abort_on_expiry;
}

sc_watchdog_dev sc_soft_watchdog_dev(sc_soft_watchdog *w)
{
    sc_watchdog_dev d = {&k_soft_ops, w};
    return d;
}

void sc_soft_watchdog_stop(sc_soft_watchdog *w)
{
    if (w->thread_started) {
        atomic_store(&w->running, 0);
        pthread_join(w->thread, NULL);
        w->thread_started = 0;
    }
}

/* ---- kernel watchdog device ------------------------------------------------------------- */

int sc_dev_watchdog_open(sc_dev_watchdog *w, const char *path)
{
    memset(w, 0, sizeof *w);
    w->fd = open(path, O_WRONLY | O_CLOEXEC);
    if (w->fd < 0) {
        w->last_errno = errno;
        return errno == ENOENT ? SC_ERR_NOT_FOUND : SC_ERR_IO;
    }
    return 0;
}

static int dev_wdg_start(void *ctx, uint32_t timeout_ms)
{
    sc_dev_watchdog *w = ctx;
    int t = (int)((timeout_ms + 999u) / 1000u); /* the interface counts whole seconds */
    if (t < 1) {
        t = 1;
    }
    if (ioctl(w->fd, WDIOC_SETTIMEOUT, &t) != 0) {
        w->last_errno = errno;
        if (errno != EOPNOTSUPP && errno != ENOTTY) {
            return SC_ERR_IO;
        }
        /* fixed-timeout hardware: keep its own timeout */
        if (ioctl(w->fd, WDIOC_GETTIMEOUT, &t) != 0) {
            t = 0;
        }
    }
    w->timeout_s = (uint32_t)t;
    return ioctl(w->fd, WDIOC_KEEPALIVE, 0) == 0 ? 0 : SC_ERR_IO;
}

static int dev_wdg_kick(void *ctx)
{
    sc_dev_watchdog *w = ctx;
    if (ioctl(w->fd, WDIOC_KEEPALIVE, 0) != 0) {
        w->last_errno = errno;
        return SC_ERR_IO;
    }
    return 0;
}

static const sc_watchdog_ops k_dev_ops = {dev_wdg_start, dev_wdg_kick};

sc_watchdog_dev sc_dev_watchdog_dev(sc_dev_watchdog *w)
{
    sc_watchdog_dev d = {&k_dev_ops, w};
    return d;
}

void sc_dev_watchdog_close(sc_dev_watchdog *w, int disarm)
{
    if (w->fd >= 0) {
        if (disarm) {
            ssize_t ignored = write(w->fd, "V", 1u);
            (void)ignored;
        }
        close(w->fd);
        w->fd = -1;
    }
}
