/* sc_test_tmpdir.c: see sc_test_tmpdir.h. */
#define _GNU_SOURCE
#include "sc_test_tmpdir.h"

#include <stdio.h>
#include <stdlib.h>

int sc_test_tmpdir_make(char *dir, size_t cap, const char *prefix)
{
    const int n = snprintf(dir, cap, "/tmp/%s_XXXXXX", prefix);
    if (n < 0 || (size_t)n >= cap) {
        return -1;
    }
    return mkdtemp(dir) == NULL ? -1 : 0;
}

int sc_test_tmpdir_remove(const char *dir)
{
    char cmd[4200];
    const int n = snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (n < 0 || (size_t)n >= sizeof cmd) {
        return -1;
    }
    return system(cmd) == 0 ? 0 : -1;
}
