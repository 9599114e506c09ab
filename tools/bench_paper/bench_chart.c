/* bench_chart.c: see bench_chart.h. */
#include "bench_chart.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sc_png_write.h"

#define W 1200
#define H 600
#define ML 110 /* left margin (axis labels) */
#define MR 20
#define MT 50  /* title */
#define MB 90 /* group names and legend */

static uint8_t g_px[H][W][3];

/* 5x7 glyphs, one byte per row, bit 4 = leftmost column */
typedef struct glyph {
    char c;
    uint8_t row[7];
} glyph;

static const glyph k_font[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'A', {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}}, {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}},
    {'C', {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}}, {'D', {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C}},
    {'E', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}}, {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
    {'G', {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}}, {'H', {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
    {'I', {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}}, {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
    {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}}, {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}},
    {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}}, {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
    {'O', {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
    {'Q', {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}}, {'R', {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}},
    {'S', {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}}, {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}},
    {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}}, {'X', {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}},
    {'Y', {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04}}, {'Z', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}},
    {'x', {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11}}, {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}},
    {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}}, {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}}, {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}}, {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}}, {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
    {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
};

static const uint8_t *glyph_rows(char c)
{
    if (c >= 'a' && c <= 'z' && c != 'x') {
        c = (char)(c - 'a' + 'A');
    }
    for (size_t i = 0; i < sizeof k_font / sizeof k_font[0]; i++) {
        if (k_font[i].c == c) {
            return k_font[i].row;
        }
    }
    return NULL; /* space and anything unknown: blank */
}

static void put(int x, int y, const uint8_t rgb[3])
{
    if (x >= 0 && x < W && y >= 0 && y < H) {
        memcpy(g_px[y][x], rgb, 3);
    }
}

static void rect(int x0, int y0, int x1, int y1, const uint8_t rgb[3])
{
    for (int y = y0; y < y1; y++) {
        for (int x = x0; x < x1; x++) {
            put(x, y, rgb);
        }
    }
}

/* text at (x, y) top-left, scale s (pixels per font dot); returns the width drawn */
static int text(int x, int y, const char *s, int scale, const uint8_t rgb[3])
{
    int cx = x;
    for (; s && *s; s++) {
        const uint8_t *g = glyph_rows(*s);
        if (g) {
            for (int r = 0; r < 7; r++) {
                for (int c = 0; c < 5; c++) {
                    if (g[r] & (0x10 >> c)) {
                        rect(cx + c * scale, y + r * scale, cx + (c + 1) * scale,
                             y + (r + 1) * scale, rgb);
                    }
                }
            }
        }
        cx += 6 * scale;
    }
    return cx - x;
}

static int text_width(const char *s, int scale)
{
    return (int)strlen(s) * 6 * scale;
}

/* y pixel of value v on the log axis */
static int y_of(const chart *c, double v)
{
    const double lo = log10(c->y_min), hi = log10(c->y_max);
    double f = (log10(v) - lo) / (hi - lo);
    if (f < 0.0) {
        f = 0.0;
    }
    if (f > 1.0) {
        f = 1.0;
    }
    return H - MB - (int)(f * (double)(H - MB - MT));
}

int chart_write_png(const chart *c, const char *path)
{
    if (!c || c->groups < 1 || c->groups > CHART_MAX_GROUPS || c->series < 1 ||
        c->series > CHART_MAX_SERIES || !(c->y_min > 0.0) || !(c->y_max > c->y_min)) {
        return -1;
    }
    static const uint8_t white[3] = {255, 255, 255}, black[3] = {0, 0, 0},
                         grid[3] = {215, 215, 215};
    rect(0, 0, W, H, white);
    text(ML, 14, c->title, 2, black);
    /* decades: grid line and label */
    for (double d = c->y_min; d <= c->y_max * 1.0001; d *= 10.0) {
        const int y = y_of(c, d);
        rect(ML, y, W - MR, y + 1, grid);
        char lab[32];
        snprintf(lab, sizeof lab, d < 0.1 ? "%.2f" : (d < 1.0 ? "%.1f" : "%.0f"), d);
        text(ML - 8 - text_width(lab, 2), y - 7, lab, 2, black);
    }
    /* y label, written as a column of letters */
    if (c->y_label) {
        const int n = (int)strlen(c->y_label);
        int y0 = MT + ((H - MB - MT) - n * 18) / 2;
        for (int i = 0; i < n; i++) {
            const char ch[2] = {c->y_label[i], 0};
            text(8, y0 + i * 18, ch, 2, black);
        }
    }
    rect(ML, MT, ML + 1, H - MB, black);
    rect(ML, H - MB, W - MR, H - MB + 1, black);
    const int gw = (W - MR - ML) / c->groups;
    const int bw = (gw - 16) / c->series;
    for (int g = 0; g < c->groups; g++) {
        const int gx = ML + g * gw + 8;
        for (int s = 0; s < c->series; s++) {
            const double v = c->value[g][s];
            if (!(v > 0.0)) {
                continue;
            }
            const int y = y_of(c, v);
            rect(gx + s * bw + 1, y, gx + (s + 1) * bw - 1, H - MB, c->series_rgb[s]);
        }
        const char *name = c->group_name[g] ? c->group_name[g] : "";
        text(gx + (gw - 16 - text_width(name, 2)) / 2, H - MB + 8, name, 2, black);
    }
    /* legend: two rows of series */
    int lx = ML, ly = H - MB + 40;
    for (int s = 0; s < c->series; s++) {
        const char *name = c->series_name[s] ? c->series_name[s] : "";
        const int need = 22 + text_width(name, 2) + 24;
        if (lx + need > W - MR) {
            lx = ML;
            ly += 24;
        }
        rect(lx, ly, lx + 16, ly + 14, c->series_rgb[s]);
        lx += 22;
        lx += text(lx, ly, name, 2, black) + 24;
    }
    return sc_png_write(path, W, H, 3u, &g_px[0][0][0], (size_t)W * 3u) == 0 ? 0 : -1;
}
