/* sc_test.h: what every cmocka test includes: cmocka itself (with its prerequisites). */
#ifndef SC_TEST_H
#define SC_TEST_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#endif /* SC_TEST_H */
