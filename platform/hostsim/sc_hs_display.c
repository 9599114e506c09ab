/* sc_hs_display.c: in-memory display recorder, see sc_hs_display.h. */
#include "sc_hs_display.h"

#include <string.h>

#include "sc_err.h"

uint64_t sc_hs_hash64(const void *data, uint64_t size, uint64_t seed)
{
    const uint8_t *p = data;
    uint64_t h = seed ? seed : 0xcbf29ce484222325ull;
    for (uint64_t i = 0; i < size; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

static int hs_begin(void *ctx, const sc_display_frame_info *info)
{
    sc_hs_display *d = ctx;
    if (d->link_down) {
        d->calls_refused++;
        d->in_frame = 0;
        return SC_ERR_IO;
    }
    if (d->in_frame) {
        d->frames_incomplete++; /* previous frame never ended */
        d->protocol_errors++;
    }
    if (info->lines == 0u || info->lines > SC_MAX_SCAN_LINES || info->samples == 0u ||
        info->samples > SC_MAX_SCAN_SAMPLES) {
        d->protocol_errors++;
        d->in_frame = 0;
        return SC_ERR_IMG_GEOMETRY;
    }
    d->info = *info;
    d->in_frame = 1;
    d->lines_seen = 0;
    memset(d->line_seen, 0, sizeof(d->line_seen));
    memset(d->image, 0, (size_t)info->lines * info->samples);
    memset(d->colour, 0, (size_t)info->lines * SC_MAX_SCAN_SAMPLES);
    return SC_OK;
}

static int hs_colour_line(void *ctx, uint32_t frame_no, uint16_t line_index, uint16_t first,
                          const int8_t *values, uint16_t count)
{
    sc_hs_display *d = ctx;
    if (!d->in_frame || frame_no != d->info.frame_no || line_index >= d->info.lines ||
        count == 0u || (uint32_t)first + count > d->info.samples || values == NULL) {
        d->protocol_errors++;
        return SC_ERR_INVALID_ARG;
    }
    memcpy(d->colour + (size_t)line_index * SC_MAX_SCAN_SAMPLES + first, values, count);
    d->colour_lines++;
    d->colour_hash = sc_hs_hash64(values, count, d->colour_hash ^ line_index);
    return SC_OK;
}

static int hs_doppler(void *ctx, const sc_display_doppler_info *info)
{
    sc_hs_display *d = ctx;
    if (!d->in_frame || info == NULL || info->frame_no != d->info.frame_no ||
        info->spectrum_bins > SC_DISPLAY_SPECTRUM_MAX_BINS ||
        (info->spectrum_bins > 0u && info->spectrum == NULL)) {
        d->protocol_errors++;
        return SC_ERR_INVALID_ARG;
    }
    d->doppler = *info;
    memcpy(d->spectrum, info->spectrum, info->spectrum_bins);
    d->doppler.spectrum = d->spectrum;
    d->doppler_records++;
    d->colour_hash = sc_hs_hash64(d->spectrum, info->spectrum_bins, d->colour_hash);
    return SC_OK;
}

static int hs_line(void *ctx, uint32_t frame_no, uint16_t line_index, const uint8_t *samples,
                   uint16_t count)
{
    sc_hs_display *d = ctx;
    if (d->link_down) {
        d->calls_refused++;
        return SC_ERR_IO;
    }
    d->lines++;
    if (!d->in_frame || frame_no != d->info.frame_no || line_index >= d->info.lines ||
        count != d->info.samples || d->line_seen[line_index]) {
        d->protocol_errors++;
        return SC_ERR_INVALID_ARG;
    }
    d->line_seen[line_index] = 1;
    d->lines_seen++;
    memcpy(&d->image[(size_t)line_index * d->info.samples], samples, count);
    return SC_OK;
}

static int hs_end(void *ctx, const sc_display_end_info *end)
{
    sc_hs_display *d = ctx;
    if (d->link_down) {
        d->calls_refused++;
        return SC_ERR_IO;
    }
    if (!end || !d->in_frame || end->frame_no != d->info.frame_no) {
        d->protocol_errors++;
        return SC_ERR_STATE;
    }
    d->in_frame = 0;
    d->end = *end;
    if (d->lines_seen != d->info.lines) {
        d->frames_incomplete++;
        return SC_OK;
    }
    const size_t n = (size_t)d->info.lines * d->info.samples;
    memcpy(d->last, d->image, n);
    d->last_info = d->info;
    d->last_end = *end;
    if (d->hash_count < SC_HS_DISPLAY_HISTORY) {
        d->hashes[d->hash_count++] = sc_hs_hash64(d->image, n, 0);
    }
    d->frames_complete++;
    return SC_OK;
}

static int hs_link_state(void *ctx, sc_display_link_state *st)
{
    sc_hs_display *d = ctx;
    *st = (sc_display_link_state){
        .up = (uint8_t)!d->link_down, .lines_sent = (uint32_t)d->lines,
        .lines_dropped = (uint32_t)d->calls_refused};
    return SC_OK;
}

static const sc_display_ops hs_display_ops = {
    .frame_begin = hs_begin,
    .line = hs_line,
    .frame_end = hs_end,
    .link_state = hs_link_state,
    .colour_line = hs_colour_line,
    .doppler = hs_doppler,
};

void sc_hs_display_init(sc_hs_display *d)
{
    memset(d, 0, sizeof(*d));
}

sc_display_dev sc_hs_display_dev(sc_hs_display *d)
{
    return (sc_display_dev){.ops = &hs_display_ops, .ctx = d};
}
