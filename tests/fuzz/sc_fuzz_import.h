/*
 * sc_fuzz_import.h: shared by the importer fuzz targets (fuzz_import_*.c): each input is
 * written to a file in a private temporary folder (the readers take paths) under the name the
 * format needs, and also as "data.raw" beside it so that detached headers reach their data;
 * the reader runs with a small voxel ceiling so that no input can claim much memory.
 */
#ifndef SC_FUZZ_IMPORT_H
#define SC_FUZZ_IMPORT_H

#ifndef _GNU_SOURCE
#define _GNU_SOURCE /* mkdtemp */
#endif

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sc_caseimport.h"
#include "sc_err.h"
#include "sc_fuzz.h"

#define SC_FUZZ_IMPORT_MAX_VOXELS (1u << 16)

static void sc_fuzz_import_cleanup(void);

static inline const char *sc_fuzz_import_dir(void)
{
    static char dir[64];
    if (dir[0] == 0) {
        /* tmpfs when there is one: the input is written twice per run */
        const char *base = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
        snprintf(dir, sizeof dir, "%s/sc_fuzz_import_XXXXXX", base);
        if (mkdtemp(dir) == NULL) {
            abort();
        }
        atexit(sc_fuzz_import_cleanup);
    }
    return dir;
}

static inline void sc_fuzz_import_put(const char *name, const uint8_t *data, size_t size,
                                      char *path, size_t n)
{
    snprintf(path, n, "%s/%s", sc_fuzz_import_dir(), name);
    FILE *f = fopen(path, "wb");
    SC_FUZZ_CHECK(f != NULL);
    SC_FUZZ_CHECK(size == 0u || fwrite(data, 1, size, f) == size);
    SC_FUZZ_CHECK(fclose(f) == 0);
}

/* Read `name` (written from the input) and check what any successful read promises. */
static inline void sc_fuzz_import_run(const char *name, const uint8_t *data, size_t size)
{
    char path[256], raw[256];
    sc_fuzz_import_put(name, data, size, path, sizeof path);
    sc_fuzz_import_put("data.raw", data, size, raw, sizeof raw);
    sc_read_limits lim = sc_read_default_limits();
    lim.max_voxels = SC_FUZZ_IMPORT_MAX_VOXELS;
    sc_image img;
    char err[512];
    err[0] = 0;
    const int rc = sc_image_read_ex(path, &lim, &img, err, sizeof err);
    SC_FUZZ_CHECK(memchr(err, 0, sizeof err) != NULL);
    if (rc != SC_OK) {
        SC_FUZZ_CHECK(rc < 0 && err[0] != 0);
        return;
    }
    const uint64_t n = (uint64_t)img.dim[0] * img.dim[1] * img.dim[2];
    SC_FUZZ_CHECK(n >= 1u && n <= SC_FUZZ_IMPORT_MAX_VOXELS);
    for (int a = 0; a < 3; a++) {
        SC_FUZZ_CHECK(img.spacing[a] >= SC_IMPORT_MIN_SPACING_MM &&
                      img.spacing[a] <= SC_IMPORT_MAX_SPACING_MM);
    }
    for (uint64_t i = 0; i < n; i++) {
        SC_FUZZ_CHECK(isfinite(img.data[i])); /* every voxel readable (ASan) and finite */
    }
    sc_image_free(&img);
}

static inline size_t sc_fuzz_import_copy(const void *src, size_t n, uint8_t *buf, size_t cap)
{
    if (n > cap) {
        n = cap;
    }
    memcpy(buf, src, n);
    return n;
}

static void sc_fuzz_import_cleanup(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", sc_fuzz_import_dir());
    if (system(cmd) != 0) {
        fprintf(stderr, "fuzz: could not remove %s\n", sc_fuzz_import_dir());
    }
}

#endif /* SC_FUZZ_IMPORT_H */
