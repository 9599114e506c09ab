/* bench_chart.h: a grouped bar chart as an RGB PNG (the paper's Fig. 9 style), drawn in memory
 * with a built-in 5x7 font and written with the project's PNG writer (platform/linux
 * sc_png_write.h, libpng). Log-scale y axis (0.1 .. 1000 ms by default) so that a 20x10x10 bar
 * and a 64x32x32 bar both show; a bar whose value is missing (negative) is not drawn.
 * Host tool code: static storage, one chart at a time. */
#ifndef BENCH_CHART_H
#define BENCH_CHART_H

#include <stdint.h>

#define CHART_MAX_GROUPS 16
#define CHART_MAX_SERIES 8

typedef struct chart {
    const char *title;                    /* upper case letters, digits, " .,:()X=/-%" */
    const char *y_label;                  /* e.g. "MS PER FRAME" */
    int groups, series;
    const char *group_name[CHART_MAX_GROUPS];
    const char *series_name[CHART_MAX_SERIES];
    uint8_t series_rgb[CHART_MAX_SERIES][3];
    double value[CHART_MAX_GROUPS][CHART_MAX_SERIES]; /* ms; < 0: missing */
    double y_min, y_max;                  /* log axis limits, decades (e.g. 0.1, 1000) */
} chart;

/* Render and write. 0, or -1 (bad chart or the PNG could not be written). */
int chart_write_png(const chart *c, const char *path);

#endif /* BENCH_CHART_H */
