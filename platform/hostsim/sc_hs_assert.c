/* sc_hs_assert.c: the host's SC_ASSERT hook: print the failed check and abort. */
#include <stdio.h>
#include <stdlib.h>

#include "sc_assert.h"

void sc_assert_failed(const char *file, int line, const char *expr)
{
    fprintf(stderr, "%s:%d: SC_ASSERT failed: %s\n", file, line, expr);
    abort();
}
