/* sc_png_write.c: PNG through libpng (see sc_png_write.h). */
#include "sc_png_write.h"

#include <errno.h>
#include <png.h>
#include <stdio.h>
#include <string.h>

#include "sc_err.h"

#define SC_PNG_MAX_SIDE 65535u

/* libpng reports an error by calling this, which must not return: back to the setjmp in
 * encode(). Its message is not printed (the caller reports SC_ERR_IO with its own words). */
static void on_error(png_structp png, png_const_charp msg)
{
    (void)msg;
    png_longjmp(png, 1);
}

static void on_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

/* The image into the open file f: 0 or SC_ERR_IO. Nothing here is changed between setjmp and
 * a longjmp except through libpng's own structures, which png_destroy_write_struct frees. */
static int encode(FILE *f, uint32_t width, uint32_t height, uint32_t channels,
                  const uint8_t *pixels, size_t stride)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, on_error, on_warning);
    if (!png) {
        return SC_ERR_IO;
    }
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        return SC_ERR_IO;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return SC_ERR_IO;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, width, height, 8, channels == 1u ? PNG_COLOR_TYPE_GRAY
                                                             : PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 1);
    png_write_info(png, info);
    for (uint32_t y = 0; y < height; y++) {
        png_write_row(png, pixels + (size_t)y * stride);
    }
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return 0;
}

int sc_png_write(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                 const uint8_t *pixels, size_t stride)
{
    if (!path || !pixels || width == 0u || height == 0u || width > SC_PNG_MAX_SIDE ||
        height > SC_PNG_MAX_SIDE || (channels != 1u && channels != 3u) ||
        stride < (size_t)width * channels) {
        return SC_ERR_INVALID_ARG;
    }
    char tmp[4096 + 8];
    if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp) {
        return SC_ERR_INVALID_ARG;
    }
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        return SC_ERR_IO;
    }
    int rc = encode(f, width, height, channels, pixels, stride);
    if (fclose(f) != 0) {
        rc = SC_ERR_IO;
    }
    if (rc == 0 && rename(tmp, path) != 0) {
        rc = SC_ERR_IO;
    }
    if (rc != 0) {
        const int e = errno;
        remove(tmp);
        errno = e;
    }
    return rc;
}
