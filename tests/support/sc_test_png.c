/* sc_test_png.c: see sc_test_png.h (libpng's simplified reading API). */
#include "sc_test_png.h"

#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int sc_test_png_read(const char *path, uint32_t *width, uint32_t *height, uint32_t *channels,
                     uint8_t **pixels)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    *pixels = NULL;
    *channels = 0;
    if (!png_image_begin_read_from_file(&img, path)) {
        fprintf(stderr, "sc_test_png_read: %s: %s\n", path, img.message);
        return -1;
    }
    *width = img.width;
    *height = img.height;
    if (img.format == PNG_FORMAT_GRAY) {
        *channels = 1;
    } else if (img.format == PNG_FORMAT_RGB) {
        *channels = 3;
    } else {
        png_image_free(&img);
        return 0;
    }
    uint8_t *buf = malloc(PNG_IMAGE_SIZE(img));
    if (!buf || !png_image_finish_read(&img, NULL, buf, 0, NULL)) {
        fprintf(stderr, "sc_test_png_read: %s: %s\n", path, img.message);
        free(buf);
        png_image_free(&img);
        return -1;
    }
    *pixels = buf;
    return 0;
}
