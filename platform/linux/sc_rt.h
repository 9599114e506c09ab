/*
 * sc_rt.h: the real-time side of the Linux appliance.
 *
 * - Clock: an sc_clock_dev on CLOCK_MONOTONIC; sleep_until_ns is clock_nanosleep with
 *   TIMER_ABSTIME (absolute release times: no drift from the time spent computing a frame),
 *   resumed after signals until the release time.
 * - Process set-up (sc_rt_apply): mlockall(MCL_CURRENT | MCL_FUTURE) and a pre-faulted stack;
 *   SCHED_FIFO at a priority and pinning to one CPU when asked. Each step that the system
 *   refuses (no CAP_SYS_NICE or RLIMIT_RTPRIO, RLIMIT_MEMLOCK too small, CPU not present) is
 *   reported with its errno and the process continues at normal priority: never fatal, and the
 *   caller logs the report.
 * - Signals: SIGINT and SIGTERM set a stop flag (async-signal-safe) that the frame loop polls
 *   once per frame; SIGPIPE is ignored (a closed log pipe must not kill the engine).
 * - Watchdogs (sc_watchdog_dev, hal/sc_hal_watchdog.h): the kernel watchdog device
 *   (/dev/watchdog: WDIOC_SETTIMEOUT, WDIOC_KEEPALIVE, magic close 'V' on a clean stop), and a
 *   software watchdog for hosts: a thread that checks the last kick and, on expiry, reports
 *   and aborts the process (or only counts, for tests). Between start and the first kick it
 *   allows 10 timeouts (the engine arms it at init, then loads its case before the first
 *   frame); the kernel device has no such grace: there the case load must fit the timeout.
 *
 * Allocation: none after set-up. Threads: the clock is reentrant; the soft watchdog owns one
 * thread; kick is wait-free.
 */
#ifndef SC_RT_H
#define SC_RT_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "sc_hal_clock.h"
#include "sc_hal_watchdog.h"

/* ---- clock ------------------------------------------------------------------------------ */
uint64_t sc_rt_now_ns(void);
/* The hal clock device (stateless: ctx unused). */
sc_clock_dev sc_rt_clock_dev(void);

/* ---- process set-up --------------------------------------------------------------------- */
typedef struct sc_rt_def {
    int mlock;                   /* mlockall + stack pre-fault */
    size_t prefault_stack_bytes; /* stack touched after mlockall (default 256 KiB) */
    int sched_fifo;              /* try SCHED_FIFO */
    int priority;                /* 1..99 */
    int cpu;                     /* -1: no pinning */
} sc_rt_def;

typedef struct sc_rt_report {
    int locked; /* mlockall succeeded */
    int lock_errno;
    int fifo; /* running SCHED_FIFO */
    int fifo_errno;
    int pinned; /* pinned to def.cpu */
    int pin_errno;
    int huge; /* the caller's: the engine advised onto huge pages (sc_rt_advise_hugepages) */
} sc_rt_report;

sc_rt_def sc_rt_default_def(void);
/* Apply def to the calling thread / process; the report says what took effect. Returns 0 when
 * everything asked for took effect, 1 when something fell back (see the report). */
int sc_rt_apply(const sc_rt_def *def, sc_rt_report *rep);
/* Ask the kernel to back [p, p+n) with transparent huge pages (madvise MADV_HUGEPAGE on the
 * 2 MiB-aligned part; the kernel's THP mode "madvise", Debian's default, needs the ask). Call it
 * on the engine's static state before anything touches it (before mlockall's pre-fault). Why:
 * the implicit solvers stream 60 matrix rows a few hundred KB apart and the cell passes add into
 * 234 lines per block of cells, one 4 KiB page each: with 2 MiB pages the 64x32x32 stable MSDS
 * step took 10-20 % less (docs/performance.md, "Huge pages"). Returns 0 when the advice was
 * taken, 1 when the range holds no whole 2 MiB page, SC_ERR_IO when madvise refused it (errno
 * kept: a kernel without THP gives EINVAL); nothing changes but the page size. */
int sc_rt_advise_hugepages(void *p, size_t n);

/* Touch every page of [p, p+n) (writing a zero to the first byte of each page, which the
 * caller must not mind: call it on freshly zeroed storage), so that a locked process takes
 * no page fault there later. */
void sc_rt_prefault(void *p, size_t n);

/* ---- signals ---------------------------------------------------------------------------- */
/* Install SIGINT/SIGTERM handlers (no SA_RESTART) and ignore SIGPIPE. 0 or SC_ERR_IO. */
int sc_rt_install_signals(void);
int sc_rt_stop_requested(void);
/* The signal that asked to stop (0 if none). */
int sc_rt_stop_signal(void);
void sc_rt_request_stop(void);

/* ---- watchdogs -------------------------------------------------------------------------- */
typedef struct sc_soft_watchdog {
    atomic_ullong last_kick_ns;
    atomic_uint timeout_ms;
    atomic_int running;
    atomic_uint expiries;
    atomic_int kicked; /* fed at least once since start */
    int abort_on_expiry;
    int thread_started;
    pthread_t thread;
} sc_soft_watchdog;

/* abort_on_expiry: 1 on a real run (the process dies with a message, as a reset would), 0 in
 * tests (expiries only counted, the watchdog re-arms). Nothing runs before start. */
void sc_soft_watchdog_init(sc_soft_watchdog *w, int abort_on_expiry);
sc_watchdog_dev sc_soft_watchdog_dev(sc_soft_watchdog *w);
void sc_soft_watchdog_stop(sc_soft_watchdog *w);

typedef struct sc_dev_watchdog {
    int fd;
    int last_errno;
    uint32_t timeout_s; /* as the driver set it */
} sc_dev_watchdog;

/* Open the device (the kernel arms it at open). 0, SC_ERR_NOT_FOUND or SC_ERR_IO. */
int sc_dev_watchdog_open(sc_dev_watchdog *w, const char *path);
sc_watchdog_dev sc_dev_watchdog_dev(sc_dev_watchdog *w);
/* disarm: write the magic 'V' first (clean shutdown); otherwise the board resets. */
void sc_dev_watchdog_close(sc_dev_watchdog *w, int disarm);

#endif /* SC_RT_H */
