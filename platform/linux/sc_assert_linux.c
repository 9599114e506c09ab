/* sc_assert_linux.c: the SC_ASSERT hook of every Linux host program (the appliance, the host simulator, the tools): print the failed check and abort. */
#include <stdio.h>
#include <stdlib.h>

#include "sc_assert.h"

void sc_assert_failed(const char *file, int line, const char *expr)
{
    fprintf(stderr, "%s:%d: SC_ASSERT failed: %s\n", file, line, expr);
    abort();
}
