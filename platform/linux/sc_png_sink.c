/* sc_png_sink.c: PNG frame files from the display HAL (see sc_png_sink.h). */
#include "sc_png_sink.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "sc_config.h"
#include "sc_err.h"
#include "sc_png_write.h"
#include "sc_scan_overlay.h"
#include "sc_scanconv.h"

#define STRIDE      SC_MAX_SCAN_SAMPLES
#define FRAME_BYTES ((size_t)SC_MAX_SCAN_LINES * SC_MAX_SCAN_SAMPLES)

struct sc_png_sink {
    char dir[4096];
    uint32_t every_n;
    uint32_t max_frames;
    /* frame loop side */
    uint8_t *frame; /* lines being collected */
    int8_t *colour; /* colour Doppler of the frame (colour_line), NULL-free; has_colour: any */
    int has_colour;
    int8_t *handoff_colour;
    int handoff_has_colour;
    uint8_t *rgb; /* writer: RGB raster of a frame with colour */
    uint8_t got[SC_MAX_SCAN_LINES];
    uint32_t got_n;
    sc_display_frame_info info;
    int in_frame;
    /* hand-off */
    pthread_mutex_t lock;
    pthread_cond_t cond;
    int pending; /* the writer has a frame to write */
    int stopping;
    uint8_t *handoff;
    sc_display_frame_info handoff_info;
    /* writer side */
    sc_scanconv conv;
    uint8_t *raster;
    pthread_t thread;
    int thread_started;
    sc_png_sink_stats st; /* under lock */
};

static void *writer_main(void *arg)
{
    sc_png_sink *s = arg;
    pthread_mutex_lock(&s->lock);
    for (;;) {
        while (!s->pending && !s->stopping) {
            pthread_cond_wait(&s->cond, &s->lock);
        }
        if (!s->pending && s->stopping) {
            break;
        }
        const sc_display_frame_info info = s->handoff_info;
        pthread_mutex_unlock(&s->lock);
        char path[4200];
        snprintf(path, sizeof path, "%s/frame_%06u.png", s->dir, (unsigned)info.frame_no);
        int rc;
        if (s->handoff_has_colour) { /* colour Doppler over the grey B-scan: an RGB file */
            sc_scanconv_render_colour(&s->conv, &info, s->handoff, s->handoff_colour, STRIDE,
                                      s->rgb);
            /* the scanner's display over the colour image */
            sc_overlay_draw_rgb(s->rgb, s->raster, s->conv.width, s->conv.height, &info);
            rc = sc_png_write(path, s->conv.width, s->conv.height, 3u, s->rgb, 3u * s->conv.width);
        } else {
            sc_scanconv_render(&s->conv, &info, s->handoff, STRIDE, s->raster);
            sc_overlay_draw(s->raster, s->conv.width, s->conv.height, &info); /* a scanner's display */
            rc = sc_png_write(path, s->conv.width, s->conv.height, 1u, s->raster, s->conv.width);
        }
        pthread_mutex_lock(&s->lock);
        if (rc == 0) {
            s->st.frames_written++;
        } else {
            s->st.write_errors++;
        }
        s->pending = 0;
        pthread_cond_broadcast(&s->cond);
    }
    pthread_mutex_unlock(&s->lock);
    return NULL;
}

static void count_protocol_error(sc_png_sink *s)
{
    pthread_mutex_lock(&s->lock);
    s->st.protocol_errors++;
    pthread_mutex_unlock(&s->lock);
}

static int png_frame_begin(void *ctx, const sc_display_frame_info *info)
{
    sc_png_sink *s = ctx;
    if (info->lines == 0u || info->lines > SC_MAX_SCAN_LINES || info->samples == 0u ||
        info->samples > SC_MAX_SCAN_SAMPLES) {
        count_protocol_error(s);
        s->in_frame = 0;
        return SC_ERR_RANGE;
    }
    s->info = *info;
    memset(s->got, 0, info->lines);
    s->got_n = 0;
    s->in_frame = 1;
    if (s->has_colour) {
        memset(s->colour, 0, FRAME_BYTES);
        s->has_colour = 0;
    }
    return 0;
}

static int png_colour_line(void *ctx, uint32_t frame_no, uint16_t line_index, uint16_t first,
                           const int8_t *values, uint16_t count)
{
    sc_png_sink *s = ctx;
    if (!s->in_frame || frame_no != s->info.frame_no || line_index >= s->info.lines ||
        count == 0u || (uint32_t)first + count > s->info.samples || values == NULL) {
        count_protocol_error(s);
        return SC_ERR_STATE;
    }
    memcpy(s->colour + (size_t)line_index * STRIDE + first, values, count);
    s->has_colour = 1;
    return 0;
}

static int png_line(void *ctx, uint32_t frame_no, uint16_t line_index, const uint8_t *samples,
                    uint16_t count)
{
    sc_png_sink *s = ctx;
    if (!s->in_frame || frame_no != s->info.frame_no || line_index >= s->info.lines ||
        count != s->info.samples) {
        count_protocol_error(s);
        return SC_ERR_STATE;
    }
    memcpy(s->frame + (size_t)line_index * STRIDE, samples, count);
    if (!s->got[line_index]) {
        s->got[line_index] = 1;
        s->got_n++;
    }
    return 0;
}

static int png_frame_end(void *ctx, const sc_display_end_info *end)
{
    sc_png_sink *s = ctx;
    if (!end || !s->in_frame || end->frame_no != s->info.frame_no) {
        count_protocol_error(s);
        return SC_ERR_STATE;
    }
    s->in_frame = 0;
    pthread_mutex_lock(&s->lock);
    s->st.frames++;
    if (s->got_n < s->info.lines) {
        s->st.frames_incomplete++;
        for (uint32_t i = 0; i < s->info.lines; i++) {
            if (!s->got[i]) {
                memset(s->frame + (size_t)i * STRIDE, 0, s->info.samples);
            }
        }
    }
    int rc = 0;
    const int wanted =
        (s->every_n <= 1u || end->frame_no % s->every_n == 0u) &&
        (s->max_frames == 0u || s->st.frames_written + (uint64_t)s->pending < s->max_frames);
    if (wanted) {
        if (s->pending) {
            s->st.frames_busy++;
            rc = SC_ERR_WOULD_BLOCK;
        } else {
            memcpy(s->handoff, s->frame, FRAME_BYTES);
            s->handoff_has_colour = s->has_colour;
            if (s->has_colour) {
                memcpy(s->handoff_colour, s->colour, FRAME_BYTES);
            }
            s->handoff_info = s->info;
            s->pending = 1;
            pthread_cond_signal(&s->cond);
        }
    }
    pthread_mutex_unlock(&s->lock);
    return rc;
}

static int png_link_state(void *ctx, sc_display_link_state *st)
{
    sc_png_sink *s = ctx;
    pthread_mutex_lock(&s->lock);
    st->up = s->st.write_errors == 0u;
    st->lines_sent = (uint32_t)(s->st.frames_written);
    st->lines_dropped = (uint32_t)(s->st.frames_busy);
    pthread_mutex_unlock(&s->lock);
    return 0;
}

static const sc_display_ops k_png_ops = {png_frame_begin, png_line,        png_frame_end,
                                         png_link_state,  png_colour_line, NULL};

int sc_png_sink_open(sc_png_sink **out, const sc_png_sink_def *def)
{
    *out = NULL;
    if (!def || !def->dir || strlen(def->dir) >= 4096u) {
        return SC_ERR_INVALID_ARG;
    }
    struct stat sb;
    if (stat(def->dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
        return SC_ERR_NOT_FOUND;
    }
    sc_png_sink *s = calloc(1, sizeof *s);
    if (!s) {
        return SC_ERR_IO;
    }
    snprintf(s->dir, sizeof s->dir, "%s", def->dir);
    s->every_n = def->every_n;
    s->max_frames = def->max_frames;
    const uint32_t w = def->width_px ? def->width_px : 512u;
    const uint32_t h = def->height_px ? def->height_px : 512u;
    s->frame = calloc(1, FRAME_BYTES);
    s->handoff = calloc(1, FRAME_BYTES);
    s->raster = calloc(1, (size_t)w * h);
    s->colour = calloc(1, FRAME_BYTES);
    s->handoff_colour = calloc(1, FRAME_BYTES);
    s->rgb = calloc(3, (size_t)w * h);
    if (!s->frame || !s->handoff || !s->raster || !s->colour || !s->handoff_colour || !s->rgb ||
        sc_scanconv_init(&s->conv, w, h) != 0) {
        free(s->colour);
        free(s->handoff_colour);
        free(s->rgb);
        free(s->frame);
        free(s->handoff);
        free(s->raster);
        free(s);
        return SC_ERR_IO;
    }
    sc_scanconv_set_fit(&s->conv, 1); /* a PNG is the image's box: no black band below it */
    pthread_mutex_init(&s->lock, NULL);
    pthread_cond_init(&s->cond, NULL);
    if (pthread_create(&s->thread, NULL, writer_main, s) != 0) {
        sc_scanconv_free(&s->conv);
        free(s->colour);
        free(s->handoff_colour);
        free(s->rgb);
        free(s->frame);
        free(s->handoff);
        free(s->raster);
        free(s);
        return SC_ERR_IO;
    }
    s->thread_started = 1;
    *out = s;
    return 0;
}

sc_display_dev sc_png_sink_dev(sc_png_sink *s)
{
    sc_display_dev d = {&k_png_ops, s};
    return d;
}

void sc_png_sink_get_stats(sc_png_sink *s, sc_png_sink_stats *st)
{
    pthread_mutex_lock(&s->lock);
    *st = s->st;
    pthread_mutex_unlock(&s->lock);
}

void sc_png_sink_close(sc_png_sink *s)
{
    if (!s) {
        return;
    }
    if (s->thread_started) {
        pthread_mutex_lock(&s->lock);
        s->stopping = 1;
        pthread_cond_broadcast(&s->cond);
        pthread_mutex_unlock(&s->lock);
        pthread_join(s->thread, NULL);
    }
    pthread_mutex_destroy(&s->lock);
    pthread_cond_destroy(&s->cond);
    sc_scanconv_free(&s->conv);
    free(s->colour);
    free(s->handoff_colour);
    free(s->rgb);
    free(s->frame);
    free(s->handoff);
    free(s->raster);
    free(s);
}
