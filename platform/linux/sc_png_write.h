/*
 * sc_png_write.h: a dependency-free PNG writer for 8-bit grey and RGB images.
 *
 * The image data goes into zlib "stored" (uncompressed) deflate blocks, so no zlib or libpng
 * is linked: the engine binary also links statically for the HIL VM, where Debian's shared
 * libraries are not available. Files are therefore about the raw image size (a 512 x 512 grey
 * frame is 257 KiB). CRC-32 from core/base/sc_crc32.h, Adler-32 computed here. Any PNG reader
 * (libpng, browsers, ImageMagick, Python) reads them.
 *
 * Allocation: none (streams through a stdio FILE). Reentrant.
 */
#ifndef SC_PNG_WRITE_H
#define SC_PNG_WRITE_H

#include <stddef.h>
#include <stdint.h>

/* channels: 1 (grey) or 3 (RGB). stride: bytes between rows. 0, SC_ERR_INVALID_ARG or
 * SC_ERR_IO (errno set). The file is written to path + ".tmp" and renamed, so a reader never
 * sees half a frame. */
int sc_png_write(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                 const uint8_t *pixels, size_t stride);

#endif /* SC_PNG_WRITE_H */
