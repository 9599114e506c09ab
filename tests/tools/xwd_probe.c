/*
 * xwd_probe.c: reads an X window dump (XWD, as Xvfb -fbdir maps its screen) and checks what a
 * person would see in a rectangle: `xwd_probe FILE dark X Y R MAX` passes when the mean grey of
 * the (2R+1)^2 square at (X, Y) is at most MAX; `bright` the same with at least; `contrast X1 Y1
 * X2 Y2 R MIN` when the mean at 2 exceeds the mean at 1 by MIN; `text X0 Y0 X1 Y1 N` when the
 * box holds at least N near-white pixels (overlay text). Several checks may follow one FILE.
 * Prints each measured value; exit 0 when every check passes, 1 otherwise, 2 on a bad file.
 * Only TrueColor 24/32-bit dumps (what Xvfb -screen WxHx24 produces) are supported.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint32_t be32(const uint8_t *p)
{
    return ((uint32_t)p[0] << 24) | ((uint32_t)p[1] << 16) | ((uint32_t)p[2] << 8) | p[3];
}

typedef struct img {
    uint32_t w, h, bpl, bpp, lsb_first;
    uint32_t rmask, gmask, bmask;
    const uint8_t *px;
} img;

static int shift_of(uint32_t m)
{
    int s = 0;
    while (m && !(m & 1u)) {
        m >>= 1;
        s++;
    }
    return s;
}

static double grey_at(const img *im, uint32_t x, uint32_t y)
{
    const uint8_t *p = im->px + (size_t)y * im->bpl + (size_t)x * (im->bpp / 8u);
    uint32_t v = 0;
    const uint32_t n = im->bpp / 8u;
    for (uint32_t i = 0; i < n; i++) {
        v |= (uint32_t)p[i] << (im->lsb_first ? 8u * i : 8u * (n - 1u - i));
    }
    const double r = (double)((v & im->rmask) >> shift_of(im->rmask));
    const double g = (double)((v & im->gmask) >> shift_of(im->gmask));
    const double b = (double)((v & im->bmask) >> shift_of(im->bmask));
    return (r + g + b) / 3.0;
}

static double mean_sq(const img *im, long x, long y, long r)
{
    double sum = 0.0;
    long n = 0;
    for (long j = y - r; j <= y + r; j++) {
        for (long i = x - r; i <= x + r; i++) {
            if (i >= 0 && j >= 0 && (uint32_t)i < im->w && (uint32_t)j < im->h) {
                sum += grey_at(im, (uint32_t)i, (uint32_t)j);
                n++;
            }
        }
    }
    return n ? sum / (double)n : -1.0;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: xwd_probe FILE CHECK...\n");
        return 2;
    }
    FILE *f = fopen(argv[1], "rb");
    if (!f) {
        perror(argv[1]);
        return 2;
    }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *buf = malloc((size_t)size);
    if (!buf || fread(buf, 1, (size_t)size, f) != (size_t)size || size < 100) {
        fprintf(stderr, "xwd_probe: cannot read %s\n", argv[1]);
        return 2;
    }
    fclose(f);
    const uint32_t header = be32(buf), version = be32(buf + 4);
    img im;
    im.w = be32(buf + 16);
    im.h = be32(buf + 20);
    im.lsb_first = be32(buf + 28) == 0u; /* byte_order: 0 LSBFirst */
    im.bpp = be32(buf + 44);
    im.bpl = be32(buf + 48);
    const uint32_t vclass = be32(buf + 52);
    im.rmask = be32(buf + 56);
    im.gmask = be32(buf + 60);
    im.bmask = be32(buf + 64);
    const uint32_t ncolors = be32(buf + 76);
    if (version != 7u || vclass != 4u || (im.bpp != 24u && im.bpp != 32u)) {
        fprintf(stderr, "xwd_probe: unsupported dump (version %u class %u bpp %u)\n", version,
                vclass, im.bpp);
        return 2;
    }
    const size_t off = (size_t)header + (size_t)ncolors * 12u;
    if (off + (size_t)im.bpl * im.h > (size_t)size) {
        fprintf(stderr, "xwd_probe: truncated dump\n");
        return 2;
    }
    im.px = buf + off;
    printf("xwd %ux%u, %u bpp\n", im.w, im.h, im.bpp);
    int fails = 0;
    for (int a = 2; a < argc;) {
        const char *c = argv[a];
        if ((strcmp(c, "dark") == 0 || strcmp(c, "bright") == 0) && a + 4 < argc) {
            double m = mean_sq(&im, atol(argv[a + 1]), atol(argv[a + 2]), atol(argv[a + 3]));
            double lim = atof(argv[a + 4]);
            int ok = c[0] == 'd' ? m <= lim : m >= lim;
            printf("%s at (%s,%s) r %s: mean %.1f, limit %.1f: %s\n", c, argv[a + 1], argv[a + 2],
                   argv[a + 3], m, lim, ok ? "ok" : "FAIL");
            fails += !ok;
            a += 5;
        } else if (strcmp(c, "contrast") == 0 && a + 6 < argc) {
            long r = atol(argv[a + 5]);
            double m1 = mean_sq(&im, atol(argv[a + 1]), atol(argv[a + 2]), r);
            double m2 = mean_sq(&im, atol(argv[a + 3]), atol(argv[a + 4]), r);
            double min = atof(argv[a + 6]);
            int ok = m2 - m1 >= min;
            printf("contrast (%s,%s) %.1f vs (%s,%s) %.1f: %.1f, at least %.1f: %s\n", argv[a + 1],
                   argv[a + 2], m1, argv[a + 3], argv[a + 4], m2, m2 - m1, min, ok ? "ok" : "FAIL");
            fails += !ok;
            a += 7;
        } else if (strcmp(c, "text") == 0 && a + 5 < argc) {
            long x0 = atol(argv[a + 1]), y0 = atol(argv[a + 2]);
            long x1 = atol(argv[a + 3]), y1 = atol(argv[a + 4]);
            long need = atol(argv[a + 5]), n = 0;
            for (long y = y0; y <= y1 && y < (long)im.h; y++) {
                for (long x = x0; x <= x1 && x < (long)im.w; x++) {
                    n += grey_at(&im, (uint32_t)x, (uint32_t)y) >= 240.0;
                }
            }
            int ok = n >= need;
            printf("text box (%ld,%ld)-(%ld,%ld): %ld white pixels, at least %ld: %s\n", x0, y0, x1,
                   y1, n, need, ok ? "ok" : "FAIL");
            fails += !ok;
            a += 6;
        } else {
            fprintf(stderr, "xwd_probe: bad check at '%s'\n", c);
            return 2;
        }
    }
    free(buf);
    return fails ? 1 : 0;
}
