/* host_noise.c: the host's own spread for fixed work, to read the real loop's p99 against.
 *
 * The engine's frame time varies from frame to frame; on a virtual machine part of that is the
 * host's (other guests on the same caches, memory and cores, the hypervisor), not the engine's.
 * This program times two jobs whose work never changes, on the same CPUs and in the same duty
 * cycle as the frame loop, so whatever spread they show is the machine's:
 *   compute  a chain of dependent float multiply-adds in registers (no memory traffic), sized
 *            at start to about 1 ms;
 *   memory   a sum over MiB of floats split over the threads (default 16 MiB: the 64x32x32
 *            solver matrix is 15.7 MB, and the CG streams it once per product), each thread
 *            its own part, as the pool splits the product.
 * Every period (1 / RATE s, absolute-time sleeps) each thread runs REPS x (compute, memory),
 * then sleeps until the next period; threads are pinned to CPUs 0 .. THREADS-1 and run
 * SCHED_FIFO when permitted (as sonocomp under rt_press.sh). Printed per job: count, min, p50,
 * p99, p99.9, worst (ms) and p99 / p50; then the steal time the kernel reports over the run.
 *
 * Usage: sc-host-noise [--seconds S] [--threads N] [--rate HZ] [--reps R] [--mib M]
 * Defaults: 10 s, 2 threads, 60 Hz, 3 reps, 16 MiB. Exit status: 0, 2 on a usage error, 1 when
 * the buffers or threads cannot be had. Not part of the engine: a host tool (allocates, calls
 * the OS). */
#define _GNU_SOURCE
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define MAX_THREADS 8u

typedef struct opts {
    double seconds;
    unsigned threads, rate_hz, reps, mib;
} opts;

typedef struct worker {
    unsigned index;
    const opts *o;
    const float *part; /* this thread's part of the buffer */
    size_t part_n;
    uint64_t chain;     /* multiply-adds of the compute job */
    struct timespec t0; /* the first period's start, shared */
    uint64_t *compute_ns, *memory_ns;
    size_t n; /* samples taken of each */
    size_t cap;
    int fifo;
    volatile float sink;
} worker;

static uint64_t ns_of(const struct timespec *t)
{
    return (uint64_t)t->tv_sec * 1000000000u + (uint64_t)t->tv_nsec;
}

static uint64_t now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return ns_of(&t);
}

/* a dependent chain: each step waits for the last, so the time is the FMA latency x steps */
static float compute_job(uint64_t steps, float seed)
{
    float a = seed, b = 0.999999f, c = 1e-7f;
    for (uint64_t i = 0; i < steps; i++) {
        a = a * b + c;
    }
    return a;
}

static float memory_job(const float *p, size_t n)
{
    float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f, s3 = 0.0f;
    size_t i = 0;
    for (; i + 4u <= n; i += 4u) {
        s0 += p[i];
        s1 += p[i + 1u];
        s2 += p[i + 2u];
        s3 += p[i + 3u];
    }
    for (; i < n; i++) {
        s0 += p[i];
    }
    return (s0 + s1) + (s2 + s3);
}

static void pin_and_raise(worker *w)
{
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(w->index, &set);
    (void)pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    struct sched_param sp = {.sched_priority = 80};
    w->fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
}

static void *worker_main(void *arg)
{
    worker *w = arg;
    pin_and_raise(w);
    const uint64_t period_ns = 1000000000u / w->o->rate_hz;
    const uint64_t start = ns_of(&w->t0);
    const uint64_t end = start + (uint64_t)(w->o->seconds * 1e9);
    float acc = 0.0f;
    for (uint64_t k = 0;; k++) {
        const uint64_t at = start + k * period_ns;
        if (at >= end) {
            break;
        }
        const struct timespec ts = {.tv_sec = (time_t)(at / 1000000000u),
                                    .tv_nsec = (long)(at % 1000000000u)};
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
        }
        for (unsigned r = 0; r < w->o->reps && w->n < w->cap; r++) {
            uint64_t t = now_ns();
            acc += compute_job(w->chain, acc);
            uint64_t u = now_ns();
            acc += memory_job(w->part, w->part_n);
            const uint64_t v = now_ns();
            w->compute_ns[w->n] = u - t;
            w->memory_ns[w->n] = v - u;
            w->n++;
        }
    }
    w->sink = acc;
    return NULL;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* nearest rank */
static double pct_ms(const uint64_t *s, size_t n, unsigned per_mille)
{
    size_t r = (n * per_mille + 999u) / 1000u;
    r = r == 0u ? 0u : r - 1u;
    return (double)s[r < n ? r : n - 1u] / 1e6;
}

static void print_row(const char *name, uint64_t *s, size_t n)
{
    if (n == 0u) {
        printf("%-8s %7u        -\n", name, 0u);
        return;
    }
    qsort(s, n, sizeof *s, cmp_u64);
    const double p50 = pct_ms(s, n, 500u), p99 = pct_ms(s, n, 990u);
    printf("%-8s %7zu %8.3f %8.3f %8.3f %8.3f %8.3f %8.2f\n", name, n, (double)s[0] / 1e6, p50, p99,
           pct_ms(s, n, 999u), (double)s[n - 1u] / 1e6, p50 > 0.0 ? p99 / p50 : 0.0);
}

static long long steal_ticks(void)
{
    FILE *f = fopen("/proc/stat", "r");
    long long v[8] = {0};
    if (f == NULL) {
        return -1;
    }
    const int got = fscanf(f, "cpu %lld %lld %lld %lld %lld %lld %lld %lld", &v[0], &v[1], &v[2],
                           &v[3], &v[4], &v[5], &v[6], &v[7]);
    fclose(f);
    return got == 8 ? v[7] : -1;
}

static int usage(void)
{
    fprintf(stderr,
            "usage: sc-host-noise [--seconds S] [--threads N] [--rate HZ] [--reps R] "
            "[--mib M]\n"
            "  S 1..600 (10), N 1..%u and at most the CPUs online (2), HZ 1..1000 (60),\n"
            "  R 1..100 (3), M 1..1024 (16)\n",
            MAX_THREADS);
    return 2;
}

static int parse_num(const char *s, double lo, double hi, double *out)
{
    char *end = NULL;
    errno = 0;
    const double v = strtod(s, &end);
    if (end == s || *end != '\0' || errno != 0 || !(v >= lo && v <= hi)) {
        return -1;
    }
    *out = v;
    return 0;
}

static int parse_uint(const char *s, unsigned lo, unsigned hi, unsigned *out)
{
    char *end = NULL;
    errno = 0;
    const unsigned long v = strtoul(s, &end, 10);
    if (end == s || *end != '\0' || errno != 0 || s[0] == '-' || v < lo || v > hi) {
        return -1;
    }
    *out = (unsigned)v;
    return 0;
}

static int parse_args(int argc, char **argv, opts *o)
{
    *o = (opts){.seconds = 10.0, .threads = 2u, .rate_hz = 60u, .reps = 3u, .mib = 16u};
    const long online = sysconf(_SC_NPROCESSORS_ONLN);
    for (int i = 1; i < argc; i++) {
        double v;
        const char *k = argv[i];
        if (strcmp(k, "--help") == 0) {
            (void)usage();
            return 1;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "sc-host-noise: '%s' wants a value\n", k);
            return usage();
        }
        const char *val = argv[++i];
        if (strcmp(k, "--seconds") == 0 && parse_num(val, 1, 600, &v) == 0) {
            o->seconds = v;
        } else if (strcmp(k, "--threads") == 0 &&
                   parse_uint(val, 1u, MAX_THREADS, &o->threads) == 0) {
        } else if (strcmp(k, "--rate") == 0 && parse_uint(val, 1u, 1000u, &o->rate_hz) == 0) {
        } else if (strcmp(k, "--reps") == 0 && parse_uint(val, 1u, 100u, &o->reps) == 0) {
        } else if (strcmp(k, "--mib") == 0 && parse_uint(val, 1u, 1024u, &o->mib) == 0) {
        } else {
            fprintf(stderr, "sc-host-noise: bad option or value '%s %s'\n", k, val);
            return usage();
        }
    }
    if (o->threads > (unsigned)(online < 1 ? 1 : online)) {
        fprintf(stderr, "sc-host-noise: --threads %u: only %ld CPUs online\n", o->threads, online);
        return usage();
    }
    return 0;
}

/* FMA steps for about 1 ms on this CPU: the least of five timed 200,000-step chains */
static uint64_t calibrate_chain(void)
{
    uint64_t best = UINT64_MAX;
    volatile float sink = 0.0f;
    for (int i = 0; i < 5; i++) {
        const uint64_t t = now_ns();
        sink = sink + compute_job(200000u, 1.0f);
        const uint64_t d = now_ns() - t;
        best = d < best ? d : best;
    }
    return best == 0u ? 200000u : (uint64_t)200000u * 1000000u / best;
}

int main(int argc, char **argv)
{
    opts o;
    const int prc = parse_args(argc, argv, &o);
    if (prc != 0) {
        return prc == 1 ? 0 : prc;
    }
    const size_t total_n = (size_t)o.mib * 1024u * 1024u / sizeof(float);
    float *buf = NULL;
    if (posix_memalign((void **)&buf, 64u, total_n * sizeof(float)) != 0) {
        fprintf(stderr, "sc-host-noise: no memory for %u MiB\n", o.mib);
        return 1;
    }
    for (size_t i = 0; i < total_n; i++) {
        buf[i] = (float)(i & 1023u) * 1e-3f;
    }
    const uint64_t chain = calibrate_chain();
    const size_t periods = (size_t)(o.seconds * o.rate_hz) + 1u;
    static worker w[MAX_THREADS];
    struct timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    t0.tv_sec += 1; /* the threads' first period: after they have started */
    const size_t part = total_n / o.threads;
    for (unsigned i = 0; i < o.threads; i++) {
        w[i] = (worker){.index = i,
                        .o = &o,
                        .part = buf + (size_t)i * part,
                        .part_n = part,
                        .chain = chain,
                        .t0 = t0,
                        .cap = periods * o.reps};
        w[i].compute_ns = calloc(w[i].cap, sizeof(uint64_t));
        w[i].memory_ns = calloc(w[i].cap, sizeof(uint64_t));
        if (w[i].compute_ns == NULL || w[i].memory_ns == NULL) {
            fprintf(stderr, "sc-host-noise: no memory for the samples\n");
            return 1;
        }
    }
    const long long st0 = steal_ticks();
    pthread_t th[MAX_THREADS];
    for (unsigned i = 0; i < o.threads; i++) {
        const int rc = pthread_create(&th[i], NULL, worker_main, &w[i]);
        if (rc != 0) {
            fprintf(stderr, "sc-host-noise: thread %u: %s\n", i, strerror(rc));
            return 1;
        }
    }
    for (unsigned i = 0; i < o.threads; i++) {
        (void)pthread_join(th[i], NULL);
    }
    const long long st1 = steal_ticks();
    size_t n = 0;
    int fifo = 1;
    for (unsigned i = 0; i < o.threads; i++) {
        n += w[i].n;
        fifo = fifo && w[i].fifo;
    }
    uint64_t *cs = malloc((n + 1u) * sizeof *cs), *ms = malloc((n + 1u) * sizeof *ms);
    if (cs == NULL || ms == NULL) {
        fprintf(stderr, "sc-host-noise: no memory for the samples\n");
        return 1;
    }
    size_t k = 0;
    for (unsigned i = 0; i < o.threads; i++) {
        memcpy(cs + k, w[i].compute_ns, w[i].n * sizeof *cs);
        memcpy(ms + k, w[i].memory_ns, w[i].n * sizeof *ms);
        k += w[i].n;
    }
    printf("host noise: %u thread%s pinned to CPUs 0..%u, SCHED_FIFO %s, %.0f s at %u Hz, "
           "%u x (compute, memory) a period; compute %llu dependent FMAs, memory %.1f MiB a "
           "thread\n",
           o.threads, o.threads == 1u ? "" : "s", o.threads - 1u, fifo ? "yes" : "no", o.seconds,
           o.rate_hz, o.reps, (unsigned long long)chain,
           (double)part * sizeof(float) / (1024.0 * 1024.0));
    printf("%-8s %7s %8s %8s %8s %8s %8s %8s   (ms; the same work every time)\n", "job", "count",
           "min", "p50", "p99", "p99.9", "worst", "p99/p50");
    print_row("compute", cs, n);
    print_row("memory", ms, n);
    const long hz = sysconf(_SC_CLK_TCK);
    if (st0 >= 0 && st1 >= st0 && hz > 0) {
        printf("host steal during the run: %lld ms over all CPUs\n", (st1 - st0) * 1000 / hz);
    } else {
        printf("host steal during the run: not reported by this kernel\n");
    }
    free(cs);
    free(ms);
    for (unsigned i = 0; i < o.threads; i++) {
        free(w[i].compute_ns);
        free(w[i].memory_ns);
    }
    free(buf);
    return 0;
}
