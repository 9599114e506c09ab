/*
 * sc_fuzz_main.c: deterministic mutational driver for fuzz targets (see sc_fuzz.h).
 * Usage: fuzz_x_smoke [ITERATIONS] [FILE|DIR...]. Files, and every file of a directory in name
 * order (the checked-in corpus and crash regressions), are run as given; then ITERATIONS
 * mutated inputs (default 20000, or SC_FUZZ_ITERS) derived from the target's seeds with a fixed
 * PRNG.
 * fuzz_x_smoke --write-seeds DIR writes the target's seeds as DIR/seed-NN (tools/fuzz-seeds.sh
 * makes the libFuzzer corpora from them).
 */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "sc_fuzz.h"

#define MAX_INPUT (1u << 20)
#define MAX_SEEDS 64u

static uint64_t rng = 0x243F6A8885A308D3ull;

static uint32_t next(void)
{
    rng ^= rng >> 12u;
    rng ^= rng << 25u;
    rng ^= rng >> 27u;
    return (uint32_t)((rng * 2685821657736338717ull) >> 32u);
}

static unsigned long files_run;

static int run_file(const char *path, uint8_t *buf)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "fuzz: cannot open %s\n", path);
        return 1;
    }
    size_t n = fread(buf, 1, MAX_INPUT, f);
    fclose(f);
    LLVMFuzzerTestOneInput(buf, n);
    files_run++;
    return 0;
}

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* A file, or every regular file of a directory (not recursive) in name order. */
static int run_path(const char *path, uint8_t *buf)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        fprintf(stderr, "fuzz: cannot stat %s\n", path);
        return 1;
    }
    if (!S_ISDIR(st.st_mode)) {
        return run_file(path, buf);
    }
    DIR *d = opendir(path);
    if (!d) {
        fprintf(stderr, "fuzz: cannot open directory %s\n", path);
        return 1;
    }
    char **names = NULL;
    size_t n = 0, cap = 0;
    int rc = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.') {
            continue;
        }
        if (n == cap) {
            cap = cap ? cap * 2u : 64u;
            char **grown = realloc(names, cap * sizeof *names);
            if (!grown) {
                rc = 1;
                break;
            }
            names = grown;
        }
        size_t len = strlen(path) + strlen(e->d_name) + 2u;
        names[n] = malloc(len);
        if (!names[n]) {
            rc = 1;
            break;
        }
        snprintf(names[n], len, "%s/%s", path, e->d_name);
        n++;
    }
    closedir(d);
    qsort(names, n, sizeof *names, cmp_names);
    for (size_t i = 0; i < n; i++) {
        rc |= run_file(names[i], buf);
        free(names[i]);
    }
    free(names);
    return rc;
}

static int write_seeds(const char *dir)
{
    static uint8_t seed[16384];
    uint32_t i = 0;
    for (; i < MAX_SEEDS; i++) {
        size_t n = sc_fuzz_seed(i, seed, sizeof seed);
        if (n == 0) {
            break;
        }
        char path[4096];
        snprintf(path, sizeof path, "%s/seed-%02u", dir, (unsigned)i);
        FILE *f = fopen(path, "wb");
        if (!f || fwrite(seed, 1, n, f) != n || fclose(f) != 0) {
            fprintf(stderr, "fuzz: cannot write %s\n", path);
            return 1;
        }
    }
    printf("fuzz: %u seeds written to %s\n", (unsigned)i, dir);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "--write-seeds") == 0) {
        return write_seeds(argv[2]);
    }
    unsigned long iters = 20000;
    const char *env = getenv("SC_FUZZ_ITERS");
    if (env) {
        iters = strtoul(env, NULL, 10);
    }
    int first_file = 1;
    if (argc > 1) {
        char *end;
        unsigned long v = strtoul(argv[1], &end, 10);
        if (*end == '\0') {
            iters = v;
            first_file = 2;
        }
    }
    static uint8_t seeds[MAX_SEEDS][16384];
    size_t seed_len[MAX_SEEDS];
    uint32_t nseeds = 0;
    while (nseeds < MAX_SEEDS) {
        size_t n = sc_fuzz_seed(nseeds, seeds[nseeds], sizeof(seeds[0]));
        if (n == 0) {
            break;
        }
        seed_len[nseeds++] = n;
    }
    uint8_t *buf = malloc(MAX_INPUT);
    if (!buf) {
        return 2;
    }
    int rc = 0;
    for (int i = first_file; i < argc; i++) {
        rc |= run_path(argv[i], buf);
    }
    for (uint32_t s = 0; s < nseeds; s++) {
        LLVMFuzzerTestOneInput(seeds[s], seed_len[s]);
    }
    unsigned long done = 0;
    for (; done < iters; done++) {
        size_t n = 0;
        if (nseeds) {
            uint32_t s = next() % nseeds;
            n = seed_len[s];
            memcpy(buf, seeds[s], n);
        }
        uint32_t muts = 1u + next() % 8u;
        for (uint32_t m = 0; m < muts; m++) {
            switch (next() % 6u) {
            case 0: /* flip a bit */
                if (n) {
                    uint32_t b = next() % (uint32_t)(n * 8u);
                    buf[b / 8u] ^= (uint8_t)(1u << (b % 8u));
                }
                break;
            case 1: /* set a byte to an interesting value */
                if (n) {
                    static const uint8_t vals[] = {0, 1, 0x7F, 0x80, 0xFF, 0xFE, '\n', '=', '#'};
                    buf[next() % n] = vals[next() % sizeof(vals)];
                }
                break;
            case 2: /* truncate */
                if (n) {
                    n = next() % n;
                }
                break;
            case 3: /* extend with random bytes */
            {
                uint32_t k = next() % 64u;
                for (uint32_t i = 0; i < k && n < MAX_INPUT; i++) {
                    buf[n++] = (uint8_t)next();
                }
                break;
            }
            case 4: /* random byte */
                if (n) {
                    buf[next() % n] = (uint8_t)next();
                }
                break;
            default: /* splice a piece of another seed */
                if (nseeds && n) {
                    uint32_t s = next() % nseeds;
                    size_t off = next() % n;
                    size_t len = seed_len[s] < n - off ? seed_len[s] : n - off;
                    memcpy(buf + off, seeds[s], len);
                }
                break;
            }
        }
        LLVMFuzzerTestOneInput(buf, n);
    }
    free(buf);
    printf("fuzz: %lu corpus/regression files, %u seeds, %lu mutated inputs, no crash\n",
           files_run, nseeds, done);
    return rc;
}
