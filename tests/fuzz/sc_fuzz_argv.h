/* sc_fuzz_argv.h: command-line fuzz targets. The input is split at NUL bytes into the
 * arguments after argv[0] (each copied into a buffer of its exact length, so that ASan sees a
 * read past its end); the program's own parser runs on them with its output sent to
 * /dev/null (sanitizer reports still reach stderr: they write to the descriptor). */
#ifndef SC_FUZZ_ARGV_H
#define SC_FUZZ_ARGV_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_fuzz.h"

#define SC_FUZZ_ARGV_MAX 48

typedef struct sc_fuzz_argv {
    int argc;
    char *argv[SC_FUZZ_ARGV_MAX + 2];
} sc_fuzz_argv;

static void sc_fuzz_argv_split(const uint8_t *data, size_t size, const char *prog,
                               sc_fuzz_argv *a)
{
    a->argc = 0;
    a->argv[a->argc] = malloc(strlen(prog) + 1u);
    SC_FUZZ_CHECK(a->argv[a->argc] != NULL);
    memcpy(a->argv[a->argc++], prog, strlen(prog) + 1u);
    size_t start = 0;
    while (start < size && a->argc <= SC_FUZZ_ARGV_MAX) {
        size_t end = start;
        while (end < size && data[end] != 0u) {
            end++;
        }
        char *arg = malloc(end - start + 1u);
        SC_FUZZ_CHECK(arg != NULL);
        memcpy(arg, data + start, end - start);
        arg[end - start] = '\0';
        a->argv[a->argc++] = arg;
        start = end + 1u;
    }
    a->argv[a->argc] = NULL;
}

static void sc_fuzz_argv_free(sc_fuzz_argv *a)
{
    for (int i = 0; i < a->argc; i++) {
        free(a->argv[i]);
    }
    a->argc = 0;
}

/* stdout and stderr (the FILE streams) to /dev/null while on. */
static void sc_fuzz_quiet(int on)
{
    static FILE *null_f, *saved_out, *saved_err;
    if (on) {
        if (!null_f) {
            null_f = fopen("/dev/null", "w");
            SC_FUZZ_CHECK(null_f != NULL);
        }
        saved_out = stdout;
        saved_err = stderr;
        stdout = null_f;
        stderr = null_f;
    } else {
        stdout = saved_out;
        stderr = saved_err;
    }
}

/* Seed i of a NUL-separated list of command lines (each line's arguments separated by '|'). */
static size_t sc_fuzz_argv_seed(const char *const *lines, size_t count, uint32_t i,
                                uint8_t *buf, size_t cap)
{
    if (i >= count) {
        return 0;
    }
    size_t n = strlen(lines[i]);
    if (n > cap) {
        return 0;
    }
    for (size_t k = 0; k < n; k++) {
        buf[k] = lines[i][k] == '|' ? 0u : (uint8_t)lines[i][k];
    }
    return n;
}

#endif /* SC_FUZZ_ARGV_H */
