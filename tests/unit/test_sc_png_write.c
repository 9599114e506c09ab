/* test_sc_png_write.c: the PNG writer (libpng) produces files that libpng reads back with
 * exactly the pixels written (grey and RGB, a stride wider than the row, sizes from 1 x 1),
 * compressed, byte-identical when written twice, and refuses bad arguments and unwritable
 * paths without leaving a file behind. */
#include "sc_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sc_err.h"
#include "sc_png_write.h"
#include "sc_test_png.h"

static void check_roundtrip(uint32_t w, uint32_t h, uint32_t ch)
{
    const size_t stride = (size_t)w * ch + 5u; /* a stride wider than the row */
    uint8_t *px = malloc(stride * h);
    for (size_t i = 0; i < stride * h; i++) {
        px[i] = (uint8_t)(i * 131u + 7u);
    }
    const char *path = SC_BINARY_DIR "/test_sc_png_write.png";
    assert_int_equal(sc_png_write(path, w, h, ch, px, stride), 0);
    uint32_t rw = 0, rh = 0, rc = 9;
    uint8_t *back = NULL;
    assert_int_equal(sc_test_png_read(path, &rw, &rh, &rc, &back), 0);
    assert_int_equal(rw, w);
    assert_int_equal(rh, h);
    assert_int_equal(rc, ch);
    assert_non_null(back);
    for (uint32_t y = 0; y < h; y++) {
        assert_memory_equal(back + (size_t)y * w * ch, px + (size_t)y * stride, (size_t)w * ch);
    }
    free(back);
    free(px);
    remove(path);
}

static void grey_image_round_trips_through_libpng(void **state)
{
    (void)state;
    check_roundtrip(512u, 300u, 1u);
    check_roundtrip(1u, 1u, 1u);
}

static void rgb_image_round_trips(void **state)
{
    (void)state;
    check_roundtrip(333u, 97u, 3u);
}

static long file_size(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 ? (long)sb.st_size : -1;
}

static uint8_t *slurp(const char *path, long n)
{
    uint8_t *b = malloc((size_t)n);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    return b;
}

/* A smooth frame (what the scan converter makes) compresses well below its raw size, and the
 * same image gives the same bytes (no time stamp or other varying chunk). */
static void output_is_compressed_and_deterministic(void **state)
{
    (void)state;
    enum { W = 480, H = 640 };
    static uint8_t px[W * H];
    for (uint32_t y = 0; y < H; y++) {
        for (uint32_t x = 0; x < W; x++) {
            px[y * W + x] = (uint8_t)((x / 4u + y / 8u) & 0xFFu);
        }
    }
    const char *a = SC_BINARY_DIR "/test_sc_png_write_a.png";
    const char *b = SC_BINARY_DIR "/test_sc_png_write_b.png";
    assert_int_equal(sc_png_write(a, W, H, 1u, px, W), 0);
    assert_int_equal(sc_png_write(b, W, H, 1u, px, W), 0);
    const long na = file_size(a), nb = file_size(b);
    assert_true(na > 0 && na < (long)(W * H) / 4);
    assert_int_equal(na, nb);
    uint8_t *ba = slurp(a, na), *bb = slurp(b, nb);
    assert_memory_equal(ba, bb, (size_t)na);
    free(ba);
    free(bb);
    remove(a);
    remove(b);
}

static void bad_arguments_and_unwritable_paths_are_refused(void **state)
{
    (void)state;
    uint8_t px[4] = {0};
    assert_int_equal(sc_png_write("x.png", 0u, 1u, 1u, px, 1u), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_png_write("x.png", 2u, 2u, 2u, px, 4u), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_png_write("x.png", 4u, 1u, 1u, px, 3u), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_png_write("x.png", 70000u, 1u, 1u, px, 70000u), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_png_write("/nonexistent-dir/x.png", 2u, 2u, 1u, px, 2u), SC_ERR_IO);
    assert_int_equal(file_size("x.png"), -1);
    /* a path whose directory exists but the final rename fails (a directory in the way) */
    const char *dir = SC_BINARY_DIR "/test_sc_png_write_dir.png";
    (void)mkdir(dir, 0755);
    assert_int_equal(sc_png_write(dir, 2u, 2u, 1u, px, 2u), SC_ERR_IO);
    assert_int_equal(file_size(SC_BINARY_DIR "/test_sc_png_write_dir.png.tmp"), -1);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(grey_image_round_trips_through_libpng),
        cmocka_unit_test(output_is_compressed_and_deterministic),
        cmocka_unit_test(rgb_image_round_trips),
        cmocka_unit_test(bad_arguments_and_unwritable_paths_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
