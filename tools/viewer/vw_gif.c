/* vw_gif.c: animated GIF writer (see vw_gif.h). LZW after the GIF89a specification, appendix F:
 * variable code width from 9 to 12 bits, a clear code when the table is full. */
#include "vw_gif.h"

#include <stdlib.h>
#include <string.h>

static void put_bytes(vw_gif *g, const void *p, size_t n)
{
    if (!g->err && fwrite(p, 1, n, g->f) != n) {
        g->err = 1;
    }
}

static void put_u16(vw_gif *g, uint16_t v)
{
    uint8_t b[2] = {(uint8_t)v, (uint8_t)(v >> 8)};
    put_bytes(g, b, 2);
}

static void flush_block(vw_gif *g)
{
    if (g->block_n) {
        uint8_t n = (uint8_t)g->block_n;
        put_bytes(g, &n, 1);
        put_bytes(g, g->block, g->block_n);
        g->block_n = 0;
    }
}

static void reset_dict(vw_gif *g)
{
    for (uint32_t i = 0; i < g->used_n; i++) {
        g->dict[g->used[i]] = 0;
    }
    g->used_n = 0;
}

static void put_code(vw_gif *g, uint32_t code, uint32_t width)
{
    g->bits |= code << g->nbits;
    g->nbits += width;
    while (g->nbits >= 8u) {
        g->block[g->block_n++] = (uint8_t)g->bits;
        g->bits >>= 8;
        g->nbits -= 8u;
        if (g->block_n == 255u) {
            flush_block(g);
        }
    }
}

int vw_gif_open(vw_gif *g, const char *path, uint16_t width, uint16_t height,
                const uint8_t palette[768])
{
    memset(g, 0, sizeof *g);
    g->dict = calloc(4096u * 256u, sizeof(uint16_t));
    if (!g->dict) {
        return -1;
    }
    g->f = fopen(path, "wb");
    if (!g->f) {
        free(g->dict);
        g->dict = NULL;
        return -1;
    }
    g->width = width;
    g->height = height;
    put_bytes(g, "GIF89a", 6);
    put_u16(g, width);
    put_u16(g, height);
    const uint8_t lsd[3] = {0xF7, 0, 0}; /* global table of 256, 8-bit colour resolution */
    put_bytes(g, lsd, 3);
    put_bytes(g, palette, 768);
    /* NETSCAPE2.0 application extension: loop forever */
    const uint8_t loop[19] = {0x21, 0xFF, 0x0B, 'N', 'E',  'T',  'S',  'C',  'A', 'P',
                              'E',  '2',  '.',  '0', 0x03, 0x01, 0x00, 0x00, 0x00};
    put_bytes(g, loop, sizeof loop);
    return g->err ? -1 : 0;
}

int vw_gif_add(vw_gif *g, const uint8_t *index, uint16_t delay_cs)
{
    if (!g->f) {
        return -1;
    }
    const uint8_t gce[4] = {0x21, 0xF9, 0x04, 0x00};
    put_bytes(g, gce, 4);
    put_u16(g, delay_cs);
    const uint8_t gce_end[2] = {0x00, 0x00};
    put_bytes(g, gce_end, 2);
    const uint8_t desc = 0x2C;
    put_bytes(g, &desc, 1);
    put_u16(g, 0);
    put_u16(g, 0);
    put_u16(g, g->width);
    put_u16(g, g->height);
    const uint8_t flags_min[2] = {0x00, 8u}; /* no local table; LZW minimum code size 8 */
    put_bytes(g, flags_min, 2);

    const uint32_t clear = 256u, eoi = 257u;
    uint32_t width = 9u, next = 258u;
    reset_dict(g);
    g->bits = 0;
    g->nbits = 0;
    g->block_n = 0;
    put_code(g, clear, width);
    const size_t n = (size_t)g->width * g->height;
    uint32_t prefix = index[0];
    for (size_t i = 1; i < n; i++) {
        const uint8_t c = index[i];
        const uint16_t child = g->dict[prefix * 256u + c];
        if (child) {
            prefix = child;
            continue;
        }
        put_code(g, prefix, width);
        if (next < 4096u) {
            if (next == (1u << width)) {
                width++;
            }
            g->dict[prefix * 256u + c] = (uint16_t)next++;
            g->used[g->used_n++] = prefix * 256u + c;
        } else {
            put_code(g, clear, width);
            reset_dict(g);
            width = 9u;
            next = 258u;
        }
        prefix = c;
    }
    put_code(g, prefix, width);
    put_code(g, eoi, width);
    if (g->nbits) {
        g->block[g->block_n++] = (uint8_t)g->bits;
        g->bits = 0;
        g->nbits = 0;
    }
    flush_block(g);
    const uint8_t term = 0;
    put_bytes(g, &term, 1);
    g->frames++;
    return g->err ? -1 : 0;
}

int vw_gif_close(vw_gif *g)
{
    int rc = 0;
    if (g->f) {
        const uint8_t trailer = 0x3B;
        put_bytes(g, &trailer, 1);
        if (fclose(g->f) != 0) {
            g->err = 1;
        }
        g->f = NULL;
        rc = g->err ? -1 : 0;
    }
    free(g->dict);
    g->dict = NULL;
    return rc;
}
