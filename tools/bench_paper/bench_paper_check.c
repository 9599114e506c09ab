/* bench_paper_check.c: the smoke test's checker of bench-paper's outputs (no timing asserted).
 *   bench-paper-check CSV PNG ROWS
 * CSV: the header bench-paper writes, then at least ROWS rows of 18 fields each: the mesh as
 * NXxNYxNZ, positive node and tet counts, a known method, a worker count, run and frame
 * numbers, finite non-negative times and rates (the sampling and output fields empty exactly on
 * Bullet's rows). PNG: decodes with libpng, at least 200 x 200 pixels, and has at least two
 * bar colours besides white and black (bars were drawn). Prints what failed; exit 0 or 1. */
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const k_header =
    "mesh,nodes,tets,method,workers,run,frames,step_ms,step_cpu_ms,collision_ms,sampling_ms,"
    "output_ms,frame_with_output_ms,fps_without_output,fps_with_output,max_disp_mm,"
    "sampling_cpu_ms,output_cpu_ms";

static int fail(const char *what, long line)
{
    fprintf(stderr, "bench-paper-check: %s (line %ld)\n", what, line);
    return 1;
}

static int is_uint(const char *s)
{
    if (!*s) {
        return 0;
    }
    for (; *s; s++) {
        if (*s < '0' || *s > '9') {
            return 0;
        }
    }
    return 1;
}

static int is_num(const char *s)
{
    char *end = NULL;
    const double v = strtod(s, &end);
    return *s && end && *end == '\0' && isfinite(v) && v >= 0.0;
}

static int check_csv(const char *path, long min_rows)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        return fail("CSV missing", 0);
    }
    char line[1024];
    long n = 0, rows = 0;
    int rc = 0;
    while (rc == 0 && fgets(line, sizeof line, f)) {
        n++;
        const size_t len = strlen(line);
        if (len == 0 || line[len - 1] != '\n') {
            rc = fail("line too long or not terminated", n);
            break;
        }
        line[len - 1] = '\0';
        if (n == 1) {
            if (strcmp(line, k_header) != 0) {
                rc = fail("unexpected header", n);
            }
            continue;
        }
        char *field[19];
        int nf = 0;
        char *p = line;
        for (;;) {
            if (nf == 19) {
                break;
            }
            field[nf++] = p;
            char *c = strchr(p, ',');
            if (!c) {
                break;
            }
            *c = '\0';
            p = c + 1;
        }
        if (nf != 18) {
            rc = fail("not 18 fields", n);
            break;
        }
        unsigned a, b, c;
        char tail;
        if (sscanf(field[0], "%ux%ux%u%c", &a, &b, &c, &tail) != 3 || a < 2 || b < 2 || c < 2) {
            rc = fail("bad mesh", n);
            break;
        }
        const int bullet = strcmp(field[3], "bullet") == 0;
        if (!bullet && strcmp(field[3], "msds") != 0 && strcmp(field[3], "fem") != 0 &&
            strcmp(field[3], "corot") != 0) {
            rc = fail("bad method", n);
            break;
        }
        for (int i = 1; i <= 6; i++) {
            if (i != 3 && (!is_uint(field[i]) || (i != 5 && atol(field[i]) <= 0))) {
                rc = fail("bad count", n);
                break;
            }
        }
        if (rc) {
            break;
        }
        if ((unsigned long)atol(field[1]) != (unsigned long)a * b * c) {
            rc = fail("node count is not NX*NY*NZ", n);
            break;
        }
        for (int i = 7; i <= 17 && rc == 0; i++) {
            const int may_be_empty = bullet && i >= 9 && i != 13 && i != 15;
            if (may_be_empty ? field[i][0] != '\0' : !is_num(field[i])) {
                rc = fail(may_be_empty ? "Bullet row with an imaging time" : "bad number", n);
            }
        }
        if (rc == 0 && !(strtod(field[7], NULL) > 0.0)) {
            rc = fail("zero step time", n);
        }
        rows++;
    }
    fclose(f);
    if (rc == 0 && n == 0) {
        rc = fail("empty CSV", 0);
    }
    if (rc == 0 && rows < min_rows) {
        fprintf(stderr, "bench-paper-check: %ld rows, expected at least %ld\n", rows, min_rows);
        rc = 1;
    }
    return rc;
}

static int check_png(const char *path)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&img, path)) {
        return fail("PNG does not open or decode", 0);
    }
    img.format = PNG_FORMAT_RGB;
    if (img.width < 200 || img.height < 200) {
        png_image_free(&img);
        return fail("PNG too small", 0);
    }
    const size_t size = PNG_IMAGE_SIZE(img);
    unsigned char *px = malloc(size);
    if (!px || !png_image_finish_read(&img, NULL, px, 0, NULL)) {
        free(px);
        png_image_free(&img);
        return fail("PNG pixels do not decode", 0);
    }
    /* distinct colours other than white and black (up to 8 remembered) */
    unsigned colours[8];
    int nc = 0;
    for (size_t i = 0; i + 2 < size && nc < 8; i += 3) {
        const unsigned c = (unsigned)px[i] << 16 | (unsigned)px[i + 1] << 8 | px[i + 2];
        if (c == 0xFFFFFFu || c == 0u || c == 0xD7D7D7u) { /* background, text, grid */
            continue;
        }
        int seen = 0;
        for (int k = 0; k < nc; k++) {
            seen |= colours[k] == c;
        }
        if (!seen) {
            colours[nc++] = c;
        }
    }
    free(px);
    if (nc < 2) {
        return fail("PNG has no bars", 0);
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: bench-paper-check CSV PNG ROWS\n");
        return 2;
    }
    char *end = NULL;
    const long rows = strtol(argv[3], &end, 10);
    if (!end || *end || rows < 1) {
        fprintf(stderr, "usage: bench-paper-check CSV PNG ROWS\n");
        return 2;
    }
    int rc = check_csv(argv[1], rows);
    rc |= check_png(argv[2]);
    if (rc == 0) {
        printf("bench-paper-check: %s and %s well formed\n", argv[1], argv[2]);
    }
    return rc;
}
