/*
 * sc_png_write.h: PNG files of 8-bit grey and RGB images, through libpng (Debian's
 * libpng-dev; the HIL VM's static binaries link its archive and zlib's).
 *
 * Output is deterministic for a given libpng and zlib: compression level 1 (the PNG sink
 * writes a frame in its frame period), libpng's default adaptive row filters, no time or text
 * chunks. The host simulator's image hashes are computed on the raw images, never on these
 * bytes.
 *
 * Allocation: libpng's, for the duration of one call (a few tens of KiB). Reentrant (no shared
 * state; libpng errors return through setjmp in the calling thread).
 */
#ifndef SC_PNG_WRITE_H
#define SC_PNG_WRITE_H

#include <stddef.h>
#include <stdint.h>

/* channels: 1 (grey) or 3 (RGB). stride: bytes between rows. 0, SC_ERR_INVALID_ARG (also a
 * width or height above 65535 or a path too long), or SC_ERR_IO (errno set where the C
 * library set it). The file is written to path + ".tmp" and renamed, so a reader never sees
 * half a frame; on an error no file is left behind. */
int sc_png_write(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                 const uint8_t *pixels, size_t stride);

#endif /* SC_PNG_WRITE_H */
