/* sc_test_tmpdir.h: a scratch folder for tests that write files (a cmocka group's setup makes
 * it, its teardown removes it with everything in it). */
#ifndef SC_TEST_TMPDIR_H
#define SC_TEST_TMPDIR_H

#include <stddef.h>

/* Makes /tmp/<prefix>_XXXXXX into dir (cap bytes); 0, or -1 when it cannot. */
int sc_test_tmpdir_make(char *dir, size_t cap, const char *prefix);
/* Removes dir and its contents; 0, or -1 when that fails. */
int sc_test_tmpdir_remove(const char *dir);

#endif /* SC_TEST_TMPDIR_H */
