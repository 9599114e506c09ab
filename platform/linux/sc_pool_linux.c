/* sc_pool_linux.c: pinned worker threads for the core's jobs, see sc_pool_linux.h. */
#include "sc_pool_linux.h"

#include <errno.h>
#include <limits.h>
#include <linux/futex.h>
#include <sched.h>
#include <string.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

static void cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#endif
}

static uint64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static void futex_wait(_Atomic uint32_t *addr, uint32_t val)
{
    (void)syscall(SYS_futex, (uint32_t *)addr, FUTEX_WAIT_PRIVATE, val, NULL, NULL, 0);
}

static void futex_wake_all(_Atomic uint32_t *addr)
{
    (void)syscall(SYS_futex, (uint32_t *)addr, FUTEX_WAKE_PRIVATE, INT_MAX, NULL, NULL, 0);
}

/* The claim word: the job's sequence number, then the unclaimed ranges [front, back). */
#define CLAIM_FRONT(c) ((uint32_t)((c) >> 16) & 0xffffu)
#define CLAIM_BACK(c)  ((uint32_t)(c)&0xffffu)

/* Claim and run ranges of job `seq` until none is left (or the job is no longer current). The
 * caller (w = 0) claims from the front, the workers from the back: with two, each takes one end
 * of the job's nodes in every job, so what a pass writes is mostly read by the next pass on the
 * same core (and a contested claim is rare). The job's fields are read before a successful
 * claim: a claim succeeds only while the claim word still carries seq, and the caller resets
 * that word (then a fence) before it writes the next job's fields, so what was read is this
 * job's. */
static void run_ranges(sc_pool_linux *p, uint32_t seq, uint32_t w)
{
    uint64_t finished = atomic_load_explicit(&p->done[w].n, memory_order_relaxed);
    for (;;) {
        const sc_pool_job_fn fn = atomic_load_explicit(&p->fn, memory_order_relaxed);
        void *const arg = atomic_load_explicit(&p->arg, memory_order_relaxed);
        uint64_t c = atomic_load_explicit(&p->claim, memory_order_seq_cst);
        const uint32_t front = CLAIM_FRONT(c), back = CLAIM_BACK(c);
        if ((uint32_t)(c >> 32) != seq || front >= back) {
            return;
        }
        const uint32_t r = w == 0u ? front : back - 1u;
        const uint64_t next = w == 0u ? c + ((uint64_t)1 << 16) : c - 1u;
        if (!atomic_compare_exchange_weak_explicit(&p->claim, &c, next, memory_order_seq_cst,
                                                   memory_order_seq_cst)) {
            continue;
        }
        fn(arg, r);
        atomic_store_explicit(&p->done[w].n, ++finished, memory_order_release);
    }
}

static void *worker_main(void *argp)
{
    const sc_pool_linux_arg *a = (const sc_pool_linux_arg *)argp;
    sc_pool_linux *p = a->p;
    uint32_t seen = atomic_load_explicit(&p->seq, memory_order_acquire);
    for (;;) {
        uint32_t s = atomic_load_explicit(&p->seq, memory_order_acquire);
        if (s == seen) {
            const uint64_t until = now_ns() + (uint64_t)p->spin_us * 1000u;
            uint32_t k = 0;
            while ((s = atomic_load_explicit(&p->seq, memory_order_acquire)) == seen) {
                if (atomic_load_explicit(&p->stop, memory_order_acquire)) {
                    return NULL;
                }
                cpu_relax();
                if ((++k & 255u) == 0u && now_ns() > until) {
                    atomic_fetch_add_explicit(&p->sleeping, 1u, memory_order_seq_cst);
                    if (atomic_load_explicit(&p->seq, memory_order_seq_cst) == seen &&
                        !atomic_load_explicit(&p->stop, memory_order_seq_cst)) {
                        futex_wait(&p->seq, seen);
                    }
                    atomic_fetch_sub_explicit(&p->sleeping, 1u, memory_order_seq_cst);
                }
            }
        }
        if (atomic_load_explicit(&p->stop, memory_order_acquire)) {
            return NULL;
        }
        seen = s;
        run_ranges(p, s, a->w);
    }
}

static void pool_run(void *ctx, sc_pool_job_fn fn, void *arg, uint32_t ranges)
{
    sc_pool_linux *p = (sc_pool_linux *)ctx;
    const uint64_t t0 = now_ns();
    const uint32_t seq = atomic_load_explicit(&p->seq, memory_order_relaxed) + 1u;
    if (ranges > 0xffffu) {
        /* more than the claim word holds (no job of the core's has as many): on the caller */
        for (uint32_t r = 0; r < ranges; r++) {
            fn(arg, r);
        }
        p->job_ns += now_ns() - t0;
        return;
    }
    /* the claim word first: from here no late worker of the previous job can claim */
    atomic_store_explicit(&p->claim, (uint64_t)seq << 32 | ranges, memory_order_seq_cst);
    atomic_thread_fence(memory_order_seq_cst);
    atomic_store_explicit(&p->fn, fn, memory_order_relaxed);
    atomic_store_explicit(&p->arg, arg, memory_order_relaxed);
    /* every range of the previous job has finished: the counts are still */
    uint64_t target = (uint64_t)ranges;
    for (uint32_t w = 0; w < p->workers; w++) {
        target += atomic_load_explicit(&p->done[w].n, memory_order_relaxed);
    }
    atomic_store_explicit(&p->seq, seq, memory_order_seq_cst);
    p->jobs++;
    p->ranges_run += ranges;
    if (atomic_load_explicit(&p->sleeping, memory_order_seq_cst) != 0u) {
        p->wakes++;
        futex_wake_all(&p->seq);
    }
    run_ranges(p, seq, 0u);
    /* a worker descheduled in the middle of its range makes this spin burn the caller's
     * time slice: past a few microseconds, yield to it */
    for (uint32_t k = 0;; k++) {
        uint64_t sum = 0;
        for (uint32_t w = 0; w < p->workers; w++) {
            sum += atomic_load_explicit(&p->done[w].n, memory_order_acquire);
        }
        if (sum == target) {
            break;
        }
        if (k < 4096u) {
            cpu_relax();
        } else {
            (void)sched_yield();
        }
    }
    p->job_ns += now_ns() - t0;
}

static uint32_t pool_workers(void *ctx)
{
    return ((const sc_pool_linux *)ctx)->workers;
}

static const sc_pool_ops k_pool_ops = {.run = pool_run, .workers = pool_workers};

static void pin(pthread_t th, int cpu)
{
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET((unsigned)cpu, &set);
    (void)pthread_setaffinity_np(th, sizeof set, &set);
}

int sc_pool_linux_start(sc_pool_linux *p, uint32_t workers, int first_cpu, uint32_t spin_us,
                        sc_pool_dev *dev)
{
    memset(p, 0, sizeof *p);
    dev->ops = NULL;
    dev->ctx = NULL;
    long online = sysconf(_SC_NPROCESSORS_ONLN);
    if (online < 1) {
        online = 1;
    }
    if (workers == 0u) {
        workers = (uint32_t)online;
    }
    if (workers > SC_POOL_LINUX_MAX_WORKERS) {
        return -EINVAL;
    }
    p->workers = workers;
    p->spin_us = spin_us;
    p->first_cpu = first_cpu;
    if (first_cpu >= 0) {
        pin(pthread_self(), first_cpu % (int)online);
    }
    for (uint32_t w = 1; w < workers; w++) {
        p->args[w] = (sc_pool_linux_arg){.p = p, .w = w};
        const int rc = pthread_create(&p->th[w], NULL, worker_main, &p->args[w]);
        if (rc != 0) {
            sc_pool_linux_stop(p);
            return -rc;
        }
        p->started++;
        if (first_cpu >= 0) {
            pin(p->th[w], (first_cpu + (int)w) % (int)online);
        }
    }
    dev->ops = &k_pool_ops;
    dev->ctx = p;
    return 0;
}

uint64_t sc_pool_linux_ranges(const sc_pool_linux *p, uint64_t *by_workers)
{
    uint64_t w = 0;
    for (uint32_t i = 1; i < p->workers; i++) {
        w += atomic_load_explicit(&p->done[i].n, memory_order_acquire);
    }
    *by_workers = w;
    return atomic_load_explicit(&p->done[0].n, memory_order_relaxed);
}

void sc_pool_linux_stop(sc_pool_linux *p)
{
    atomic_store_explicit(&p->stop, 1u, memory_order_seq_cst);
    atomic_fetch_add_explicit(&p->seq, 1u, memory_order_seq_cst);
    futex_wake_all(&p->seq);
    for (uint32_t w = 1; w <= p->started; w++) {
        (void)pthread_join(p->th[w], NULL);
    }
    p->started = 0u;
}
