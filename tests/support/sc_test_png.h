/* sc_test_png.h: reading a PNG back with libpng (the reference decoder) in tests. */
#ifndef SC_TEST_PNG_H
#define SC_TEST_PNG_H

#include <stdint.h>

/* Decodes path; *pixels (malloc'd, rows of width * channels bytes, no padding) for the caller
 * to free. 0, or -1 when libpng refuses the file (its message on stderr). *channels is 1 for
 * a grey file, 3 for RGB, 0 for anything else (then no pixels). */
int sc_test_png_read(const char *path, uint32_t *width, uint32_t *height, uint32_t *channels,
                     uint8_t **pixels);

#endif /* SC_TEST_PNG_H */
