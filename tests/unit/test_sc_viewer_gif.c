/* test_sc_viewer_gif.c: the viewer's animated GIF writer (tools/viewer/vw_gif.c, giflib)
 * produces a GIF89a that giflib's decoder reads back to the exact frames, delays, palette and
 * loop extension written (noise that fills the LZW table, smooth runs, one colour), the same
 * bytes when written twice, and an unwritable path is an error that leaves nothing open. */
#include "sc_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gif_lib.h>
#include <sys/stat.h>

#include "vw_gif.h"

static void written_frames_decode_back_exactly(void **state)
{
    (void)state;
    const uint16_t w = 301, h = 203;
    const size_t n = (size_t)w * h;
    uint8_t pal[768];
    for (int i = 0; i < 768; i++) {
        pal[i] = (uint8_t)(i / 3);
    }
    uint8_t *frames[3];
    for (int f = 0; f < 3; f++) {
        frames[f] = malloc(n);
        for (size_t i = 0; i < n; i++) {
            /* 0: noise (many codes, table resets); 1: smooth runs; 2: all one colour */
            uint32_t x = (uint32_t)i * 2654435761u + (uint32_t)f * 977u;
            frames[f][i] = f == 0 ? (uint8_t)(x >> 24) : f == 1 ? (uint8_t)((i / 37u) & 0xFFu) : 7u;
        }
    }
    const char *path = SC_BINARY_DIR "/test_sc_viewer_gif.gif";
    vw_gif g;
    assert_int_equal(vw_gif_open(&g, path, w, h, pal), 0);
    for (int f = 0; f < 3; f++) {
        assert_int_equal(vw_gif_add(&g, frames[f], (uint16_t)(5 + f)), 0);
    }
    assert_int_equal(vw_gif_close(&g), 0);

    int err = 0;
    GifFileType *gif = DGifOpenFileName(path, &err);
    assert_non_null(gif);
    assert_int_equal(DGifSlurp(gif), GIF_OK);
    assert_int_equal(gif->SWidth, w);
    assert_int_equal(gif->SHeight, h);
    assert_non_null(gif->SColorMap);
    assert_int_equal(gif->SColorMap->ColorCount, 256);
    for (int i = 0; i < 256; i++) {
        assert_int_equal(gif->SColorMap->Colors[i].Red, pal[3 * i]);
        assert_int_equal(gif->SColorMap->Colors[i].Green, pal[3 * i + 1]);
        assert_int_equal(gif->SColorMap->Colors[i].Blue, pal[3 * i + 2]);
    }
    assert_int_equal(gif->ImageCount, 3);
    int loop_found = 0;
    for (int f = 0; f < gif->ImageCount; f++) {
        const SavedImage *im = &gif->SavedImages[f];
        assert_int_equal(im->ImageDesc.Left, 0);
        assert_int_equal(im->ImageDesc.Top, 0);
        assert_int_equal(im->ImageDesc.Width, w);
        assert_int_equal(im->ImageDesc.Height, h);
        assert_false(im->ImageDesc.Interlace);
        assert_null(im->ImageDesc.ColorMap);
        assert_memory_equal(im->RasterBits, frames[f], n);
        GraphicsControlBlock gcb;
        assert_int_equal(DGifSavedExtensionToGCB(gif, f, &gcb), GIF_OK);
        assert_int_equal(gcb.DelayTime, 5 + f); /* 1/100 s */
        assert_int_equal(gcb.TransparentColor, NO_TRANSPARENT_COLOR);
        for (int e = 0; e < im->ExtensionBlockCount; e++) {
            const ExtensionBlock *x = &im->ExtensionBlocks[e];
            if (x->Function == APPLICATION_EXT_FUNC_CODE && x->ByteCount == 11 &&
                memcmp(x->Bytes, "NETSCAPE2.0", 11) == 0) {
                loop_found = 1; /* giflib keeps it with the first image */
                assert_true(e + 1 < im->ExtensionBlockCount);
                const ExtensionBlock *sub = &im->ExtensionBlocks[e + 1];
                assert_int_equal(sub->ByteCount, 3);
                assert_int_equal(sub->Bytes[0], 1);
                assert_int_equal(sub->Bytes[1] | sub->Bytes[2] << 8, 0); /* forever */
            }
        }
    }
    assert_true(loop_found);
    assert_int_equal(DGifCloseFile(gif, &err), GIF_OK);

    /* the same frames give the same bytes */
    const char *path2 = SC_BINARY_DIR "/test_sc_viewer_gif_2.gif";
    assert_int_equal(vw_gif_open(&g, path2, w, h, pal), 0);
    for (int f = 0; f < 3; f++) {
        assert_int_equal(vw_gif_add(&g, frames[f], (uint16_t)(5 + f)), 0);
    }
    assert_int_equal(vw_gif_close(&g), 0);
    struct stat s1, s2;
    assert_int_equal(stat(path, &s1), 0);
    assert_int_equal(stat(path2, &s2), 0);
    assert_int_equal(s1.st_size, s2.st_size);
    uint8_t *b1 = malloc((size_t)s1.st_size), *b2 = malloc((size_t)s2.st_size);
    FILE *f1 = fopen(path, "rb"), *f2 = fopen(path2, "rb");
    assert_int_equal(fread(b1, 1, (size_t)s1.st_size, f1), (size_t)s1.st_size);
    assert_int_equal(fread(b2, 1, (size_t)s2.st_size, f2), (size_t)s2.st_size);
    fclose(f1);
    fclose(f2);
    assert_memory_equal(b1, b2, (size_t)s1.st_size);
    free(b1);
    free(b2);
    remove(path2);
    for (int f = 0; f < 3; f++) {
        free(frames[f]);
    }
    remove(path);
}

static void an_unwritable_path_fails_and_adds_then_fail(void **state)
{
    (void)state;
    uint8_t pal[768] = {0};
    vw_gif g;
    assert_int_equal(vw_gif_open(&g, "/nonexistent-dir/x.gif", 64, 64, pal), -1);
    assert_int_not_equal(g.err, 0);
    assert_null(g.gif);
    uint8_t px[64 * 64] = {0};
    assert_int_equal(vw_gif_add(&g, px, 5), -1);
    assert_int_equal(vw_gif_close(&g), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(written_frames_decode_back_exactly),
        cmocka_unit_test(an_unwritable_path_fails_and_adds_then_fail),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
