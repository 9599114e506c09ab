/* sc_dlink.c: display link packet codec and frame assembler (see sc_dlink.h, docs/display-link.md).
 */
#include "sc_dlink.h"

#include <math.h>
#include <string.h>

#include "sc_crc32.h"
#include "sc_err.h"

/* Header byte offsets (docs/display-link.md). */
enum {
    OFF_MAGIC = 0,
    OFF_VERSION = 4,
    OFF_TYPE = 5,
    OFF_FLAGS = 6,
    OFF_FRAME = 8,
    OFF_LINE = 12,
    OFF_COUNT = 14,
    OFF_SAMPLES = 16,
    OFF_GEOMETRY = 18,
    OFF_PAYLOAD_LEN = 20,
    OFF_RESERVED = 22,
    OFF_CRC = 24,
};
_Static_assert(OFF_CRC + 4 == SC_DLINK_HEADER_SIZE, "header layout");

#define SC_DLINK_GEOMETRY_MAX    1u
#define SC_DLINK_COMPRESSION_MAX 1000u

static void put16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)(v >> 8);
}

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)((v >> 8) & 0xFFu);
    p[2] = (uint8_t)((v >> 16) & 0xFFu);
    p[3] = (uint8_t)(v >> 24);
}

static uint16_t get16(const uint8_t *p)
{
    return (uint16_t)((uint16_t)p[0] | (uint16_t)((uint16_t)p[1] << 8));
}

static uint32_t get32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static uint32_t f32_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static float f32_from_bits(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static int compression_ok(uint16_t pm)
{
    return pm <= SC_DLINK_COMPRESSION_MAX || pm == SC_DLINK_COMPRESSION_UNKNOWN;
}

static int frame_fields_ok(const sc_dlink_frame *f)
{
    return f->line_count >= 1u && f->line_count <= SC_MAX_SCAN_LINES && f->samples >= 1u &&
           f->samples <= SC_MAX_SCAN_SAMPLES && f->geometry_id <= SC_DLINK_GEOMETRY_MAX;
}

/* Write the header (CRC field excluded) of a packet of the given type and payload length. */
static void write_header(uint8_t *buf, const sc_dlink_frame *f, sc_dlink_type type,
                         uint16_t line_index, uint16_t payload_len)
{
    put32(buf + OFF_MAGIC, SC_DLINK_MAGIC);
    buf[OFF_VERSION] = (uint8_t)(type >= SC_DLINK_COLOUR_LINE ? SC_DLINK_VERSION_COLOUR
                                                               : SC_DLINK_VERSION);
    buf[OFF_TYPE] = (uint8_t)type;
    put16(buf + OFF_FLAGS, f->flags);
    put32(buf + OFF_FRAME, f->frame_no);
    put16(buf + OFF_LINE, line_index);
    put16(buf + OFF_COUNT, f->line_count);
    put16(buf + OFF_SAMPLES, f->samples);
    put16(buf + OFF_GEOMETRY, f->geometry_id);
    put16(buf + OFF_PAYLOAD_LEN, payload_len);
    put16(buf + OFF_RESERVED, 0u);
}

/* CRC over header bytes before the CRC field, then the payload. */
static uint32_t packet_crc(const uint8_t *hdr, const uint8_t *payload, size_t payload_len)
{
    uint32_t c = sc_crc32_update(SC_CRC32_INIT, hdr, OFF_CRC);
    c = sc_crc32_update(c, payload, payload_len);
    return sc_crc32_final(c);
}

static int finish(uint8_t *buf, uint16_t payload_len)
{
    put32(buf + OFF_CRC, packet_crc(buf, buf + SC_DLINK_HEADER_SIZE, payload_len));
    return (int)(SC_DLINK_HEADER_SIZE + payload_len);
}

int sc_dlink_encode_begin(uint8_t *buf, size_t cap, const sc_dlink_frame *f,
                          const sc_dlink_begin *b)
{
    if (!buf || !f || !b) {
        return SC_ERR_INVALID_ARG;
    }
    if (cap < SC_DLINK_HEADER_SIZE + SC_DLINK_BEGIN_PAYLOAD) {
        return SC_ERR_NO_SPACE;
    }
    if (!frame_fields_ok(f)) {
        return SC_ERR_DLINK_FIELD;
    }
    if (!isfinite(b->depth_mm) || !isfinite(b->width_mm) || !isfinite(b->radius_mm)) {
        return SC_ERR_NOT_FINITE;
    }
    if (b->radius_mm < 0.0f) {
        return SC_ERR_DLINK_FIELD;
    }
    write_header(buf, f, SC_DLINK_FRAME_BEGIN, 0u, (uint16_t)SC_DLINK_BEGIN_PAYLOAD);
    uint8_t *p = buf + SC_DLINK_HEADER_SIZE;
    put32(p + 0, f32_bits(b->depth_mm));
    put32(p + 4, f32_bits(b->width_mm));
    put32(p + 8, f32_bits(b->radius_mm));
    put32(p + 12, 0u);
    return finish(buf, (uint16_t)SC_DLINK_BEGIN_PAYLOAD);
}

int sc_dlink_encode_line(uint8_t *buf, size_t cap, const sc_dlink_frame *f, uint16_t line_index,
                         const uint8_t *samples, uint16_t count)
{
    if (!buf || !f || !samples) {
        return SC_ERR_INVALID_ARG;
    }
    if (!frame_fields_ok(f) || line_index >= f->line_count || count != f->samples) {
        return SC_ERR_DLINK_FIELD;
    }
    if (cap < (size_t)SC_DLINK_HEADER_SIZE + count) {
        return SC_ERR_NO_SPACE;
    }
    write_header(buf, f, SC_DLINK_LINE, line_index, count);
    memcpy(buf + SC_DLINK_HEADER_SIZE, samples, count);
    return finish(buf, count);
}

int sc_dlink_encode_end(uint8_t *buf, size_t cap, const sc_dlink_frame *f, const sc_dlink_end *e)
{
    if (!buf || !f || !e) {
        return SC_ERR_INVALID_ARG;
    }
    if (cap < SC_DLINK_HEADER_SIZE + SC_DLINK_END_PAYLOAD) {
        return SC_ERR_NO_SPACE;
    }
    if (!frame_fields_ok(f) || (uint32_t)e->lines_sent + e->lines_dropped > f->line_count ||
        !compression_ok(e->compression_pm) || !compression_ok(e->artery_compression_pm)) {
        return SC_ERR_DLINK_FIELD;
    }
    write_header(buf, f, SC_DLINK_FRAME_END, 0u, (uint16_t)SC_DLINK_END_PAYLOAD);
    uint8_t *p = buf + SC_DLINK_HEADER_SIZE;
    put16(p + 0, e->lines_sent);
    put16(p + 2, e->lines_dropped);
    put16(p + 4, e->compression_pm);
    put16(p + 6, e->artery_compression_pm);
    return finish(buf, (uint16_t)SC_DLINK_END_PAYLOAD);
}

static int params_ok(const float v[4 + SC_DLINK_PARAMS_TGC])
{
    static const float lo[4] = {-60.0f, 0.0f, 0.0f, 0.0f}, hi[4] = {60.0f, 120.0f, 300.0f, 30.0f};
    for (uint32_t i = 0; i < 4u + SC_DLINK_PARAMS_TGC; i++) {
        const float l = i < 4u ? lo[i] : -60.0f, h = i < 4u ? hi[i] : 60.0f;
        if (!(v[i] >= l && v[i] <= h)) {
            return 0;
        }
    }
    return 1;
}

static void params_to_array(const sc_dlink_params *p, float v[4 + SC_DLINK_PARAMS_TGC])
{
    v[0] = p->gain_db;
    v[1] = p->dynamic_range_db;
    v[2] = p->focus_mm;
    v[3] = p->frequency_mhz;
    for (uint32_t i = 0; i < SC_DLINK_PARAMS_TGC; i++) {
        v[4 + i] = p->tgc_db[i];
    }
}

int sc_dlink_encode_params(uint8_t *buf, size_t cap, const sc_dlink_frame *f,
                           const sc_dlink_params *p)
{
    if (!buf || !f || !p) {
        return SC_ERR_INVALID_ARG;
    }
    if (cap < SC_DLINK_HEADER_SIZE + SC_DLINK_PARAMS_PAYLOAD) {
        return SC_ERR_NO_SPACE;
    }
    float v[4 + SC_DLINK_PARAMS_TGC];
    params_to_array(p, v);
    for (uint32_t i = 0; i < 4u + SC_DLINK_PARAMS_TGC; i++) {
        if (!isfinite(v[i])) {
            return SC_ERR_NOT_FINITE;
        }
    }
    if (!frame_fields_ok(f) || !params_ok(v)) {
        return SC_ERR_DLINK_FIELD;
    }
    write_header(buf, f, SC_DLINK_FRAME_PARAMS, 0u, (uint16_t)SC_DLINK_PARAMS_PAYLOAD);
    uint8_t *q = buf + SC_DLINK_HEADER_SIZE;
    for (uint32_t i = 0; i < 4u + SC_DLINK_PARAMS_TGC; i++) {
        put32(q + 4u * i, f32_bits(v[i]));
    }
    return finish(buf, (uint16_t)SC_DLINK_PARAMS_PAYLOAD);
}

void sc_dlink_parse_params(const uint8_t *payload, sc_dlink_params *p)
{
    p->gain_db = f32_from_bits(get32(payload + 0));
    p->dynamic_range_db = f32_from_bits(get32(payload + 4));
    p->focus_mm = f32_from_bits(get32(payload + 8));
    p->frequency_mhz = f32_from_bits(get32(payload + 12));
    for (uint32_t i = 0; i < SC_DLINK_PARAMS_TGC; i++) {
        p->tgc_db[i] = f32_from_bits(get32(payload + 16u + 4u * i));
    }
}

/* ---- version 3: colour Doppler ---------------------------------------------------------- */

static int doppler_ok(const sc_dlink_frame *f, const sc_dlink_doppler *d)
{
    return d->box_line_lo <= d->box_line_hi && d->box_line_hi <= f->line_count &&
           d->box_sample_lo <= d->box_sample_hi && d->box_sample_hi <= f->samples &&
           d->nyquist_mm_s > 0.0f && d->steer_deg >= -90.0f && d->steer_deg <= 90.0f &&
           d->gate_line < f->line_count && d->gate_sample_lo < d->gate_sample_hi &&
           d->gate_sample_hi <= f->samples && d->bins <= SC_DLINK_SPECTRUM_MAX;
}

int sc_dlink_encode_colour(uint8_t *buf, size_t cap, const sc_dlink_frame *f, uint16_t line_index,
                           uint16_t first, const int8_t *values, uint16_t count)
{
    if (!buf || !f || !values) {
        return SC_ERR_INVALID_ARG;
    }
    if (!frame_fields_ok(f) || line_index >= f->line_count || count == 0u ||
        (uint32_t)first + count > f->samples) {
        return SC_ERR_DLINK_FIELD;
    }
    const uint16_t plen = (uint16_t)(SC_DLINK_COLOUR_HEAD + count);
    if (cap < (size_t)SC_DLINK_HEADER_SIZE + plen) {
        return SC_ERR_NO_SPACE;
    }
    write_header(buf, f, SC_DLINK_COLOUR_LINE, line_index, plen);
    uint8_t *p = buf + SC_DLINK_HEADER_SIZE;
    put16(p + 0, first);
    put16(p + 2, count);
    memcpy(p + SC_DLINK_COLOUR_HEAD, values, count);
    return finish(buf, plen);
}

int sc_dlink_encode_doppler(uint8_t *buf, size_t cap, const sc_dlink_frame *f,
                            const sc_dlink_doppler *d)
{
    if (!buf || !f || !d) {
        return SC_ERR_INVALID_ARG;
    }
    if (!isfinite(d->nyquist_mm_s) || !isfinite(d->steer_deg) ||
        !isfinite(d->gate_velocity_mm_s)) {
        return SC_ERR_NOT_FINITE;
    }
    if (!frame_fields_ok(f) || !doppler_ok(f, d)) {
        return SC_ERR_DLINK_FIELD;
    }
    const uint16_t plen = (uint16_t)(SC_DLINK_DOPPLER_HEAD + d->bins);
    if (cap < (size_t)SC_DLINK_HEADER_SIZE + plen) {
        return SC_ERR_NO_SPACE;
    }
    write_header(buf, f, SC_DLINK_DOPPLER, 0u, plen);
    uint8_t *p = buf + SC_DLINK_HEADER_SIZE;
    put16(p + 0, d->box_line_lo);
    put16(p + 2, d->box_line_hi);
    put16(p + 4, d->box_sample_lo);
    put16(p + 6, d->box_sample_hi);
    put32(p + 8, f32_bits(d->nyquist_mm_s));
    put32(p + 12, f32_bits(d->steer_deg));
    put32(p + 16, f32_bits(d->gate_velocity_mm_s));
    put16(p + 20, d->gate_line);
    put16(p + 22, d->gate_sample_lo);
    put16(p + 24, d->gate_sample_hi);
    put16(p + 26, d->bins);
    memcpy(p + SC_DLINK_DOPPLER_HEAD, d->spectrum, d->bins);
    return finish(buf, plen);
}

void sc_dlink_parse_doppler(const uint8_t *pl, sc_dlink_doppler *d)
{
    d->box_line_lo = get16(pl + 0);
    d->box_line_hi = get16(pl + 2);
    d->box_sample_lo = get16(pl + 4);
    d->box_sample_hi = get16(pl + 6);
    d->nyquist_mm_s = f32_from_bits(get32(pl + 8));
    d->steer_deg = f32_from_bits(get32(pl + 12));
    d->gate_velocity_mm_s = f32_from_bits(get32(pl + 16));
    d->gate_line = get16(pl + 20);
    d->gate_sample_lo = get16(pl + 22);
    d->gate_sample_hi = get16(pl + 24);
    d->bins = get16(pl + 26);
    memset(d->spectrum, 0, sizeof d->spectrum);
    memcpy(d->spectrum, pl + SC_DLINK_DOPPLER_HEAD,
           d->bins <= SC_DLINK_SPECTRUM_MAX ? d->bins : SC_DLINK_SPECTRUM_MAX);
}

int sc_dlink_decode(const uint8_t *pkt, size_t len, sc_dlink_header *h, const uint8_t **payload)
{
    return sc_dlink_decode_as(pkt, len, (uint8_t)SC_DLINK_VERSION_COLOUR, h, payload);
}

int sc_dlink_decode_as(const uint8_t *pkt, size_t len, uint8_t max_version, sc_dlink_header *h,
                       const uint8_t **payload)
{
    if (!pkt || !h || !payload) {
        return SC_ERR_INVALID_ARG;
    }
    if (len < SC_DLINK_HEADER_SIZE) {
        return SC_ERR_DLINK_LENGTH;
    }
    if (get32(pkt + OFF_MAGIC) != SC_DLINK_MAGIC) {
        return SC_ERR_DLINK_MAGIC;
    }
    const uint8_t ver = pkt[OFF_VERSION];
    if (ver != SC_DLINK_VERSION &&
        !(ver == SC_DLINK_VERSION_COLOUR && max_version >= SC_DLINK_VERSION_COLOUR)) {
        return SC_ERR_DLINK_VERSION;
    }
    uint16_t plen = get16(pkt + OFF_PAYLOAD_LEN);
    if ((size_t)SC_DLINK_HEADER_SIZE + plen != len) {
        return SC_ERR_DLINK_LENGTH;
    }
    const uint8_t *pl = pkt + SC_DLINK_HEADER_SIZE;
    if (packet_crc(pkt, pl, plen) != get32(pkt + OFF_CRC)) {
        return SC_ERR_DLINK_CRC;
    }
    sc_dlink_header d;
    d.version = pkt[OFF_VERSION];
    d.type = pkt[OFF_TYPE];
    d.flags = get16(pkt + OFF_FLAGS);
    d.frame_no = get32(pkt + OFF_FRAME);
    d.line_index = get16(pkt + OFF_LINE);
    d.line_count = get16(pkt + OFF_COUNT);
    d.samples = get16(pkt + OFF_SAMPLES);
    d.geometry_id = get16(pkt + OFF_GEOMETRY);
    d.payload_len = plen;
    uint16_t expect_len;
    switch (d.type) {
    case SC_DLINK_FRAME_BEGIN:
        expect_len = (uint16_t)SC_DLINK_BEGIN_PAYLOAD;
        break;
    case SC_DLINK_LINE:
        expect_len = d.samples;
        break;
    case SC_DLINK_FRAME_END:
        expect_len = (uint16_t)SC_DLINK_END_PAYLOAD;
        break;
    case SC_DLINK_FRAME_PARAMS:
        expect_len = (uint16_t)SC_DLINK_PARAMS_PAYLOAD;
        break;
    case SC_DLINK_COLOUR_LINE:
        expect_len = plen >= SC_DLINK_COLOUR_HEAD
                         ? (uint16_t)(SC_DLINK_COLOUR_HEAD + get16(pl + 2))
                         : (uint16_t)SC_DLINK_COLOUR_HEAD;
        break;
    case SC_DLINK_DOPPLER:
        expect_len = plen >= SC_DLINK_DOPPLER_HEAD
                         ? (uint16_t)(SC_DLINK_DOPPLER_HEAD + get16(pl + 26))
                         : (uint16_t)SC_DLINK_DOPPLER_HEAD;
        break;
    default:
        return SC_ERR_DLINK_TYPE;
    }
    /* the colour types exist in version 3 only; version 3 carries nothing else */
    if ((d.type >= SC_DLINK_COLOUR_LINE) != (ver == SC_DLINK_VERSION_COLOUR)) {
        return SC_ERR_DLINK_TYPE;
    }
    if (plen != expect_len) {
        return SC_ERR_DLINK_LENGTH;
    }
    const sc_dlink_frame f = {d.frame_no, d.flags, d.line_count, d.samples, d.geometry_id};
    if (!frame_fields_ok(&f) || get16(pkt + OFF_RESERVED) != 0u) {
        return SC_ERR_DLINK_FIELD;
    }
    if (d.type == SC_DLINK_LINE || d.type == SC_DLINK_COLOUR_LINE) {
        if (d.line_index >= d.line_count) {
            return SC_ERR_DLINK_FIELD;
        }
    } else if (d.line_index != 0u) {
        return SC_ERR_DLINK_FIELD;
    }
    if (d.type == SC_DLINK_FRAME_BEGIN) {
        float depth = f32_from_bits(get32(pl + 0));
        float width = f32_from_bits(get32(pl + 4));
        float radius = f32_from_bits(get32(pl + 8));
        if (!isfinite(depth) || !isfinite(width) || !isfinite(radius) || radius < 0.0f ||
            get32(pl + 12) != 0u) {
            return SC_ERR_DLINK_FIELD;
        }
    } else if (d.type == SC_DLINK_FRAME_END) {
        if ((uint32_t)get16(pl + 0) + get16(pl + 2) > d.line_count ||
            !compression_ok(get16(pl + 4)) || !compression_ok(get16(pl + 6))) {
            return SC_ERR_DLINK_FIELD;
        }
    } else if (d.type == SC_DLINK_FRAME_PARAMS) {
        sc_dlink_params p;
        float v[4 + SC_DLINK_PARAMS_TGC];
        sc_dlink_parse_params(pl, &p);
        params_to_array(&p, v);
        if (!params_ok(v)) { /* NaN fails the range too */
            return SC_ERR_DLINK_FIELD;
        }
    } else if (d.type == SC_DLINK_COLOUR_LINE) {
        const uint16_t first = get16(pl + 0), count = get16(pl + 2);
        if (count == 0u || (uint32_t)first + count > d.samples) {
            return SC_ERR_DLINK_FIELD;
        }
    } else if (d.type == SC_DLINK_DOPPLER) {
        sc_dlink_doppler dd;
        sc_dlink_parse_doppler(pl, &dd);
        if (!isfinite(dd.nyquist_mm_s) || !isfinite(dd.steer_deg) ||
            !isfinite(dd.gate_velocity_mm_s) || !doppler_ok(&f, &dd)) {
            return SC_ERR_DLINK_FIELD;
        }
    }
    *h = d;
    *payload = pl;
    return 0;
}

void sc_dlink_parse_begin(const uint8_t *payload, sc_dlink_begin *b)
{
    b->depth_mm = f32_from_bits(get32(payload + 0));
    b->width_mm = f32_from_bits(get32(payload + 4));
    b->radius_mm = f32_from_bits(get32(payload + 8));
}

void sc_dlink_parse_end(const uint8_t *payload, sc_dlink_end *e)
{
    e->lines_sent = get16(payload + 0);
    e->lines_dropped = get16(payload + 2);
    e->compression_pm = get16(payload + 4);
    e->artery_compression_pm = get16(payload + 6);
}

uint16_t sc_dlink_compression_pm(float area_ratio)
{
    if (!(area_ratio >= 0.0f) || !isfinite(area_ratio)) {
        return SC_DLINK_COMPRESSION_UNKNOWN;
    }
    const float c = 1000.0f * (1.0f - fminf(1.0f, area_ratio));
    return (uint16_t)(c + 0.5f);
}

/* ---- assembler ------------------------------------------------------------------------- */

/* Serial-number difference a - b of 32-bit frame counters (RFC 1982 style). */
static int32_t frame_diff(uint32_t a, uint32_t b)
{
    uint32_t d = a - b;
    return (d <= 0x7FFFFFFFu) ? (int32_t)d : -(int32_t)(~d) - 1;
}

void sc_dlink_asm_init(sc_dlink_asm *a)
{
    memset(a, 0, sizeof *a);
    a->max_version = (uint8_t)SC_DLINK_VERSION_COLOUR;
    a->end.compression_pm = SC_DLINK_COMPRESSION_UNKNOWN;
    a->end.artery_compression_pm = SC_DLINK_COMPRESSION_UNKNOWN;
}

static void count_reject(sc_dlink_rx_stats *s, int rc)
{
    s->rejected++;
    switch (rc) {
    case SC_ERR_DLINK_LENGTH:
        s->rej_length++;
        break;
    case SC_ERR_DLINK_MAGIC:
        s->rej_magic++;
        break;
    case SC_ERR_DLINK_VERSION:
        s->rej_version++;
        break;
    case SC_ERR_DLINK_CRC:
        s->rej_crc++;
        break;
    case SC_ERR_DLINK_TYPE:
        s->rej_type++;
        break;
    default: /* SC_ERR_DLINK_FIELD and inconsistent frames */
        s->rej_field++;
        break;
    }
}

static void close_frame(sc_dlink_asm *a, uint8_t end_seen)
{
    const uint32_t stride = SC_MAX_SCAN_SAMPLES;
    uint8_t *img = a->image[a->cur];
    const uint8_t *prev = a->image[a->cur ^ 1u];
    const int carry = a->have_done && a->done.frame.samples == a->frame.samples;
    uint16_t lost = 0;
    for (uint32_t i = 0; i < a->frame.line_count; i++) {
        if ((a->got[i / 32u] & (1u << (i % 32u))) == 0u) {
            lost++;
            if (carry) {
                memcpy(img + i * stride, prev + i * stride, a->frame.samples);
            } else {
                memset(img + i * stride, 0, a->frame.samples);
            }
        }
    }
    a->stats.lines_lost += lost;
    if (lost == 0u) {
        a->stats.frames_complete++;
    } else {
        a->stats.frames_incomplete++;
    }
    if (!end_seen) {
        a->stats.ends_missing++;
    }
    a->done.frame = a->frame;
    a->done.begin = a->begin;
    a->done.end = end_seen ? a->end : (sc_dlink_end){0u, 0u, SC_DLINK_COMPRESSION_UNKNOWN,
                                                     SC_DLINK_COMPRESSION_UNKNOWN};
    a->done.lines_received = a->received;
    a->done.lines_lost = lost;
    a->done.begin_seen = a->begin_seen;
    a->done.end_seen = end_seen;
    a->done.image = img;
    a->done.params = a->params;
    a->done.params_known = a->params_known;
    a->done.colour = a->colour_used[a->cur] ? a->colour[a->cur] : NULL;
    a->done.doppler_seen = a->doppler_seen;
    a->done.doppler = a->doppler;
    a->have_done = 1u;
    a->last_closed_no = a->frame.frame_no;
    a->cur ^= 1u;
    a->open = 0u;
}

static void open_frame(sc_dlink_asm *a, const sc_dlink_frame *f, uint8_t type)
{
    a->frame = *f;
    a->open = 1u;
    a->begin_seen = 0u;
    a->received = 0u;
    a->doppler_seen = 0u;
    memset(a->got, 0, sizeof a->got);
    if (a->colour_used[a->cur]) {
        memset(a->colour[a->cur], 0, sizeof a->colour[a->cur]);
        a->colour_used[a->cur] = 0u;
    }
    if (type != SC_DLINK_FRAME_BEGIN) {
        a->stats.begins_missing++;
    }
}

static void count_late(sc_dlink_asm *a, uint8_t type)
{
    if (type == SC_DLINK_LINE || type == SC_DLINK_COLOUR_LINE) {
        a->stats.lines_late++;
    } else {
        a->stats.frames_late++;
    }
}

int sc_dlink_asm_push(sc_dlink_asm *a, const uint8_t *pkt, size_t len)
{
    sc_dlink_header h;
    const uint8_t *pl = NULL;
    a->stats.packets++;
    int rc = sc_dlink_decode_as(pkt, len, a->max_version, &h, &pl);
    if (rc < 0) {
        count_reject(&a->stats, rc);
        return rc;
    }
    const sc_dlink_frame f = {h.frame_no, h.flags, h.line_count, h.samples, h.geometry_id};
    int closed = 0;
    if (a->open && h.frame_no == a->frame.frame_no) {
        if (h.line_count != a->frame.line_count || h.samples != a->frame.samples ||
            h.geometry_id != a->frame.geometry_id) {
            count_reject(&a->stats, SC_ERR_DLINK_FIELD);
            return SC_ERR_DLINK_FIELD;
        }
    } else {
        /* Reference: the open frame, else the last closed one. */
        if (a->open || a->have_done) {
            const uint32_t ref = a->open ? a->frame.frame_no : a->last_closed_no;
            const int32_t d = frame_diff(h.frame_no, ref);
            if (d <= 0 && d >= -(int32_t)SC_DLINK_RESYNC_FRAMES) {
                count_late(a, h.type);
                return 0;
            }
        }
        if (a->open) {
            close_frame(a, 0u);
            closed = 1;
        }
        open_frame(a, &f, h.type);
    }
    switch ((sc_dlink_type)h.type) {
    case SC_DLINK_FRAME_BEGIN:
        if (a->begin_seen) {
            a->stats.frames_late++; /* a repeated FRAME_BEGIN: ignored */
            break;
        }
        sc_dlink_parse_begin(pl, &a->begin);
        a->begin_seen = 1u;
        a->frame.flags = h.flags;
        break;
    case SC_DLINK_LINE: {
        const uint32_t i = h.line_index;
        const uint32_t bit = 1u << (i % 32u);
        if (a->got[i / 32u] & bit) {
            a->stats.lines_duplicate++;
            break;
        }
        a->got[i / 32u] |= bit;
        memcpy(a->image[a->cur] + i * SC_MAX_SCAN_SAMPLES, pl, h.samples);
        a->received++;
        a->stats.lines_received++;
        break;
    }
    case SC_DLINK_FRAME_PARAMS:
        sc_dlink_parse_params(pl, &a->params);
        a->params_known = 1u;
        break;
    case SC_DLINK_FRAME_END: {
        sc_dlink_end e;
        sc_dlink_parse_end(pl, &e);
        a->stats.lines_sender_dropped += e.lines_dropped;
        a->end = e;
        a->frame.flags = h.flags;
        close_frame(a, 1u);
        closed = 1;
        break;
    }
    case SC_DLINK_COLOUR_LINE: {
        const uint16_t first = get16(pl + 0), count = get16(pl + 2);
        memcpy(a->colour[a->cur] + (size_t)h.line_index * SC_MAX_SCAN_SAMPLES + first,
               pl + SC_DLINK_COLOUR_HEAD, count);
        a->colour_used[a->cur] = 1u;
        a->stats.colour_lines++;
        break;
    }
    case SC_DLINK_DOPPLER:
        sc_dlink_parse_doppler(pl, &a->doppler);
        a->doppler_seen = 1u;
        a->stats.doppler_records++;
        break;
    }
    return closed;
}

int sc_dlink_asm_flush(sc_dlink_asm *a)
{
    if (!a->open) {
        return 0;
    }
    close_frame(a, 0u);
    return 1;
}

const sc_dlink_done *sc_dlink_asm_done(const sc_dlink_asm *a)
{
    return a->have_done ? &a->done : NULL;
}
