/* test_sc_png_write.c: the dependency-free PNG writer produces a valid PNG (signature, chunk
 * CRCs, zlib stored blocks, Adler-32) whose pixels are the ones written, across the 64 KiB
 * stored-block boundaries, for grey and RGB. */
#include "sc_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sc_crc32.h"
#include "sc_err.h"
#include "sc_png_write.h"

static uint32_t rd32(const uint8_t *p)
{
    return ((uint32_t)p[0] << 24) | ((uint32_t)p[1] << 16) | ((uint32_t)p[2] << 8) | p[3];
}

/* Decode a PNG made of stored deflate blocks (what the writer produces); returns raw rows
 * (filter byte + pixels) in *raw, checking every CRC, the block lengths and the Adler-32. */
static size_t decode(const uint8_t *f, size_t n, uint32_t *w, uint32_t *h, uint8_t *ctype,
                     uint8_t *raw, size_t raw_cap)
{
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    assert_true(n > 8u);
    assert_memory_equal(f, sig, 8u);
    static uint8_t z[8 << 20];
    size_t zn = 0, pos = 8;
    int seen_end = 0;
    while (pos + 12u <= n) {
        uint32_t len = rd32(f + pos);
        const uint8_t *type = f + pos + 4;
        assert_true(pos + 12u + len <= n);
        uint32_t crc = sc_crc32(type, 4u + len);
        assert_int_equal(crc, rd32(f + pos + 8 + len));
        if (memcmp(type, "IHDR", 4) == 0) {
            *w = rd32(type + 4);
            *h = rd32(type + 8);
            assert_int_equal(type[12], 8);
            *ctype = type[13];
        } else if (memcmp(type, "IDAT", 4) == 0) {
            memcpy(z + zn, type + 4, len);
            zn += len;
        } else if (memcmp(type, "IEND", 4) == 0) {
            seen_end = 1;
        }
        pos += 12u + len;
    }
    assert_true(seen_end);
    assert_int_equal(pos, n);
    assert_int_equal(z[0], 0x78);
    assert_int_equal(((unsigned)z[0] << 8 | z[1]) % 31u, 0u); /* zlib header check */
    size_t zp = 2, rn = 0;
    for (;;) {
        uint8_t bh = z[zp];
        assert_int_equal(bh & 6u, 0u); /* stored */
        uint32_t len = (uint32_t)z[zp + 1] | ((uint32_t)z[zp + 2] << 8);
        uint32_t nlen = (uint32_t)z[zp + 3] | ((uint32_t)z[zp + 4] << 8);
        assert_int_equal(len ^ 0xFFFFu, nlen);
        assert_true(rn + len <= raw_cap);
        memcpy(raw + rn, z + zp + 5, len);
        rn += len;
        zp += 5u + len;
        if (bh & 1u) {
            break;
        }
    }
    uint32_t a = 1, b = 0;
    for (size_t i = 0; i < rn; i++) {
        a = (a + raw[i]) % 65521u;
        b = (b + a) % 65521u;
    }
    assert_int_equal(rd32(z + zp), (b << 16) | a);
    assert_int_equal(zp + 4u, zn);
    return rn;
}

static void check_roundtrip(uint32_t w, uint32_t h, uint32_t ch)
{
    const size_t stride = (size_t)w * ch + 5u; /* a stride wider than the row */
    uint8_t *px = malloc(stride * h);
    for (size_t i = 0; i < stride * h; i++) {
        px[i] = (uint8_t)(i * 131u + 7u);
    }
    const char *path = SC_BINARY_DIR "/test_sc_png_write.png";
    assert_int_equal(sc_png_write(path, w, h, ch, px, stride), 0);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    static uint8_t file[8 << 20];
    size_t n = fread(file, 1, sizeof file, f);
    fclose(f);
    static uint8_t raw[8 << 20];
    uint32_t rw = 0, rh = 0;
    uint8_t ct = 9;
    size_t rn = decode(file, n, &rw, &rh, &ct, raw, sizeof raw);
    assert_int_equal(rw, w);
    assert_int_equal(rh, h);
    assert_int_equal(ct, ch == 1u ? 0u : 2u);
    assert_int_equal(rn, (size_t)h * (1u + w * ch));
    for (uint32_t y = 0; y < h; y++) {
        const uint8_t *row = raw + (size_t)y * (1u + w * ch);
        assert_int_equal(row[0], 0);
        assert_memory_equal(row + 1, px + (size_t)y * stride, (size_t)w * ch);
    }
    free(px);
    remove(path);
}

static void grey_image_round_trips_through_several_stored_blocks(void **state)
{
    (void)state;
    check_roundtrip(512u, 300u, 1u); /* 153,900 raw bytes: 3 blocks, boundaries mid-row */
    check_roundtrip(1u, 1u, 1u);
}

static void rgb_image_round_trips(void **state)
{
    (void)state;
    check_roundtrip(333u, 97u, 3u);
}

static void bad_arguments_and_unwritable_paths_are_refused(void **state)
{
    (void)state;
    uint8_t px[4] = {0};
    assert_int_equal(sc_png_write("x.png", 0u, 1u, 1u, px, 1u), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_png_write("x.png", 2u, 2u, 2u, px, 4u), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_png_write("x.png", 4u, 1u, 1u, px, 3u), SC_ERR_INVALID_ARG);
    assert_int_equal(sc_png_write("/nonexistent-dir/x.png", 2u, 2u, 1u, px, 2u), SC_ERR_IO);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(grey_image_round_trips_through_several_stored_blocks),
        cmocka_unit_test(rgb_image_round_trips),
        cmocka_unit_test(bad_arguments_and_unwritable_paths_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
