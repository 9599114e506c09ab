/* test_sc_viewer_gif.c: the viewer's animated GIF writer (tools/viewer/vw_gif.c) produces a
 * GIF89a that an independent LZW decoder (below, after the GIF89a specification) reads back
 * to the exact frames written, including code-width growth to 12 bits and table resets. */
#include "sc_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vw_gif.h"

typedef struct rd {
    const uint8_t *p;
    size_t n, pos;
} rd;

static uint8_t get8(rd *r)
{
    assert_true(r->pos < r->n);
    return r->p[r->pos++];
}

static uint16_t get16(rd *r)
{
    uint16_t lo = get8(r);
    return (uint16_t)(lo | (get8(r) << 8));
}

/* Decode one image's LZW data (sub-blocks) into out (w*h). */
static void decode_lzw(rd *r, uint8_t *out, size_t npix)
{
    const uint32_t min = get8(r);
    assert_int_equal(min, 8);
    /* gather the sub-blocks */
    static uint8_t data[16 << 20];
    size_t dn = 0;
    for (;;) {
        uint8_t len = get8(r);
        if (!len) {
            break;
        }
        assert_true(r->pos + len <= r->n);
        memcpy(data + dn, r->p + r->pos, len);
        dn += len;
        r->pos += len;
    }
    static uint16_t prefix[4096];
    static uint8_t suffix[4096], first[4096];
    static uint8_t stack[4096];
    const uint32_t clear = 256u, eoi = 257u;
    for (uint32_t i = 0; i < 256u; i++) {
        prefix[i] = 0xFFFFu;
        suffix[i] = first[i] = (uint8_t)i;
    }
    uint32_t width = 9u, next = 258u, old = 0xFFFFu;
    uint64_t bits = 0;
    uint32_t nbits = 0;
    size_t dp = 0, op = 0;
    for (;;) {
        while (nbits < width) {
            assert_true(dp < dn);
            bits |= (uint64_t)data[dp++] << nbits;
            nbits += 8u;
        }
        uint32_t code = (uint32_t)(bits & ((1u << width) - 1u));
        bits >>= width;
        nbits -= width;
        if (code == clear) {
            width = 9u;
            next = 258u;
            old = 0xFFFFu;
            continue;
        }
        if (code == eoi) {
            break;
        }
        uint32_t in = code;
        uint32_t sp = 0;
        if (old == 0xFFFFu) {
            assert_true(code < 256u);
            assert_true(op < npix);
            out[op++] = (uint8_t)code;
            old = code;
            continue;
        }
        assert_true(code <= next);
        if (code == next) { /* KwKwK */
            stack[sp++] = first[old];
            code = old;
        }
        while (code >= 256u) {
            stack[sp++] = suffix[code];
            code = prefix[code];
        }
        stack[sp++] = (uint8_t)code;
        if (next < 4096u) {
            prefix[next] = (uint16_t)old;
            suffix[next] = (uint8_t)code;
            first[next] = first[old];
            next++;
            if (next == (1u << width) && width < 12u) {
                width++;
            }
        }
        while (sp) {
            assert_true(op < npix);
            out[op++] = stack[--sp];
        }
        old = in;
    }
    assert_int_equal(op, npix);
}

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

    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    static uint8_t file[16 << 20];
    rd r = {file, fread(file, 1, sizeof file, fp), 0};
    fclose(fp);
    assert_memory_equal(file, "GIF89a", 6);
    r.pos = 6;
    assert_int_equal(get16(&r), w);
    assert_int_equal(get16(&r), h);
    assert_int_equal(get8(&r), 0xF7);
    r.pos += 2;
    assert_memory_equal(file + r.pos, pal, 768);
    r.pos += 768;
    uint8_t *img = malloc(n);
    int frame = 0;
    for (;;) {
        uint8_t b = get8(&r);
        if (b == 0x3B) {
            break;
        }
        if (b == 0x21) {
            uint8_t label = get8(&r);
            if (label == 0xF9) {
                assert_int_equal(get8(&r), 4);
                r.pos += 1;
                assert_int_equal(get16(&r), 5 + frame); /* delay, 1/100 s */
                r.pos += 1;                             /* transparent index */
            } else {
                assert_int_equal(label, 0xFF); /* application extension: NETSCAPE2.0 loop */
                const uint8_t bs = get8(&r);
                assert_int_equal(bs, 11);
                assert_memory_equal(file + r.pos, "NETSCAPE2.0", 11);
                r.pos += bs;
            }
            /* skip the remaining sub-blocks of the extension */
            for (uint8_t len = get8(&r); len; len = get8(&r)) {
                r.pos += len;
            }
            continue;
        }
        assert_int_equal(b, 0x2C);
        r.pos += 4;
        assert_int_equal(get16(&r), w);
        assert_int_equal(get16(&r), h);
        assert_int_equal(get8(&r), 0);
        memset(img, 0xAB, n);
        decode_lzw(&r, img, n);
        assert_memory_equal(img, frames[frame], n);
        frame++;
    }
    assert_int_equal(frame, 3);
    assert_int_equal(r.pos, r.n);
    for (int f = 0; f < 3; f++) {
        free(frames[f]);
    }
    free(img);
    remove(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(written_frames_decode_back_exactly),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
