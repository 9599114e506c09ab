/*
 * sc_pool_linux.h: the appliance's worker pool (hal/sc_hal_pool.h): W - 1 threads created once
 * at start-up, each pinned to its own core (the caller, worker 0, pinned to the first), that
 * wait for a job and claim its ranges one at a time from a shared claim word, as the caller
 * does: a worker that the kernel has descheduled (a shared machine) holds up no range it has not
 * claimed. The caller claims from the job's first range up, the workers from its last range
 * down: with two cores each takes the same end of the nodes in every job, so what one pass
 * writes the next pass mostly reads on the same core, from its own caches (64x32x32, two
 * workers: the MSDS step 9.1 -> 8.5-8.6 ms, the FEM's 6.4-6.8 -> 5.6-6.1 ms). The claim word
 * carries the job's sequence number, so a late worker can never claim a range of the next job
 * with the previous job's view. A job has at most 65,535 ranges (one of more runs on the
 * caller alone). Between the jobs of a frame the
 * workers spin (pause) for up to spin_us, then sleep on a futex until the next job, so an idle
 * engine costs no CPU and a hand-over within a frame costs about a microsecond.
 * Which worker runs which range varies from run to run; the core's jobs do not depend on it
 * (hal/sc_hal_pool.h), so the results do not either.
 * Threads: run is called by one thread at a time (the frame loop). Allocation: none after
 * sc_pool_linux_start (the threads' stacks are created there).
 */
#ifndef SC_POOL_LINUX_H
#define SC_POOL_LINUX_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>

#include "sc_hal_pool.h"

#define SC_POOL_LINUX_MAX_WORKERS 16u

typedef struct sc_pool_linux_arg {
    struct sc_pool_linux *p;
    uint32_t w;
} sc_pool_linux_arg;

typedef struct sc_pool_linux {
    uint32_t workers;
    sc_pool_linux_arg args[SC_POOL_LINUX_MAX_WORKERS];
    uint32_t spin_us;
    pthread_t th[SC_POOL_LINUX_MAX_WORKERS];
    uint32_t started; /* threads started */
    /* Cache lines (scale5): the job's read-mostly fields, the claim word and each worker's
     * count of finished ranges on lines of their own, so that a claim or a finished range
     * moves one line between the cores instead of the one line every field shared (the
     * caller's spin on the old shared `done` pulled it back after every range). */
    /* the current job: written by the caller before seq is bumped, stable until all report */
    _Alignas(64) _Atomic(sc_pool_job_fn) fn;
    _Atomic(void *) arg;
    _Atomic uint32_t seq;   /* job sequence number (also the futex word) */
    _Atomic uint32_t stop;
    _Atomic uint32_t sleeping; /* workers blocked on the futex */
    _Alignas(64) _Atomic uint64_t claim; /* job sequence << 32 | front << 16 | back: the
                                          * ranges [front, back) are unclaimed */
    /* ranges finished since the start, per worker (worker w alone writes done[w]; the caller
     * waits until their sum has grown by the job's ranges) */
    struct {
        _Alignas(64) _Atomic uint64_t n;
    } done[SC_POOL_LINUX_MAX_WORKERS];
    int first_cpu;             /* worker w pinned to CPU first_cpu + w (-1: not pinned) */
    /* counters of the caller (run's thread alone writes them; read them between jobs) */
    uint64_t jobs;    /* run calls that went to the workers (ranges > 1) */
    uint64_t ranges_run; /* their ranges */
    uint64_t wakes;   /* jobs that found a worker asleep on the futex (a wake-up syscall) */
    uint64_t job_ns;  /* wall time the caller spent in those runs (CLOCK_MONOTONIC): the rest
                       * of its time between two readings is its work alone, no worker's */
} sc_pool_linux;

/* Start a pool of `workers` (1..SC_POOL_LINUX_MAX_WORKERS; 0: one per online CPU) and fill
 * dev. first_cpu >= 0 pins worker w (w >= 1) to CPU (first_cpu + w) mod online CPUs, and the
 * caller to first_cpu; -1 leaves placement to the kernel. Returns 0, or a negative errno
 * (then no thread runs and dev is the serial pool: NULL ops). */
int sc_pool_linux_start(sc_pool_linux *p, uint32_t workers, int first_cpu, uint32_t spin_us,
                        sc_pool_dev *dev);

/* The ranges run so far by the caller (returned) and by the workers (*by_workers): read them
 * between jobs, on the caller's thread. Per frame, the workers' share tells whether the other
 * cores took part: with two, about half when both run, and next to none if the host stops the
 * second CPU (sonocomp's final statistics count such frames). */
uint64_t sc_pool_linux_ranges(const sc_pool_linux *p, uint64_t *by_workers);

/* Stop and join the threads. The pool must not be running a job. */
void sc_pool_linux_stop(sc_pool_linux *p);

#endif /* SC_POOL_LINUX_H */
