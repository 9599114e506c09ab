/* sc_test_support.c: keeps the support library non-empty; shared test helpers go here. */
#include "sc_test.h"

int sc_test_support_linked(void);
int sc_test_support_linked(void)
{
    return 1;
}
