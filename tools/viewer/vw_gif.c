/* vw_gif.c: animated GIF through giflib's streaming writer (see vw_gif.h). */
#include "vw_gif.h"

#include <gif_lib.h>
#include <stdlib.h>
#include <string.h>

static int fail(vw_gif *g, int code)
{
    if (!g->err) {
        g->err = code ? code : E_GIF_ERR_WRITE_FAILED;
    }
    return -1;
}

/* A failed open leaves nothing behind to close. */
static int fail_open(vw_gif *g, int code)
{
    fail(g, code);
    const int err = g->err;
    (void)vw_gif_close(g);
    g->err = err;
    return -1;
}

int vw_gif_open(vw_gif *g, const char *path, uint16_t width, uint16_t height,
                const uint8_t palette[768])
{
    memset(g, 0, sizeof *g);
    if (width == 0u || height == 0u) {
        return fail(g, E_GIF_ERR_DATA_TOO_BIG);
    }
    g->row = malloc(width);
    if (!g->row) {
        return fail(g, E_GIF_ERR_NOT_ENOUGH_MEM);
    }
    int err = 0;
    GifFileType *gif = EGifOpenFileName(path, false, &err);
    if (!gif) {
        free(g->row);
        g->row = NULL;
        return fail(g, err);
    }
    g->gif = gif;
    g->width = width;
    g->height = height;
    EGifSetGifVersion(gif, true); /* GIF89a: delays and the loop extension */
    GifColorType colours[256];
    for (int i = 0; i < 256; i++) {
        colours[i].Red = palette[3 * i];
        colours[i].Green = palette[3 * i + 1];
        colours[i].Blue = palette[3 * i + 2];
    }
    ColorMapObject *map = GifMakeMapObject(256, colours);
    if (!map) {
        return fail_open(g, E_GIF_ERR_NOT_ENOUGH_MEM);
    }
    const int rc = EGifPutScreenDesc(gif, width, height, 8, 0, map);
    GifFreeMapObject(map); /* the screen descriptor keeps its own copy */
    if (rc != GIF_OK) {
        return fail_open(g, gif->Error);
    }
    /* NETSCAPE2.0 application extension: loop forever */
    static const GifByteType app[11] = {'N', 'E', 'T', 'S', 'C', 'A', 'P', 'E', '2', '.', '0'};
    static const GifByteType loop[3] = {1, 0, 0};
    if (EGifPutExtensionLeader(gif, APPLICATION_EXT_FUNC_CODE) != GIF_OK ||
        EGifPutExtensionBlock(gif, sizeof app, app) != GIF_OK ||
        EGifPutExtensionBlock(gif, sizeof loop, loop) != GIF_OK ||
        EGifPutExtensionTrailer(gif) != GIF_OK) {
        return fail_open(g, gif->Error);
    }
    return 0;
}

int vw_gif_add(vw_gif *g, const uint8_t *index, uint16_t delay_cs)
{
    GifFileType *gif = g->gif;
    if (!gif || g->err) {
        return -1;
    }
    GraphicsControlBlock gcb = {.DisposalMode = DISPOSAL_UNSPECIFIED,
                                .UserInputFlag = false,
                                .DelayTime = delay_cs,
                                .TransparentColor = NO_TRANSPARENT_COLOR};
    GifByteType ext[4];
    const size_t ext_n = EGifGCBToExtension(&gcb, ext);
    if (EGifPutExtension(gif, GRAPHICS_EXT_FUNC_CODE, (int)ext_n, ext) != GIF_OK ||
        EGifPutImageDesc(gif, 0, 0, g->width, g->height, false, NULL) != GIF_OK) {
        return fail(g, gif->Error);
    }
    for (uint32_t y = 0; y < g->height; y++) {
        memcpy(g->row, index + (size_t)y * g->width, g->width);
        if (EGifPutLine(gif, g->row, g->width) != GIF_OK) {
            return fail(g, gif->Error);
        }
    }
    g->frames++;
    return 0;
}

int vw_gif_close(vw_gif *g)
{
    int rc = g->err ? -1 : 0;
    if (g->gif) {
        int err = 0;
        if (EGifCloseFile(g->gif, &err) != GIF_OK) {
            rc = fail(g, err);
        }
        g->gif = NULL;
    }
    free(g->row);
    g->row = NULL;
    return rc;
}
