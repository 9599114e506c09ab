/* sc_png_write.c: PNG with stored deflate blocks (see sc_png_write.h). */
#include "sc_png_write.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "sc_crc32.h"
#include "sc_err.h"

typedef struct png_out {
    FILE *f;
    uint32_t crc;    /* running CRC of the current chunk */
    uint32_t a1, a2; /* Adler-32 of the zlib stream */
    int err;
} png_out;

static void put(png_out *o, const void *p, size_t n)
{
    if (!o->err && fwrite(p, 1, n, o->f) != n) {
        o->err = 1;
    }
    o->crc = sc_crc32_update(o->crc, p, n);
}

static void be32(uint8_t *b, uint32_t v)
{
    b[0] = (uint8_t)(v >> 24);
    b[1] = (uint8_t)(v >> 16);
    b[2] = (uint8_t)(v >> 8);
    b[3] = (uint8_t)v;
}

static void chunk_begin(png_out *o, const char type[4], uint32_t len)
{
    uint8_t b[4];
    be32(b, len);
    if (!o->err && fwrite(b, 1, 4, o->f) != 4) {
        o->err = 1;
    }
    o->crc = SC_CRC32_INIT;
    put(o, type, 4);
}

static void chunk_end(png_out *o)
{
    uint8_t b[4];
    be32(b, sc_crc32_final(o->crc));
    if (!o->err && fwrite(b, 1, 4, o->f) != 4) {
        o->err = 1;
    }
}

/* Raw zlib data, also fed to Adler-32. */
static void put_raw(png_out *o, const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        o->a1 = (o->a1 + p[i]) % 65521u;
        o->a2 = (o->a2 + o->a1) % 65521u;
    }
    put(o, p, n);
}

int sc_png_write(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                 const uint8_t *pixels, size_t stride)
{
    if (!path || !pixels || width == 0u || height == 0u || (channels != 1u && channels != 3u) ||
        stride < (size_t)width * channels) {
        return SC_ERR_INVALID_ARG;
    }
    char tmp[4096 + 8];
    if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp) {
        return SC_ERR_INVALID_ARG;
    }
    png_out o = {fopen(tmp, "wb"), 0u, 1u, 0u, 0};
    if (!o.f) {
        return SC_ERR_IO;
    }
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    if (fwrite(sig, 1, sizeof sig, o.f) != sizeof sig) {
        o.err = 1;
    }
    uint8_t ihdr[13];
    be32(ihdr, width);
    be32(ihdr + 4, height);
    ihdr[8] = 8;                        /* bit depth */
    ihdr[9] = channels == 1u ? 0u : 2u; /* colour type: grey / RGB */
    ihdr[10] = 0;                       /* deflate */
    ihdr[11] = 0;                       /* adaptive filtering (we use filter 0) */
    ihdr[12] = 0;                       /* no interlace */
    chunk_begin(&o, "IHDR", 13u);
    put(&o, ihdr, 13u);
    chunk_end(&o);

    const uint64_t row = 1u + (uint64_t)width * channels; /* filter byte + pixels */
    const uint64_t raw = row * height;
    const uint64_t blocks = (raw + 65534u) / 65535u;
    const uint64_t idat = 2u + blocks * 5u + raw + 4u;
    if (idat > 0x7FFFFFFFu) {
        fclose(o.f);
        remove(tmp);
        return SC_ERR_INVALID_ARG;
    }
    chunk_begin(&o, "IDAT", (uint32_t)idat);
    const uint8_t zhdr[2] = {0x78, 0x01}; /* deflate, 32 KiB window, no dictionary */
    put(&o, zhdr, 2u);
    /* Stream rows into stored blocks of at most 65535 bytes. */
    uint64_t left = raw;   /* raw bytes still to emit */
    uint32_t in_block = 0; /* bytes left in the open block */
    for (uint32_t y = 0; y < height; y++) {
        const uint8_t *src = pixels + (size_t)y * stride;
        size_t pos = 0; /* 0 = the filter byte, then pixel bytes */
        const size_t n_row = (size_t)row;
        while (pos < n_row) {
            if (in_block == 0u) {
                const uint32_t len = left > 65535u ? 65535u : (uint32_t)left;
                const uint8_t bh[5] = {(uint8_t)(left <= 65535u ? 1u : 0u), (uint8_t)len,
                                       (uint8_t)(len >> 8), (uint8_t)~len, (uint8_t)((~len) >> 8)};
                put(&o, bh, 5u);
                in_block = len;
            }
            size_t take = n_row - pos;
            if (take > in_block) {
                take = in_block;
            }
            if (pos == 0u) {
                const uint8_t filter = 0;
                put_raw(&o, &filter, 1u);
                pos = 1u;
                take -= 1u;
                in_block -= 1u;
                left -= 1u;
            }
            put_raw(&o, src + (pos - 1u), take);
            pos += take;
            in_block -= (uint32_t)take;
            left -= take;
        }
    }
    uint8_t ad[4];
    be32(ad, (o.a2 << 16) | o.a1);
    put(&o, ad, 4u);
    chunk_end(&o);
    chunk_begin(&o, "IEND", 0u);
    chunk_end(&o);
    if (fclose(o.f) != 0) {
        o.err = 1;
    }
    if (o.err || rename(tmp, path) != 0) {
        int e = errno;
        remove(tmp);
        errno = e;
        return SC_ERR_IO;
    }
    return 0;
}
